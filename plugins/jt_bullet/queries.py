"""What an environment asks the ``bullet`` simulator besides stepping: batched link reads,
contacts, distances, rays, static scene bodies (boxes, heightfields) and rendering.

A mixin of ``BulletSimulator`` (it uses the simulator's ``client``, ``character``, ``_masses``,
``_link_ids`` and ``char_cfg``); every method is part of ``toolkit.interfaces.Simulator``, except
the classmethod ``planar_world``: a bullet-only extra that opens a ``jt_bullet.planar.PlanarWorld``
(a torque-controlled URDF of its own, e.g. the standing-jump paper's planar jumper).
"""

from __future__ import annotations

import math
from typing import Any, Optional, Sequence

import numpy as np

from toolkit.errors import JtError


COMPOUND_MAX = 16  #: PyBullet's MAX_COMPOUND_COLLISION_SHAPES: a compound body keeps its first 16 shapes
RAY_MASK = -1 ^ 1  #: every collision filter group but Bullet's DefaultFilter (1), the group of every dynamic body


class UnknownName(JtError, KeyError):
    """A link / joint name the character does not have: a one-line ``JtError`` that is also the
    ``KeyError`` callers caught before."""

    __str__ = Exception.__str__  # the message as written, not KeyError's quoted repr


class SceneQueries:
    """The query, scene and render half of ``toolkit.interfaces.Simulator`` on PyBullet."""

    # ------------------------------------------------------------------ the character
    @property
    def body_id(self) -> int:
        """PyBullet id of the character (for jt_bullet's own tools)."""
        return self.character.body_id

    @property
    def masses(self) -> np.ndarray:
        """Link masses ``(n_links + 1,)``, base first (kg)."""
        return self._masses

    def link_states(self, base_only: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Centre-of-mass positions ``(n_links + 1, 3)`` and orientations ``(n_links + 1, 4)`` of
        the base and every link (world frame, x, y, z, w); ``base_only`` reads row 0 alone."""
        import pybullet as pb

        kw, b = {"physicsClientId": self.client}, self.character.body_id
        compiled = getattr(self, "_compiled", None)
        if compiled and not base_only:  # the same request and fields through the C API
            return compiled.link_states()
        pos, orn = pb.getBasePositionAndOrientation(b, **kw)
        if base_only:
            return np.array([pos]), np.array([orn])
        states = pb.getLinkStates(b, self._link_ids, **kw)
        return np.array([pos] + [s[0] for s in states]), np.array([orn] + [s[1] for s in states])

    def link_velocities(self) -> tuple[np.ndarray, np.ndarray]:
        """World linear and angular velocities ``(n_links + 1, 3)`` of the base and every link's
        centre of mass, from the current joint velocities (PyBullet's getBaseVelocity and
        getLinkStates(computeLinkVelocity=1); the links' rotation to the world is the one cached
        at the last substep, as PyBullet reports it)."""
        import pybullet as pb

        kw, b = {"physicsClientId": self.client}, self.character.body_id
        compiled = getattr(self, "_compiled", None)
        if compiled:  # the same request and fields through the C API
            return compiled.link_velocities()
        lin, ang = pb.getBaseVelocity(b, **kw)
        states = pb.getLinkStates(b, self._link_ids, computeLinkVelocity=1, **kw)
        return np.array([lin] + [s[6] for s in states]), np.array([ang] + [s[7] for s in states])

    def link_index(self, name: str) -> int:
        """PyBullet index of the link called ``name``, else of the joint called ``name`` (its child
        link); -1 for ``"base"`` / ``"root"`` (when no link or joint has that name).

        Raises:
            UnknownName: no such link or joint (a ``JtError`` and ``KeyError``; lists the links).
        """
        from jt_bullet.scene import find_link

        try:
            return find_link(self.client, self.character.body_id, str(name))
        except KeyError as e:
            raise UnknownName(f"character {self.character.name!r}: {e.args[0]}") from None

    def com(self) -> np.ndarray:
        """The character's centre of mass ``(3,)`` now (forward kinematics of the current state)."""
        q, _ = self.state()
        return self.com_now(q)

    def com_now(self, q: np.ndarray) -> np.ndarray:
        """The CoM ``(3,)`` of configuration ``q`` by the model's forward kinematics (numba, a few
        µs; PyBullet's cached link frames lag one substep behind the integrated state)."""
        fk = getattr(self, "_com_fk", None)
        if fk is None:
            from toolkit.dynamics.com import CenterOfMass

            fk = self._com_fk = CenterOfMass(self.model)
        return fk(q)

    def link_pose(self, link: int) -> tuple[np.ndarray, np.ndarray]:
        """World position ``(3,)`` and orientation x, y, z, w ``(4,)`` of a link's URDF frame
        (-1: the base frame)."""
        import pybullet as pb

        kw, b = {"physicsClientId": self.client}, self.character.body_id
        compiled = getattr(self, "_compiled", None)
        if compiled:  # the same request and fields through the C API
            pos, orn = compiled.link_frames(np.array([int(link)], dtype=np.int64))
            return pos[0], orn[0]
        if link < 0:
            pos, orn = pb.getBasePositionAndOrientation(b, **kw)
        else:
            s = pb.getLinkState(b, link, computeForwardKinematics=True, **kw)
            pos, orn = s[4], s[5]
        return np.array(pos), np.array(orn)

    def link_poses(self, links: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
        """``link_pose`` of ``links``: positions ``(n, 3)``, orientations ``(n, 4)`` (one C API
        request for all of them where the compiled loop runs)."""
        compiled = getattr(self, "_compiled", None)
        if compiled:
            return compiled.link_frames(np.asarray(links, dtype=np.int64).reshape(-1))
        return super().link_poses(links)  # Simulator's: link_pose for each

    def aabb(self, link: int) -> tuple[np.ndarray, np.ndarray]:
        """World AABB ``(low (3,), high (3,))`` of a link (-1: the base)."""
        import pybullet as pb

        lo, hi = pb.getAABB(self.character.body_id, int(link), physicsClientId=self.client)
        return np.array(lo), np.array(hi)

    def contacts(self, body: Optional[int] = None) -> list[tuple[int, int]]:
        """``(scene body, character link)`` of every contact point now (of ``body`` only if given)."""
        import pybullet as pb

        kw = {"physicsClientId": self.client}
        if body is None:
            pts = pb.getContactPoints(bodyA=self.character.body_id, **kw)
        else:
            pts = pb.getContactPoints(bodyA=self.character.body_id, bodyB=int(body), **kw)
        return [(int(p[2]), int(p[3])) for p in pts]

    def near(self, body: int, margin: float) -> bool:
        """True when any part of the character is within ``margin`` m of scene ``body`` (-1: none)."""
        import pybullet as pb

        if body is None or body < 0:
            return False
        pts = pb.getClosestPoints(bodyA=self.character.body_id, bodyB=int(body), distance=float(margin),
                                  physicsClientId=self.client)
        return len(pts) > 0

    def ray(self, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
        """Hit points ``(n, 3)`` of rays ``starts -> ends`` ``(n, 3)`` against the scene, the
        character's own bodies ignored; NaN rows where a ray hits nothing else.

        While every other body is static, the rays are first cast with a collision filter mask
        without Bullet's default group (``RAY_MASK``: the group of every dynamic body, the
        character's), so a ray through a character lying on the ground reaches the ground under it
        in one batch. A ray that ends on a ground plane (or on nothing) keeps that hit: the same
        point as the all-hits cast below. Every other ray (one on a terrain box, where Bullet's
        closest-hit callback can differ from the all-hits one in the last bits, or any ray while
        something else moves) takes the general path: one cast against everything, and a ray whose
        first hit is the character is cast again reporting every hit along it (PyBullet's
        ``reportHitNumber``: Bullet's all-hits callback, in no particular order) and takes the
        nearest hit on anything else (re-casting from just past the first hit would start inside
        the body, which Bullet's ray test then misses on convex shapes).
        """
        starts, ends = np.asarray(starts, float).reshape(-1, 3), np.asarray(ends, float).reshape(-1, 3)
        out = np.full(starts.shape, np.nan)
        planes = self._static_planes()
        if planes is None:
            rest = np.arange(len(starts))
        else:
            rest = []
            for i, h in enumerate(self._cast(starts, ends, RAY_MASK)):
                if h[0] < 0 or h[0] in planes:
                    if h[0] >= 0:
                        out[i] = h[3]
                else:
                    rest.append(i)
            rest = np.asarray(rest, int)
        if len(rest):
            out[rest] = self._rays_general(starts[rest], ends[rest])
        return out

    def _cast(self, starts: np.ndarray, ends: np.ndarray, mask: int = -1, **kw: Any) -> list:
        """PyBullet's ``rayTestBatch`` results for rays ``(n, 3)`` in batches of its maximum size."""
        import pybullet as pb

        batch, hits = pb.MAX_RAY_INTERSECTION_BATCH_SIZE - 1, []
        for i0 in range(0, len(starts), batch):
            hits += pb.rayTestBatch(starts[i0:i0 + batch].tolist(), ends[i0:i0 + batch].tolist(),
                                    collisionFilterMask=mask, physicsClientId=self.client, **kw)
        return hits

    def _rays_general(self, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
        """:meth:`ray` against every body: one cast, then the all-hits cast where the character
        is hit first."""
        out = np.full(starts.shape, np.nan)
        me, blocked = self.character.body_id, []
        for i, h in enumerate(self._cast(starts, ends)):
            if h[0] >= 0 and h[0] != me:
                out[i] = h[3]
            elif h[0] == me:
                blocked.append(i)
        if blocked:
            out[blocked] = self._rays_past_character(starts[blocked], ends[blocked])
        return out

    def _static_planes(self) -> frozenset | None:
        """The ground plane's id (empty without one) while every body but the character is static
        (has no mass); None while something else moves. Cached until the number of bodies changes
        or :meth:`remove` removes one."""
        import pybullet as pb

        n = pb.getNumBodies(physicsClientId=self.client)
        if self._scene_planes is None or self._scene_planes[0] != n:
            me, kw = self.character.body_id, {"physicsClientId": self.client}
            others = [b for b in (pb.getBodyUniqueId(i, **kw) for i in range(n)) if b != me]
            static = all(pb.getDynamicsInfo(b, link, **kw)[0] == 0.0
                         for b in others for link in range(-1, pb.getNumJoints(b, **kw)))
            planes = frozenset([self.ground] if self.ground >= 0 else [])
            self._scene_planes = (n, planes if static else None)
        return self._scene_planes[1]

    def _rays_past_character(self, starts: np.ndarray, ends: np.ndarray, max_hits: int = 64) -> np.ndarray:
        """Nearest hit ``(n, 3)`` on a body other than the character along each ray (NaN: none), from
        the k-th hits of every ray, k = 0, 1, ... until no ray has a k-th hit."""
        import pybullet as pb

        me = self.character.body_id
        out = np.full(starts.shape, np.nan)
        best = np.full(len(starts), np.inf)
        batch = pb.MAX_RAY_INTERSECTION_BATCH_SIZE - 1
        for i0 in range(0, len(starts), batch):
            s, e = starts[i0:i0 + batch].tolist(), ends[i0:i0 + batch].tolist()
            for k in range(max_hits):
                hits = pb.rayTestBatch(s, e, reportHitNumber=k, physicsClientId=self.client)
                if all(h[0] < 0 for h in hits):
                    break
                for j, h in enumerate(hits):
                    if h[0] >= 0 and h[0] != me and h[2] < best[i0 + j]:
                        best[i0 + j], out[i0 + j] = h[2], h[3]
        return out

    # ------------------------------------------------------------------ scene
    def add_box(self, half_extents: Sequence[float], position: Sequence[float],
                orientation: Sequence[float] = (0.0, 0.0, 0.0, 1.0),
                rgba: Sequence[float] = (0.6, 0.6, 0.6, 1.0), friction: float = 0.9) -> int:
        """A static box; its handle (a PyBullet body id)."""
        import pybullet as pb

        kw = {"physicsClientId": self.client}
        half = [float(v) for v in half_extents]
        col = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=half, **kw)
        vis = pb.createVisualShape(pb.GEOM_BOX, halfExtents=half, rgbaColor=list(rgba), **kw)
        body = pb.createMultiBody(0.0, col, vis, list(map(float, position)), list(orientation), **kw)
        pb.changeDynamics(body, -1, lateralFriction=float(friction), **kw)
        return int(body)

    def add_boxes(self, half_extents: np.ndarray, positions: np.ndarray, orientations: np.ndarray,
                  rgba: Any = (0.6, 0.6, 0.6, 1.0), friction: float = 0.9) -> tuple[int, ...]:
        """Static boxes (half extents ``(n, 3)``, centres ``(n, 3)``, orientations ``(n, 4)``,
        colours ``rgba`` ``(4,)`` or ``(n, 4)``) as
        compound bodies of up to 16 boxes each (PyBullet's ``MAX_COMPOUND_COLLISION_SHAPES``: it
        drops the 17th on), a few kB however many (the get-up terrain's 108); their handles."""
        import pybullet as pb

        kw = {"physicsClientId": self.client}
        half = np.asarray(half_extents, dtype=float).reshape(-1, 3)
        pos = np.asarray(positions, dtype=float).reshape(-1, 3)
        orn = np.asarray(orientations, dtype=float).reshape(-1, 4)
        if not (len(half) == len(pos) == len(orn)) or len(half) == 0 or not np.all(half > 0):
            raise ValueError(f"add_boxes needs n >= 1 boxes with positive half extents and as many centres "
                             f"and orientations, got {len(half)}, {len(pos)}, {len(orn)}")
        colours = np.broadcast_to(np.asarray(rgba, dtype=float).reshape(-1, 4), (len(half), 4))
        bodies = []
        for at in range(0, len(half), COMPOUND_MAX):
            h, p, o, c = (v[at:at + COMPOUND_MAX].tolist() for v in (half, pos, orn, colours))
            n = len(h)
            col = pb.createCollisionShapeArray([pb.GEOM_BOX] * n, halfExtents=h, collisionFramePositions=p,
                                               collisionFrameOrientations=o, **kw)
            vis = pb.createVisualShapeArray([pb.GEOM_BOX] * n, halfExtents=h, visualFramePositions=p,
                                            visualFrameOrientations=o, rgbaColors=c, **kw)
            body = pb.createMultiBody(0.0, col, vis, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0], **kw)
            pb.changeDynamics(body, -1, lateralFriction=float(friction), **kw)
            bodies.append(int(body))
        return tuple(bodies)

    def remove(self, body: int) -> None:
        """Remove a scene body added by ``add_box`` / ``add_boxes``."""
        import pybullet as pb

        pb.removeBody(int(body), physicsClientId=self.client)
        self._scene_planes = None  # a body made next would leave the count as it was

    # ------------------------------------------------------------------ output
    def render(self, width: int = 320, height: int = 240, camera: Any = None,
               target: Optional[Sequence[float]] = None, mask: bool = False) -> Any:
        """RGB frame ``(height, width, 3)`` uint8 by TinyRenderer, looking at ``target`` (default:
        the root) with ``camera`` (default: the character's view, ``character.camera_*``); with
        ``mask``, ``(frame, character pixels (height, width) bool)``."""
        import pybullet as pb

        from jt_bullet.config import DEFAULT_CAMERA
        from jt_bullet.render import render_frame
        from toolkit.render import Camera

        if camera is None:
            d, yaw, pitch = DEFAULT_CAMERA.get(self.char_cfg.name, (3.0, 0.0, -10.0))
            c = self.char_cfg
            camera = Camera(distance=d if c.camera_distance is None else c.camera_distance,
                            yaw=yaw if c.camera_yaw is None else c.camera_yaw,
                            pitch=pitch if c.camera_pitch is None else c.camera_pitch)
        if target is None:
            pos, _ = pb.getBasePositionAndOrientation(self.character.body_id, physicsClientId=self.client)
            target = [v if math.isfinite(v) else 0.0 for v in pos]
        return render_frame(self.client, target, width, height, camera,
                            self.character.body_id if mask else None)

    # ------------------------------------------------------------------ bullet-only extras
    @classmethod
    def planar_world(cls, urdf_path: Any, sim_hz: float, friction: float,
                     gravity: float = -9.8) -> Any:
        """A torque-controlled fixed-base URDF on a ground plane in its own PyBullet client.

        For models simulated outside the character/SPD loop (``task=standing_jump``'s planar
        jumper); see ``jt_bullet.planar``. The caller closes it.

        Args:
            urdf_path: the model file (z up; its first joints place the root in the plane).
            sim_hz: simulation rate, Hz (the time step is ``1 / sim_hz``).
            friction: lateral friction of the ground and of every link.
            gravity: vertical gravity, m/s² (z axis).

        Returns:
            A ``jt_bullet.planar.PlanarWorld``.
        """
        from jt_bullet.planar import PlanarWorld

        return PlanarWorld(urdf_path, sim_hz, friction, gravity)
