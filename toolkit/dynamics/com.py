"""Centre of mass of a configuration: forward kinematics over the tree (one numba kernel).

For every body ``i`` (parents first), ``joint_transforms`` gives ``X_i = (E_i, r_i)`` from the
parent's frame to body ``i``'s (``p_i = E_i (p_parent - r_i)``); composing them gives each body's
world rotation ``E^w_i = E_i E^w_parent`` and origin ``o^w_i = o^w_parent + E^{w T}_parent r_i``,
and the body's centre of mass in the world is ``o^w_i + E^{w T}_i c_i``. The whole-body CoM is the
mass-weighted mean. Bodies merged through fixed joints carry their combined mass and CoM
(as the simulator plugin builds the ``Model``), so the result equals PyBullet's link-by-link mean.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from toolkit.dynamics.kinematics import joint_transforms
from toolkit.dynamics.model import MI_PARENT, W_COLS, W_XE, W_XR, Model


@njit(cache=True)
def com_kernel(mi: np.ndarray, mf: np.ndarray, q: np.ndarray, wb: np.ndarray, sc: np.ndarray,
               mass: np.ndarray, com: np.ndarray, world: np.ndarray, out: np.ndarray) -> None:
    """Whole-body centre of mass of ``q`` into ``out`` ``(3,)``.

    Args:
        mi, mf: the model's packed tables.
        q: generalised positions ``(n_q,)``.
        wb: per-body workspace ``(n_bodies, W_COLS)``; sc: scratch ``(>= 27,)``.
        mass: body masses ``(n_bodies,)``; com: body-frame centres of mass ``(n_bodies, 3)``.
        world: scratch ``(n_bodies, 12)``: world rotation (row-major ``E^w``) and origin.
    """
    joint_transforms(mi, mf, q, wb, sc)
    nb = mi.shape[0]
    total = 0.0
    for a in range(3):
        out[a] = 0.0
    for i in range(nb):
        p = mi[i, MI_PARENT]
        E = wb[i, W_XE:W_XE + 9]
        r = wb[i, W_XR:W_XR + 3]
        Ew = world[i, 0:9]
        ow = world[i, 9:12]
        if p < 0:
            for a in range(9):
                Ew[a] = E[a]
            for a in range(3):
                ow[a] = r[a]
        else:
            Ep = world[p, 0:9]
            op = world[p, 9:12]
            for a in range(3):
                for b in range(3):
                    s = 0.0
                    for k in range(3):
                        s += E[3 * a + k] * Ep[3 * k + b]
                    Ew[3 * a + b] = s
            for a in range(3):
                ow[a] = op[a] + Ep[a] * r[0] + Ep[3 + a] * r[1] + Ep[6 + a] * r[2]
        m = mass[i]
        c = com[i]
        for a in range(3):
            out[a] += m * (ow[a] + Ew[a] * c[0] + Ew[3 + a] * c[1] + Ew[6 + a] * c[2])
        total += m
    for a in range(3):
        out[a] /= total


class CenterOfMass:
    """``com(q)`` of a model with its workspaces allocated once (hot-path use: every substep).

    Args:
        model: the character's ``toolkit.dynamics.Model``.
    """

    def __init__(self, model: Model) -> None:
        self.model = model
        nb = model.mi.shape[0]
        self._wb = np.zeros((nb, W_COLS))
        self._sc = np.zeros(64)
        self._world = np.zeros((nb, 12))
        self._mass = np.ascontiguousarray(model.mass, dtype=np.float64)
        self._com = np.ascontiguousarray(model.com, dtype=np.float64)

    def __call__(self, q: np.ndarray) -> np.ndarray:
        """The centre of mass ``(3,)`` (world) of configuration ``q`` ``(n_q,)``."""
        out = np.empty(3)
        com_kernel(self.model.mi, self.model.mf, np.ascontiguousarray(q, dtype=np.float64), self._wb,
                   self._sc, self._mass, self._com, self._world, out)
        return out
