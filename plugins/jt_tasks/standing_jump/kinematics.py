"""Planar forward kinematics of the 17-link character, from its 19 joint coordinates.

Every hinge turns about world y, so a link's pitch is the root pitch plus the signed sum of the
joint angles above it, and positions follow by 2-D rotations. Doing it here (pure Python floats)
is cheaper per control step than asking PyBullet for link states, and gives the controller
exactly the quantities it needs: link pitches and rates, joint positions, the whole-body centre of
mass and its velocity. Tests check it against ``pybullet.getLinkStates``.

Conventions: z up, x forward; a pitch ``phi`` about +y maps a frame vector ``(x, z)`` to
``(cos phi * x + sin phi * z, -sin phi * x + cos phi * z)`` in the world.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Sequence

from jt_tasks.standing_jump.model import ROOT_JOINTS, Body


@dataclasses.dataclass
class Frame:
    """Kinematic state of the character at one instant (world frame, SI units).

    Attributes:
        pitch: pitch of each of the 17 links about +y, link order of ``Body.links`` ``(17,)``.
        omega: pitch rate of each link ``(17,)``.
        joint_pos: world ``(x, z)`` of each link's joint (the pelvis: the hip centre) ``(17, 2)``.
        com: whole-body centre of mass ``(x, z)``.
        com_vel: its velocity ``(vx, vz)``.
        link_com: world CoM of each link ``(17, 2)``.
        link_vel: world velocity of each link's CoM ``(17, 2)``.
    """

    pitch: list[float]
    omega: list[float]
    joint_pos: list[tuple[float, float]]
    com: tuple[float, float]
    com_vel: tuple[float, float]
    link_com: list[tuple[float, float]]
    link_vel: list[tuple[float, float]]


class PlanarKinematics:
    """Forward kinematics for a ``Body`` given joint coordinates in PyBullet's joint order.

    Args:
        body: the character.
        joint_names: PyBullet's joint names in index order (the 3 root joints and the 16 hinges).
    """

    def __init__(self, body: Body, joint_names: Sequence[str]) -> None:
        self.body = body
        index = {n: i for i, n in enumerate(joint_names)}
        self.root = [index[n] for n in ROOT_JOINTS]
        names = [link.name for link in body.links]
        self.parent = [names.index(link.parent) if link.parent else -1 for link in body.links]
        self.qi = [index[link.joint] if link.joint else -1 for link in body.links]
        self.axis = [float(link.axis) for link in body.links]
        self.origin = [(link.origin[0], link.origin[2]) for link in body.links]
        self.c = [link.com for link in body.links]
        self.m = [link.mass for link in body.links]
        self.inertia = [link.inertia for link in body.links]
        self.mass = sum(self.m)
        self._links = [(i, self.parent[i], self.qi[i], self.axis[i], self.origin[i], self.c[i], self.m[i])
                       for i in range(len(self.parent))]
        for i, p in enumerate(self.parent):
            assert p < i, "links must be ordered parents first"

    def frame(self, q: Sequence[float], qd: Sequence[float]) -> Frame:
        """Positions, pitches and velocities for joint positions ``q`` and rates ``qd`` ``(19,)``."""
        n = len(self.parent)
        pitch = [0.0] * n
        omega = [0.0] * n
        cs = [(1.0, 0.0)] * n
        jp: list[tuple[float, float]] = [(0.0, 0.0)] * n
        jv: list[tuple[float, float]] = [(0.0, 0.0)] * n
        lc: list[tuple[float, float]] = [(0.0, 0.0)] * n
        lv: list[tuple[float, float]] = [(0.0, 0.0)] * n
        mx = mz = mvx = mvz = 0.0
        rx, rz, rp = self.root
        cos, sin = math.cos, math.sin
        for i, p, j, a, (ox, oz), (cx, cz), m in self._links:
            if p < 0:
                ph, w = q[rp], qd[rp]
                px, pz, vx, vz = q[rx], q[rz], qd[rx], qd[rz]
            else:
                c, s = cs[p]
                dx, dz = c * ox + s * oz, -s * ox + c * oz
                px, pz = jp[p]
                vx, vz = jv[p]
                wp = omega[p]
                px, pz, vx, vz = px + dx, pz + dz, vx + wp * dz, vz - wp * dx
                ph, w = pitch[p] + a * q[j], wp + a * qd[j]
            pitch[i] = ph
            omega[i] = w
            c, s = cos(ph), sin(ph)
            cs[i] = (c, s)
            jp[i] = (px, pz)
            jv[i] = (vx, vz)
            dx, dz = c * cx + s * cz, -s * cx + c * cz
            x, z, ux, uz = px + dx, pz + dz, vx + w * dz, vz - w * dx
            lc[i] = (x, z)
            lv[i] = (ux, uz)
            mx += m * x
            mz += m * z
            mvx += m * ux
            mvz += m * uz
        M = self.mass
        return Frame(pitch, omega, jp, (mx / M, mz / M), (mvx / M, mvz / M), lc, lv)

    def angular_momentum(self, fr: Frame) -> float:
        """Whole-body angular momentum about the CoM, y component (kg m²/s; + = pitching forward)."""
        cx, cz = fr.com
        vcx, vcz = fr.com_vel
        L = 0.0
        for i, m in enumerate(self.m):
            rx, rz = fr.link_com[i][0] - cx, fr.link_com[i][1] - cz
            vx, vz = fr.link_vel[i][0] - vcx, fr.link_vel[i][1] - vcz
            L += m * (rz * vx - rx * vz) + self.inertia[i] * fr.omega[i]
        return L

    @staticmethod
    def point(frame: Frame, link: int, local: tuple[float, float]) -> tuple[float, float]:
        """World ``(x, z)`` of a point given in a link's frame."""
        c, s = math.cos(frame.pitch[link]), math.sin(frame.pitch[link])
        x, z = local
        jx, jz = frame.joint_pos[link]
        return jx + c * x + s * z, jz - s * x + c * z
