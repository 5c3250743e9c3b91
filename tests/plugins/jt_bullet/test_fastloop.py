"""The compiled substep loop (``sim.loop=compiled``) against the Python loop, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from jt_bullet import capi
from jt_bullet.simulator import BulletSimulator
from toolkit.errors import JtError
from toolkit.interfaces.simulator import ContactRule, Watch


def make(loop: str, spd: str = "maba", **sim) -> BulletSimulator:
    return BulletSimulator({"sim": {"name": "bullet", "loop": loop, **sim},
                            "character": {"name": "humanoid"}, "spd": {"name": spd}})


def same(a, b, path="") -> None:
    """Records ``a`` and ``b`` equal exactly (arrays bitwise, NaNs in the same places)."""
    if isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for k in a:
            same(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, (tuple, list)) and a and isinstance(a[0], np.ndarray):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{path}[{i}]")
    elif isinstance(a, np.ndarray):
        assert a.shape == b.shape and np.array_equal(a, b, equal_nan=True), path
    else:
        assert a == b, (path, a, b)


def episode(sim: BulletSimulator, steps: int = 40, watch_every: int = 1, margin: float = 0.01) -> list[dict]:
    """A seeded episode: dropped from 10 cm onto a low box under one foot, random targets about the
    start pose; the ground rule with the feet excepted, a landing on the box that counts clear of the
    ground by ``margin``, the first touches of both and every record."""
    rng = np.random.default_rng(3)
    q, qd = sim.state()
    q[1] += 0.1
    sim.reset(q, qd)
    box = sim.add_box([0.25, 0.02, 0.25], [0.15, 0.02, 0.0])  # under one foot: landing on it asks near()
    land = ContactRule(box, "success", "landed", clear_of=sim.ground, margin=margin)
    w = Watch(rules=(ContactRule(sim.ground, "fail", "fell", except_links=(5, 11)), land),
              touches=(sim.ground, box), record=("time", "com", "root"), check_every=watch_every,
              time_limit=1.0)
    out = []
    for _ in range(steps):
        qt = q.copy()
        qt[7:] += 0.05 * rng.standard_normal(qt.size - 7)
        rec = sim.step(qt, watch=w)
        out.append(rec)
        if rec["outcome"] or rec["failed"]:
            break
    return out


@pytest.mark.parametrize("spd,margin,end", [("maba", 0.01, "landed"), ("df", 0.01, "landed"),
                                             ("sf", 0.01, "landed"), ("pcg", 0.01, "landed"),
                                             ("servo", 0.01, "landed"), ("maba", 1.0, "time limit")])
def test_the_compiled_loop_gives_the_python_loops_records(spd, margin, end):
    a, b = make("python", spd), make("compiled", spd)
    assert (a.loop, b.loop) == ("python", "compiled")
    try:
        ra, rb = episode(a, margin=margin), episode(b, margin=margin)
        assert len(ra) == len(rb) and ra[-1]["reason"] == end  # clear of the ground by 1 cm, not 1 m
        for x, y in zip(ra, rb):
            same(x, y)
        assert any(r["touched"] for r in ra)
        same(a.state(), b.state())
        assert a.time == b.time and a.timers["substeps"] == b.timers["substeps"]
        if spd == "pcg":
            assert a.backend.data.iterations == b.backend.data.iterations > 0
        if spd == "servo":  # constraint motors: PyBullet reports no torques in either loop
            assert np.isnan(ra[-1]["tau"]).all()
    finally:
        a.close()
        b.close()


def test_checks_every_few_substeps_and_time_limits_match():
    a, b = make("python", control_hz=10.0), make("compiled", control_hz=10.0)
    try:
        for x, y in zip(episode(a, 12, watch_every=7), episode(b, 12, watch_every=7)):
            same(x, y)
        q, _ = a.state()
        w = Watch(record=("time",), time_limit=a.time + 4.5 / 600.0, check_every=2)
        same(a.step(q, watch=w), b.step(q, watch=w))
    finally:
        a.close()
        b.close()


@pytest.mark.parametrize("setting,reason", [({"explode_speed": 0.5}, "exploded: |qd|"),
                                            ({"explode_distance": 0.5}, "exploded: root")])
def test_failures_are_the_same_in_both_loops(setting, reason):
    a, b = make("python", **setting), make("compiled", **setting)
    try:
        ra, rb = episode(a, 5), episode(b, 5)
        assert ra[-1]["failed"] and ra[-1]["reason"].startswith(reason)
        for x, y in zip(ra, rb):
            same(x, y)
        same(a.step(a.state()[0]), b.step(b.state()[0]))  # a failed simulator stays failed
    finally:
        a.close()
        b.close()


def test_a_nan_target_fails_both_loops_alike():
    a, b = make("python"), make("compiled")
    try:
        q, _ = a.state()
        q[10] = np.nan
        ra, rb = a.step(q), b.step(q)
        assert ra["failed"] and ra["substeps"] == 0
        same(ra, rb)
    finally:
        a.close()
        b.close()


def test_the_jumping_env_is_the_same_with_either_loop():
    from toolkit import plugins
    from toolkit.config import compose

    runs = []
    for loop in ("python", "compiled"):
        cfg = compose(["task=highjump", "action=raw", f"sim.loop={loop}"])
        env = plugins.load("task", "highjump")(cfg).make_env(seed=0)
        assert env.sim.loop == loop
        rng = np.random.default_rng(0)
        obs, _ = env.reset(seed=0)
        seq = [obs]
        for _ in range(30):
            a = rng.uniform(-1.0, 1.0, env.action_space.shape)
            obs, r, term, trunc, info = env.step(a)
            seq += [obs, r, term, trunc, info.get("reason", "")]
            if term or trunc:
                obs, _ = env.reset()
                seq.append(obs)
        env.close()
        runs.append(seq)
    assert len(runs[0]) == len(runs[1])
    for x, y in zip(*runs):
        same(x, y)


def test_auto_keeps_the_python_loop_where_the_compiled_one_cannot_run():
    s = make("auto", spd="bullet")
    try:
        assert s.loop == "python"
    finally:
        s.close()
    servo = make("auto", root_servo={"kp": 100.0, "kd": 10.0})
    try:
        assert servo.loop == "python"
    finally:
        servo.close()
    with pytest.raises(JtError, match=r"sim.loop=compiled: not available here: spd=bullet"):
        make("compiled", spd="bullet")
    with pytest.raises(JtError, match="choose auto, compiled or python"):
        BulletSimulator({"sim": {"name": "bullet", "loop": "fast"}, "character": {"name": "humanoid"},
                         "spd": {"name": "maba"}})
    from toolkit.config import compose

    with pytest.raises(JtError, match="sim.loop='fast': choose auto, compiled or python"):
        compose(["task=highjump", "sim.loop=fast"])


def test_the_c_handle_is_the_clients_own():
    import pybullet as pb

    lib, _f, array = capi.library()
    syms = capi.elf_symbols(pb.__file__, {"b3GetStatusType", "no_such_symbol"})
    assert set(syms) == {"b3GetStatusType"} and array
    a, b = make("compiled"), make("compiled")
    try:
        ha, _ = capi.handle(a.client, a.character.body_id)
        hb, _ = capi.handle(b.client, b.character.body_id)
        assert ha and hb and ha != hb
        b.add_box([0.1, 0.1, 0.1], [3.0, 0.1, 0.0])  # b now has one body more than a
        h, why = capi.handle(a.client, a.character.body_id)
        assert h == ha and not why
        assert capi.handle(1023, 0) == (0, "the client's C handle does not accept commands")
    finally:
        a.close()
        b.close()


def test_link_states_through_the_c_api_are_pybullets():
    a, b = make("python"), make("compiled")
    try:
        episode(a, 6)
        episode(b, 6)
        pa, oa = a.link_states()
        pb_, ob = b.link_states()
        assert pa.shape == (a.n_links + 1, 3) and ob.shape == (a.n_links + 1, 4)
        assert np.array_equal(pa, pb_) and np.array_equal(oa, ob)
        assert np.array_equal(b.link_states(base_only=True)[0], pb_[:1])
        assert not np.array_equal(pa[1], pa[2])  # real link positions, not one row repeated
    finally:
        a.close()
        b.close()


def test_link_frames_through_the_c_api_are_pybullets_forward_kinematics():
    import pybullet as pb

    b = make("compiled")
    try:
        episode(b, 4)
        q, qd = b.state()
        q[0] += 0.3
        b.reset(q, qd)  # after a reset, before a step: forward kinematics of the new state
        links = [-1, 0, 5, 11, 8, 14]
        pos, orn = b.link_poses(links)
        for k, link in enumerate(links):
            if link < 0:
                ref = pb.getBasePositionAndOrientation(b.character.body_id, physicsClientId=b.client)
            else:
                s = pb.getLinkState(b.character.body_id, link, computeForwardKinematics=True,
                                    physicsClientId=b.client)
                ref = s[4], s[5]
            assert np.array_equal(pos[k], ref[0]) and np.array_equal(orn[k], ref[1])
            assert np.array_equal(b.link_pose(link)[0], pos[k])
    finally:
        b.close()


def test_state_after_a_compiled_step_is_pybullets_without_a_second_read():
    """``state()`` after a compiled step returns the loop's last read (no C API request); it is
    PyBullet's state to the bit, and a reset makes the next ``state()`` read PyBullet again."""
    import pybullet as pb

    sim = make("compiled")
    try:
        episode(sim, 5)
        assert sim._state_read
        q, qd = sim.state()
        q2, qd2 = sim._compiled.read()  # a fresh request through the C API
        assert np.array_equal(q, q2) and np.array_equal(qd, qd2)
        base = pb.getBasePositionAndOrientation(sim.character.body_id, physicsClientId=sim.client)
        assert np.array_equal(q[:3], base[0]) and np.array_equal(q[3:7], base[1])
        q[3:7] *= 2.0  # not a unit quaternion: PyBullet stores it normalised
        sim.reset(q, qd)
        assert not sim._state_read
        stored, _ = sim.state()
        assert np.allclose(np.linalg.norm(stored[3:7]), 1.0) and sim._state_read
        stored[0] += 1.0  # a copy: the cache is not changed through it
        assert not np.array_equal(sim.state()[0], stored)
    finally:
        sim.close()
