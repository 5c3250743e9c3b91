"""The contract every simulator plugin passes (``toolkit.interfaces.Simulator``), like the SPD and
searcher suites: stepping and time, the substep loop's termination rules (``Watch``), batched link
reads, contacts, scene geometry (boxes), rays and rendering — on the real engine.

A subclass sets ``make()`` (a simulator of the humanoid with 600 Hz substeps) and inherits the
tests. States come from the hook ``run_state(sim)``: by default the DeepMimic run clip's
mid-support frame (feet down), found by the simulator under test's own forward kinematics, so the
suite needs nothing but the simulator (override it to give another state)::

    from toolkit.testing.simulator import SimulatorContract

    class TestMySim(SimulatorContract):
        def make(self, **sim):
            return MySimulator({"sim": {"name": "mine", **sim}, "spd": {"name": "df"},
                                "character": {"name": "humanoid"}})
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from toolkit.interfaces.simulator import BASE, ContactRule, Simulator, Watch


class SimulatorContract:
    """Tests every simulator must pass (subclass it as ``TestXxx`` and define ``make``)."""

    def make(self, **sim: Any) -> Any:  # pragma: no cover - abstract
        raise NotImplementedError

    def run_state(self, sim: Simulator) -> tuple[np.ndarray, np.ndarray]:
        """The hook: a humanoid state ``(q, qd)`` (``toolkit.dynamics`` layout) with the stance foot
        down. Default: the run clip's frame whose right ankle is lowest by ``sim``'s own forward
        kinematics (``reset`` to each frame, ``link_pose``), with its velocities
        (``toolkit.motion.kinematics.clip_velocities``); ``sim`` is left in that pose at rest."""
        from toolkit.motion import load_clip
        from toolkit.motion.kinematics import clip_velocities
        from toolkit.motion.skeletons import motions_dir

        clip = load_clip(f"{motions_dir()}/humanoid3d_run.txt")
        ankle = sim.link_index("right_ankle")
        poses = [np.concatenate([clip.root_pos[i], clip.root_rot[i], clip.joints[i]])
                 for i in range(clip.n_frames)]
        heights = []
        for q in poses:
            sim.reset(q, np.zeros(sim.model.n_v))
            heights.append(float(sim.link_pose(ankle)[0][1]))
        i = int(np.argmin(heights))
        sim.reset(poses[i], np.zeros(sim.model.n_v))
        vel = clip_velocities(clip)
        return poses[i], np.concatenate([vel.root_lin[i], vel.root_ang[i], vel.joints[i]])

    @pytest.fixture()
    def sim(self):
        s = self.make()
        yield s
        s.close()

    def _lifted(self, sim, height: float = 0.0):
        q, qd = self.run_state(sim)
        sim.reset(q, np.zeros_like(qd))
        low = min(sim.aabb(i)[0][1] for i in range(BASE, sim.n_links))
        q = q.copy()
        q[1] += height - low + 1e-3
        sim.reset(q, np.zeros_like(qd))
        return q, np.zeros_like(qd)

    # ------------------------------------------------------------------ state, time
    def test_reset_then_state_round_trips(self, sim):
        q, qd = self.run_state(sim)
        sim.reset(q, qd)
        q2, qd2 = sim.state()
        np.testing.assert_allclose(q2[:3], q[:3], atol=1e-9)
        assert abs(abs(float(np.dot(q2[3:7], q[3:7]))) - 1.0) < 1e-9
        np.testing.assert_allclose(qd2[:3], qd[:3], atol=1e-9)
        assert sim.time == 0.0

    def test_declares_its_rates(self, sim):
        assert sim.sim_hz > 0 and sim.control_hz > 0
        assert sim.n_substeps == round(sim.sim_hz / sim.control_hz)

    def test_declares_its_ground_friction(self):
        s = self.make(friction=0.7)
        try:
            assert s.friction == pytest.approx(0.7)
        finally:
            s.close()

    def test_step_runs_its_substeps_and_advances_time(self, sim):
        q, qd = self._lifted(sim, 0.5)
        rec = sim.step(q)
        assert rec["substeps"] == sim.n_substeps and not rec["failed"] and rec["outcome"] == ""
        assert sim.time == pytest.approx(sim.n_substeps / sim.sim_hz)
        rec = sim.step(q, n_substeps=3)
        assert rec["substeps"] == 3
        assert sim.time == pytest.approx((sim.n_substeps + 3) / sim.sim_hz)
        assert rec["q"].shape == q.shape and rec["qd"].shape == qd.shape

    def test_a_nan_state_fails_and_never_raises(self, sim):
        q, qd = self._lifted(sim, 0.5)
        bad = qd.copy()
        bad[7] = np.nan
        sim.reset(q, bad)
        rec = sim.step(q)
        assert rec["failed"] and rec["outcome"] == "fail" and rec["reason"]
        assert sim.step(q)["substeps"] == 0  # stays failed until the next reset

    # ------------------------------------------------------------------ batched reads
    def test_links_masses_and_com_agree(self, sim):
        self._lifted(sim, 0.2)
        pos, orn = sim.link_states()
        m = sim.masses
        assert pos.shape == (sim.n_links + 1, 3) and orn.shape == (sim.n_links + 1, 4) and m.shape == (sim.n_links + 1,)
        np.testing.assert_allclose(np.linalg.norm(orn, axis=1), 1.0, atol=1e-9)
        assert 40.0 < m.sum() < 60.0  # the DeepMimic humanoid at 0.25 scale: about 45 kg
        np.testing.assert_allclose(sim.com(), m @ pos / m.sum(), atol=1e-12)
        q, _ = sim.state()
        np.testing.assert_allclose(pos[0], q[:3], atol=1e-9)  # row 0 is the base

    def test_link_velocities_are_the_links_motion(self, sim):
        """Base row = the base's generalised velocity; a held pose falling freely moves every link
        with the base; a running pose's link velocities match its links' central differences."""
        if type(sim).link_velocities is Simulator.link_velocities:
            pytest.skip("link_velocities is optional")
        q, _ = self._lifted(sim, 0.5)
        for _ in range(10):
            sim.step(q, n_substeps=1)
        lin, ang = sim.link_velocities()
        _, qd = sim.state()
        assert lin.shape == ang.shape == (sim.n_links + 1, 3)
        np.testing.assert_allclose(lin[0], qd[:3], atol=1e-9)
        np.testing.assert_allclose(ang[0], qd[3:6], atol=1e-9)
        assert lin[0, 1] < -0.1  # falling
        np.testing.assert_allclose(lin, np.broadcast_to(qd[:3], lin.shape), atol=2e-3)
        np.testing.assert_allclose(ang, 0.0, atol=2e-2)
        q, qd = self.run_state(sim)
        q = q.copy()
        q[1] += 0.5
        sim.reset(q, qd)
        sim.step(q, n_substeps=2)  # link frames read after a step are the engine's own
        dt = 1.0 / sim.sim_hz
        p0 = sim.link_states()[0]
        sim.step(q, n_substeps=1)
        v1 = sim.link_velocities()[0]
        sim.step(q, n_substeps=1)
        fd = (sim.link_states()[0] - p0) / (2 * dt)
        assert np.abs(fd - v1).max() < 0.05 * np.abs(v1).max() + 0.05

    def test_link_index_and_link_pose_are_forward_kinematics_of_the_reset_state(self, sim):
        from toolkit.errors import JtError

        q, qd = self.run_state(sim)
        sim.reset(q, np.zeros_like(qd))
        assert sim.link_index("base") == BASE
        ankle = sim.link_index("right_ankle")
        assert 0 <= ankle < sim.n_links
        np.testing.assert_allclose(sim.link_pose(BASE)[0], q[:3], atol=1e-9)
        pos, orn = sim.link_pose(ankle)
        assert pos.shape == (3,) and orn.shape == (4,)
        assert abs(float(np.linalg.norm(orn)) - 1.0) < 1e-6
        moved = q.copy()
        moved[0] += 0.5
        sim.reset(moved, np.zeros_like(qd))  # no step: the pose is read from the new state
        np.testing.assert_allclose(sim.link_pose(ankle)[0], pos + [0.5, 0.0, 0.0], atol=1e-9)
        with pytest.raises(JtError, match="no link or joint 'tail'") as err:
            sim.link_index("tail")
        assert isinstance(err.value, KeyError) and "right_ankle" in str(err.value)

    # ------------------------------------------------------------------ rules in the substep loop
    def test_falling_character_touches_the_ground_within_the_step(self, sim):
        q, _ = self._lifted(sim, 0.02)
        rule = ContactRule(sim.ground, "fail", "fell")
        rec = None
        for _ in range(20):
            rec = sim.step(q, watch=Watch(rules=(rule,)))
            if rec["outcome"]:
                break
        assert rec["outcome"] == "fail" and rec["reason"] == "fell"
        assert 1 <= rec["substeps"] <= sim.n_substeps
        assert sim.contacts(sim.ground)  # the loop stopped at the touching substep

    def test_except_links_and_the_first_touch_are_reported(self, sim):
        q, _ = self._lifted(sim, 0.02)
        touched_links = set()
        for _ in range(20):
            rec = sim.step(q, watch=Watch(touches=(sim.ground,)))
            touched_links |= set(rec["touched"].get(sim.ground, ()))
            if touched_links:
                break
        assert touched_links
        rule = ContactRule(sim.ground, "fail", "fell", except_links=tuple(sorted(touched_links)))
        rec = sim.step(q, n_substeps=1, watch=Watch(rules=(rule,)))
        assert rec["outcome"] == ""  # only the excepted links touch

    def test_time_limit_and_records_at_every_checked_substep(self, sim):
        q, _ = self._lifted(sim, 1.0)
        w = Watch(record=("time", "com", "root"), time_limit=7.5 / 600.0, check_every=2)
        rec = sim.step(q, n_substeps=20, watch=w)
        assert rec["outcome"] == "fail" and rec["reason"] == "time limit"
        assert rec["substeps"] == 8  # checked at 2, 4, 6, 8: t = 8/600 >= 7.5/600
        np.testing.assert_allclose(rec["samples"]["time"], np.arange(2, 9, 2) / 600.0)
        assert rec["samples"]["com"].shape == (4, 3) and rec["samples"]["root"].shape == (4, 7)
        np.testing.assert_allclose(rec["samples"]["com"][-1], sim.com(), atol=1e-12)  # the state just integrated
        assert rec["samples"]["com"][0][1] > rec["samples"]["com"][-1][1]  # falling

    # ------------------------------------------------------------------ scene, rays
    def test_box_contact_rule_clear_of_and_remove(self, sim):
        q, _ = self._lifted(sim, 0.5)
        com = sim.com()
        box = sim.add_box([0.3, 0.05, 0.3], [com[0], 0.25, com[2]])
        other = sim.add_box([0.05, 0.05, 0.05], [com[0] + 5.0, 0.05, com[2]])
        assert sim.near(box, 1.0) and not sim.near(other, 1.0)
        land = ContactRule(box, "success", "landed", clear_of=other, margin=0.1)
        rec = None
        for _ in range(30):
            rec = sim.step(q, watch=Watch(rules=(ContactRule(sim.ground, "fail", "ground"), land)))
            if rec["outcome"]:
                break
        assert (rec["outcome"], rec["reason"]) == ("success", "landed")
        blocked = ContactRule(box, "success", "landed", clear_of=box, margin=0.1)  # never clear of itself
        assert sim.step(q, n_substeps=1, watch=Watch(rules=(blocked,)))["outcome"] == ""
        sim.remove(box)
        assert not sim.near(box, 1.0)  # removed: nothing of it is near any more

    def test_rays_hit_ground_and_boxes(self, sim):
        self._lifted(sim, 0.5)
        far = np.array([[10.0, 2.0, 10.0]])
        np.testing.assert_allclose(sim.ray(far, far - [0, 4, 0]), [[10.0, 0.0, 10.0]], atol=1e-6)
        sim.add_box([0.5, 0.2, 0.5], [10.0, 0.2, 10.0])
        assert sim.ray(far, far - [0, 4, 0])[0, 1] == pytest.approx(0.4, abs=1e-6)
        flat = sim.ray(np.array([[19.0, 2.0, 21.0]]), np.array([[19.0, -2.0, 21.0]]))[0]
        assert flat[1] == pytest.approx(0.0, abs=1e-3)
        assert np.isnan(sim.ray(np.array([[0.0, 5.0, 0.0]]), np.array([[0.0, 4.0, 0.0]]))).all()

    def test_boxes_are_where_they_say(self, sim):
        """Two boxes, one turned 30° about z (y up): rays find both tops; 40 more are all kept."""
        import math

        self._lifted(sim, 0.5)
        a = math.radians(30.0)
        half = np.array([[0.5, 0.1, 0.5], [1.0, 0.1, 0.5]])
        pos = np.array([[-10.0, 0.1, -10.0], [-13.0, 0.0, -10.0]])
        orn = np.array([[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, math.sin(a / 2), math.cos(a / 2)]])
        bodies = sim.add_boxes(half, pos, orn)
        down = np.array([[-10.2, 3.0, -10.0], [-13.0, 3.0, -10.0], [-12.5, 3.0, -10.0]])
        hits = sim.ray(down, down - [0.0, 6.0, 0.0])
        assert hits[0, 1] == pytest.approx(0.2, abs=1e-6)  # the flat box's top
        top_centre = 0.1 / math.cos(a)  # the turned box's top above its centre line
        assert hits[1, 1] == pytest.approx(top_centre, abs=1e-6)
        assert hits[2, 1] == pytest.approx(top_centre + 0.5 * math.tan(a), abs=1e-6)  # rising at 30°
        for body in bodies:
            sim.remove(body)
        assert sim.ray(down[:1], down[:1] - [0.0, 6.0, 0.0])[0, 1] == pytest.approx(0.0, abs=1e-6)
        n = 40  # a row of small boxes, 0.5 m apart, each 0.1 m higher than the last
        xs = 20.0 + 0.5 * np.arange(n)
        many = sim.add_boxes(np.tile([0.2, 0.05, 0.2], (n, 1)), np.stack([xs, 0.1 * np.arange(n), np.full(n, 20.0)], 1),
                             np.tile([0.0, 0.0, 0.0, 1.0], (n, 1)))
        tops = sim.ray(np.stack([xs, np.full(n, 9.0), np.full(n, 20.0)], 1),
                       np.stack([xs, np.full(n, -1.0), np.full(n, 20.0)], 1))[:, 1]
        np.testing.assert_allclose(tops, 0.1 * np.arange(n) + 0.05, atol=1e-6)
        for body in many:
            sim.remove(body)

    def test_render_is_an_rgb_frame(self, sim):
        self._lifted(sim, 0.1)
        img = sim.render(64, 48)
        assert img.shape == (48, 64, 3) and img.dtype == np.uint8 and img.std() > 0
