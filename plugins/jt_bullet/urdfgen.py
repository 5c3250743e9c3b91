"""Generated URDFs: the thesis' snakes and a mesh-free Atlas, written to a cache directory.

Files are named by a hash of their content, written atomically, and deterministic: the same call
always yields the same bytes, so parallel workers can share the cache.

* ``snake_urdf(k)``: a floating root segment and ``k`` segments on spherical joints (a chain, so
  the depth ``d`` equals ``n = 6 + 3k`` as in thesis ``001`` Table 2.1). Segments are boxes
  0.1 x 0.04 x 0.04 m of 0.5 kg laid along +x (our choice; the thesis gives no dimensions).
* ``atlas_urdf()``: kinematics and inertial parameters of ``atlas/atlas_v4_with_multisense.urdf``
  from bullet3's ``data/`` (itself from OSRF drcsim / OpenAI roboschool), which the pip
  ``pybullet_data`` does not ship. Visual meshes are dropped and collision geometry is the file's
  primitives minus its small backpack handles. Z-up like the original.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

from toolkit.store import atomic

SNAKE_SEGMENT = {"length": 0.1, "width": 0.04, "mass": 0.5}


def cache_dir() -> Path:
    """``$JT_CACHE_DIR/urdf`` or ``~/.cache/jt/urdf`` (created)."""
    root = os.environ.get("JT_CACHE_DIR") or os.path.join(os.path.expanduser("~"), ".cache", "jt")
    path = Path(root) / "urdf"
    path.mkdir(parents=True, exist_ok=True)
    return path


def write_cached(stem: str, text: str) -> str:
    """Write ``text`` to ``<cache>/<stem>-<hash>.urdf`` unless present; returns the path."""
    digest = hashlib.sha256(text.encode()).hexdigest()[:12]
    path = cache_dir() / f"{stem}-{digest}.urdf"
    if not path.exists():
        atomic.write_text(path, text)
    return str(path)


def _f(x: float) -> str:
    return repr(float(x))


def _inertial(m: float, com: tuple, I: tuple) -> str:
    ixx, ixy, ixz, iyy, iyz, izz = I
    return (f'<inertial><origin xyz="{" ".join(_f(c) for c in com)}" rpy="0 0 0"/>'
            f'<mass value="{_f(m)}"/><inertia ixx="{_f(ixx)}" ixy="{_f(ixy)}" ixz="{_f(ixz)}" '
            f'iyy="{_f(iyy)}" iyz="{_f(iyz)}" izz="{_f(izz)}"/></inertial>')


def _geometry(kind: str, dims: tuple) -> str:
    if kind == "box":
        return f'<box size="{" ".join(_f(d) for d in dims)}"/>'
    if kind == "cylinder":
        return f'<cylinder length="{_f(dims[0])}" radius="{_f(dims[1])}"/>'
    return f'<sphere radius="{_f(dims[0])}"/>'


def _shape(tag: str, kind: str, xyz: tuple, rpy: tuple, dims: tuple) -> str:
    return (f'<{tag}><origin xyz="{" ".join(_f(c) for c in xyz)}" '
            f'rpy="{" ".join(_f(c) for c in rpy)}"/><geometry>{_geometry(kind, dims)}</geometry>'
            f'</{tag}>')


def snake_urdf(k: int) -> str:
    """URDF text of a snake with a floating root segment and ``k`` spherical-jointed segments."""
    L, w, m = SNAKE_SEGMENT["length"], SNAKE_SEGMENT["width"], SNAKE_SEGMENT["mass"]
    ixx = m * (w * w + w * w) / 12.0
    iyy = izz = m * (L * L + w * w) / 12.0
    parts = [f'<?xml version="1.0"?>\n<robot name="snake{6 + 3 * k}">']
    for s in range(k + 1):
        parts.append(f'<link name="seg{s}">' + _inertial(m, (0.0, 0.0, 0.0), (ixx, 0, 0, iyy, 0, izz))
                     + _shape("collision", "box", (0, 0, 0), (0, 0, 0), (L, w, w))
                     + _shape("visual", "box", (0, 0, 0), (0, 0, 0), (L, w, w)) + "</link>")
        if s > 0:
            parts.append(f'<joint name="j{s}" type="spherical"><parent link="seg{s - 1}"/>'
                         f'<child link="seg{s}"/><origin xyz="{_f(L)} 0 0" rpy="0 0 0"/></joint>')
    parts.append("</robot>\n")
    return "\n".join(parts)


# --- Atlas v4 (bullet3 data/atlas/atlas_v4_with_multisense.urdf), values verbatim -------------
# link: mass, com, (ixx, ixy, ixz, iyy, iyz, izz), collisions [(kind, xyz, rpy, dims)]
_H = 1.5707963267949
_CLAV = (4.466, (0, -0.048, -0.084), (0.011, 0, 0, 0.009, 0.004, 0.004),
         [("cylinder", (0, -0.11, -0.248), (0, _H, 0), (0.1525, 0.0555)),
          ("cylinder", (0.005, -0.015, -0.08), (0, 0, 0), (0.26, 0.067)),
          ("box", (0.004, -0.064, -0.247), (1.05, 0, 0), (0.1, 0.07, 0.072))])
_UFARM = (4.386, (0, 0.065, 0), (0.00656, 0, 0, 0.00358, 0, 0.00656),
          [("cylinder", (0, -0.13, 0.004), (0, 1.5708, 0), (0.125, 0.045)),
           ("box", (0.001, -0.053, -0.002), (0, 0, 0), (0.135, 0.1, 0.045))])
_FOOT = (2.41, (0.027, 0, -0.067), (0.002, 0, 0, 0.007, 0, 0.008),
         [("box", (0.023, 0, -0.049119), (0, 0, 0), (0.327, 0.233887, 0.05))])
_LFARM = (2.509, (0, 0, 0), (0.00265, 0, 0, 0.00446, 0, 0.00446),
          [("cylinder", (0.001, -0.1, -0.01), (_H, 0, 0), (0.05, 0.03)),
           ("box", (0.001, -0.05, -0.01), (0, 0, 0), (0.13, 0.09, 0.07))])
_LARM = (3.248, (0, 0, 0), (0.00265, 0, 0, 0.00446, 0, 0.00446),
         [("cylinder", (0.001, -0.127, 0), (_H, 0, 0), (0.125, 0.045)),
          ("box", (0.001, -0.051, 0), (0, 0, 0), (0.135, 0.15, 0.06))])
_SCAP = (3.899, (0, 0, 0), (0.00319, 0, 0, 0.00583, 0, 0.00583),
         [("cylinder", (-0.005, -0.115, -0.014), (_H, 0, 0), (0.105, 0.057)),
          ("box", (-0.005, -0.075, -0.015), (0, 0, 0), (0.16, 0.17, 0.08))])
_TALUS = (0.125, (0, 0, 0), (1.01674e-05, 0, 0, 8.42775e-06, 0, 1.30101e-05),
          [("cylinder", (0, 0, 0), (0, _H, 0), (0.029542, 0.010181))])
_UARM = (4.386, (0, 0.065, 0), (0.00656, 0, 0, 0.00358, 0, 0.00656),
         [("cylinder", (0, -0.035, 0), (1.5708, 0, 0), (0.11, 0.065)),
          ("cylinder", (-0.005, -0.111, 0.017), (0, 1.5708, 0), (0.142, 0.047))])
_ATLAS_LINKS = {
    "pelvis": (80.309, (0.0638, 0, 0.0071), (0.1244, 0.0008, -0.0007, 0.0958, -0.0005, 0.1167),
               [("cylinder", (-0.03, 0, 0.01), (_H, 0, 0), (0.06, 0.11)),
                ("cylinder", (0.01, 0.042, 0.09), (0, 0, 0), (0.05, 0.16)),
                ("cylinder", (0.01, -0.042, 0.09), (0, 0, 0), (0.05, 0.16)),
                ("box", (-0.1, 0, -0.02), (0, 0, 0), (0.1, 0.15, 0.2))]),
    "ltorso": (2.270, (-0.0112984, -3.15366e-06, 0.0746835),
               (0.0039092, -5.04491e-08, -0.000342157, 0.00341694, 4.87119e-07, 0.00174492), []),
    "mtorso": (0.799, (-0.00816266, -0.0131245, 0.0305974),
               (0.000454181, -6.10764e-05, 3.94009e-05, 0.000483282, 5.27463e-05, 0.000444215),
               [("cylinder", (0, 0, 0.02), (0, 0, 0), (0.15, 0.02))]),
    "utorso": (4.409, (-0.0622, 0.0023, 0.3157), (1.577, -0.032, 0.102, 1.602, 0.047, 0.565),
               [("box", (-0.102, 0, 0.25), (0, 0, 0), (0.4, 0.35, 0.5)),
                ("box", (0.2, 0, 0.46), (0, 1.5707, 0), (0.13, 0.5, 0.1)),
                ("box", (0.2, 0, 0.285), (0, 1.7, 0), (0.2, 0.23, 0.1)),
                ("box", (0.15, 0, 0.1), (0, 2.0, 0), (0.2, 0.18, 0.1)),
                ("box", (-0.035, 0, 0.6265), (0, 0, 0), (0.506306, 0.341719, 0.12))]),
    "head": (1.41984, (-0.075493, 3.3383e-05, 0.02774),
             (0.0039688, -1.5797e-06, -0.00089293, 0.0041178, -6.8415e-07, 0.0035243),
             [("box", (-0.0503, 0, -0.00195), (0, 0, 0), (0.1311, 0.12, 0.0591)),
              ("box", (-0.093, 0, 0.0868), (0, 0, 0), (0.0468, 0.12, 0.1184))]),
    "l_clav": _CLAV, "r_clav": _CLAV, "l_scap": _SCAP, "r_scap": _SCAP,
    "l_uarm": _UARM, "r_uarm": _UARM, "l_larm": _LARM, "r_larm": _LARM,
    "l_ufarm": _UFARM, "r_ufarm": _UFARM, "l_lfarm": _LFARM, "r_lfarm": _LFARM,
    "l_hand": (1.0, (0, 0, 0), (0.0001, 0, 0, 0.0001, 0, 0.0001),
               [("sphere", (0, -0.15, 0.01), (0, 0, 0), (0.03,))]),
    "r_hand": (1.0, (0, 0, 0), (0.0001, 0, 0, 0.0001, 0, 0.0001),
               [("sphere", (0, -0.15, -0.01), (0, 0, 0), (0.03,))]),
    "l_uglut": (1.959, (0.00529262, -0.00344732, 0.00313046),
                (0.00074276, -3.79607e-08, -2.79549e-05, 0.000688179, -3.2735e-08, 0.00041242),
                [("box", (0.01, 0.005, 0), (0.52539, 0, 0), (0.05, 0.1, 0.1)),
                 ("cylinder", (0, 0, 0), (0, 0, 0), (0.080842, 0.019841))]),
    "r_uglut": (1.959, (0.00529262, 0.00344732, 0.00313046),
                (0.00074276, 3.79607e-08, -2.79549e-05, 0.000688179, 3.2735e-08, 0.00041242),
                [("box", (0.01, -0.005, 0), (-0.52539, 0, 0), (0.05, 0.1, 0.1)),
                 ("cylinder", (0, 0, 0), (0, 0, 0), (0.080842, 0.019841))]),
    "l_lglut": (0.898, (0.0133341, 0.0170484, -0.0312052),
                (0.000691326, -2.24344e-05, 2.50508e-06, 0.00126856, 0.000137862, 0.00106487),
                [("box", (0.015, 0.026, -0.028), (0, 0, 0), (0.125, 0.05, 0.08)),
                 ("cylinder", (0.0115, 0, 0), (0, _H, 0), (0.144, 0.02))]),
    "r_lglut": (0.898, (0.0133341, -0.0170484, -0.0312052),
                (0.000691326, 2.24344e-05, 2.50508e-06, 0.00126856, -0.000137862, 0.00106487),
                [("box", (0.015, -0.026, -0.028), (0, 0, 0), (0.125, 0.05, 0.08)),
                 ("cylinder", (0.0105, 0, 0), (0, _H, 0), (0.142, 0.02))]),
    "l_uleg": (8.204, (0, 0, -0.21), (0.09, 0, 0, 0.09, 0, 0.02),
               [("cylinder", (-0.0199, 0.00585, -0.122), (0, 0, 0), (0.15, 0.09)),
                ("cylinder", (-0.032, -0.005, -0.224), (0, -0.3, 0), (0.15, 0.07))]),
    "r_uleg": (8.204, (0, 0, -0.21), (0.09, 0, 0, 0.09, 0, 0.02),
               [("cylinder", (-0.0199, -0.00585, -0.122), (0, 0, 0), (0.15, 0.09)),
                ("cylinder", (-0.032, 0.005, -0.224), (0, -0.3, 0), (0.15, 0.07))]),
    "l_lleg": (4.515, (0.001, 0, -0.187), (0.077, 0, -0.003, 0.076, 0, 0.01),
               [("cylinder", (0.02, 0.00295, -0.182), (0, 0.1, 0), (0.4, 0.07))]),
    "r_lleg": (4.515, (0.001, 0, -0.187), (0.077, 0, -0.003, 0.076, 0, 0.01),
               [("cylinder", (0.02, -0.00295, -0.182), (0, 0.1, 0), (0.4, 0.07))]),
    "l_talus": _TALUS, "r_talus": _TALUS, "l_foot": _FOOT, "r_foot": _FOOT,
}
_PI = 3.14159265359
# joint: name, parent, child, xyz, rpy, axis, lower, upper, effort, velocity  (depth-first order)
ATLAS_JOINTS = [
    ("back_bkz", "pelvis", "ltorso", (-0.0125, 0, 0), (0, 0, 0), (0, 0, 1), -0.663225, 0.663225, 106, 12),
    ("back_bky", "ltorso", "mtorso", (0, 0, 0.162), (0, 0, 0), (0, 1, 0), -0.219388, 0.538783, 445, 9),
    ("back_bkx", "mtorso", "utorso", (0, 0, 0.05), (0, 0, 0), (1, 0, 0), -0.523599, 0.523599, 300, 12),
    ("l_arm_shz", "utorso", "l_clav", (0.1406, 0.2256, 0.4776), (0, 0, _PI), (0, 0, 1), -1.5708, 0.785398, 87, 12),
    ("l_arm_shx", "l_clav", "l_scap", (0, -0.11, -0.245), (0, 0, 0), (-1, 0, 0), -1.5708, 1.5708, 99, 12),
    ("l_arm_ely", "l_scap", "l_uarm", (0, -0.187, -0.016), (0, 0, 0), (0, -1, 0), 0, 3.14159, 63, 12),
    ("l_arm_elx", "l_uarm", "l_larm", (0, -0.119, 0.0092), (0, 0, 0), (-1, 0, 0), 0, 2.35619, 112, 12),
    ("l_arm_wry", "l_larm", "l_ufarm", (0, -0.187, -0.0092), (0, _PI, 0), (0, -1, 0), 0, 3.14159, 25, 12),
    ("l_arm_wrx", "l_ufarm", "l_lfarm", (0, -0.119, 0.0092), (0, 0, 0), (1, 0, 0), -1.1781, 1.1781, 25, 12),
    ("l_arm_wry2", "l_lfarm", "l_hand", (0, 0, 0), (0, _PI, 0), (0, 1, 0), -0.001, 0.001, 5, 1),
    ("neck_ry", "utorso", "head", (0.2546, 0, 0.6215), (0, 0, 0), (0, 1, 0), -0.602139, 1.14319, 5, 6.28),
    ("r_arm_shz", "utorso", "r_clav", (0.1406, -0.2256, 0.4776), (0, 0, 0), (0, 0, 1), -0.785398, 1.5708, 87, 12),
    ("r_arm_shx", "r_clav", "r_scap", (0, -0.11, -0.245), (0, 0, 0), (1, 0, 0), -1.5708, 1.5708, 99, 12),
    ("r_arm_ely", "r_scap", "r_uarm", (0, -0.187, -0.016), (0, 0, 0), (0, 1, 0), 0, 3.14159, 63, 12),
    ("r_arm_elx", "r_uarm", "r_larm", (0, -0.119, 0.0092), (0, 0, 0), (1, 0, 0), -2.35619, 0, 112, 12),
    ("r_arm_wry", "r_larm", "r_ufarm", (0, -0.187, -0.0092), (0, 0, 0), (0, 1, 0), 0, 3.14159, 25, 12),
    ("r_arm_wrx", "r_ufarm", "r_lfarm", (0, -0.119, 0.0092), (0, 0, 0), (1, 0, 0), -1.1781, 1.1781, 25, 12),
    ("r_arm_wry2", "r_lfarm", "r_hand", (0, 0, 0), (0, 0, 0), (0, 1, 0), -0.001, 0.001, 5, 1),
    ("l_leg_hpz", "pelvis", "l_uglut", (0, 0.089, 0), (0, 0, 0), (0, 0, 1), -0.174358, 0.786794, 275, 12),
    ("l_leg_hpx", "l_uglut", "l_lglut", (0, 0, 0), (0, 0, 0), (1, 0, 0), -0.523599, 0.523599, 530, 12),
    ("l_leg_hpy", "l_lglut", "l_uleg", (0, 0, 0), (0, 0, 0), (0, 1, 0), -1.61234, 0.65764, 840, 12),
    ("l_leg_kny", "l_uleg", "l_lleg", (0, 0, -0.374), (0, 0, 0), (0, 1, 0), 0, 2.35637, 890, 12),
    ("l_leg_aky", "l_lleg", "l_talus", (0, 0, -0.422), (0, 0, 0), (0, 1, 0), -1, 0.7, 92, 12),
    ("l_leg_akx", "l_talus", "l_foot", (0, 0, 0), (0, 0, 0), (1, 0, 0), -0.8, 0.8, 45, 12),
    ("r_leg_hpz", "pelvis", "r_uglut", (0, -0.089, 0), (0, 0, 0), (0, 0, 1), -0.786794, 0.174358, 275, 12),
    ("r_leg_hpx", "r_uglut", "r_lglut", (0, 0, 0), (0, 0, 0), (1, 0, 0), -0.523599, 0.523599, 530, 12),
    ("r_leg_hpy", "r_lglut", "r_uleg", (0, 0, 0), (0, 0, 0), (0, 1, 0), -1.61234, 0.65764, 840, 12),
    ("r_leg_kny", "r_uleg", "r_lleg", (0, 0, -0.374), (0, 0, 0), (0, 1, 0), 0, 2.35637, 890, 12),
    ("r_leg_aky", "r_lleg", "r_talus", (0, 0, -0.422), (0, 0, 0), (0, 1, 0), -1, 0.7, 92, 12),
    ("r_leg_akx", "r_talus", "r_foot", (0, 0, 0), (0, 0, 0), (1, 0, 0), -0.8, 0.8, 45, 12),
]


def atlas_urdf() -> str:
    """URDF text of the mesh-free Atlas v4 (30 revolute joints)."""
    order = ["pelvis"] + [j[2] for j in ATLAS_JOINTS]
    parts = ['<?xml version="1.0"?>\n<robot name="atlas">']
    for name in order:
        m, com, I, shapes = _ATLAS_LINKS[name]
        body = "".join(_shape("collision", k, x, r, d) + _shape("visual", k, x, r, d)
                       for k, x, r, d in shapes)
        parts.append(f'<link name="{name}">{_inertial(m, com, I)}{body}</link>')
    for name, par, ch, xyz, rpy, ax, lo, hi, eff, vel in ATLAS_JOINTS:
        parts.append(
            f'<joint name="{name}" type="revolute"><parent link="{par}"/><child link="{ch}"/>'
            f'<origin xyz="{" ".join(_f(c) for c in xyz)}" rpy="{" ".join(_f(c) for c in rpy)}"/>'
            f'<axis xyz="{" ".join(_f(c) for c in ax)}"/>'
            f'<limit lower="{_f(lo)}" upper="{_f(hi)}" effort="{_f(eff)}" velocity="{_f(vel)}"/>'
            f'</joint>')
    parts.append("</robot>\n")
    return "\n".join(parts)
