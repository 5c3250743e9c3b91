"""The sagittal-plane humanoid of ``004`` §3: 17 links, 16 hinge joints, 80 kg, 1.60 m.

Segment masses, lengths, centre-of-mass positions and radii of gyration are de Leva's adjustment
of Zatsiorsky–Seluyanov's data for males (P. de Leva, *Adjustments to Zatsiorsky-Seluyanov's
segment inertia parameters*, J. Biomech. 29(9):1223–1230, 1996, Table 4), scaled to the paper's
80 kg and 1.60 m (``004`` §3). The trunk uses de Leva's three-part split (upper trunk C7–xiphoid,
middle trunk xiphoid–omphalion, lower trunk omphalion–hip centres), which gives the paper's
"back" and "abs" joints; de Leva's head+neck (vertex–C7) is split into a head (vertex–gonion) and
a neck link, which brings the count to the paper's 17 links:

    pelvis, abdomen, chest, neck, head,
    upper arm ×2, forearm ×2, hand ×2, thigh ×2, shank ×2, foot ×2

World frame: z up, x forward, the sagittal plane is x–z, every hinge turns about the world y axis.
The root (pelvis) moves in the plane through three root joints (prismatic x, prismatic z,
revolute pitch) hung off a fixed, massless world link. Joint angles are signed anatomically:
positive = flexion (hip, knee, shoulder, elbow, wrist, trunk and neck flexion, ankle dorsiflexion).
"""

from __future__ import annotations

import dataclasses
import hashlib
import os
import tempfile
from pathlib import Path
from typing import Optional

from toolkit.store import atomic

# de Leva 1996 Table 4 (males), reference stature 1741 mm:
#            length_mm, mass_fraction, com_fraction_from_proximal, radius_of_gyration_sagittal
DE_LEVA = {
    "head_neck": (242.9, 0.0694, 0.5002, 0.315),  # vertex–C7 ("head2"); CoM from vertex
    "head": (203.3, None, 0.5976, 0.376),  # vertex–mid-gonion; CoM from vertex
    "upper_trunk": (242.1, 0.1596, 0.5066, 0.505),  # C7–xiphoid ("upper trunk 2"); CoM from C7
    "middle_trunk": (215.5, 0.1633, 0.4502, 0.482),  # xiphoid–omphalion; CoM from xiphoid
    "lower_trunk": (145.7, 0.1117, 0.6115, 0.615),  # omphalion–hip centres; CoM from omphalion
    "upper_arm": (281.7, 0.0271, 0.5772, 0.285),  # shoulder–elbow centres
    "forearm": (268.9, 0.0162, 0.4574, 0.276),  # elbow–wrist centres
    "hand": (86.2, 0.0061, 0.7900, 0.628),  # wrist centre–3rd metacarpale
    "thigh": (422.2, 0.1416, 0.4095, 0.329),  # hip–knee centres
    "shank": (440.3, 0.0433, 0.4395, 0.251),  # knee–ankle centres ("shank 2")
    "foot": (258.1, 0.0137, 0.4415, 0.257),  # heel–toe tip; CoM from heel
}
SHOULDER_BELOW_C7_MM = 603.3 - 515.5  # de Leva trunk (C7–hip) minus trunk (shoulders–hip) lengths
# ankle centre height / stature (Winter, Biomechanics and Motor Control of Human Movement, Fig. 4.1)
ANKLE_HEIGHT_FRACTION = 0.039
HEEL_TO_ANKLE_FRACTION = 0.25  # horizontal heel→ankle-centre distance / foot length (our choice)
NECK_RADIUS = 0.055  # m, for the neck link's inertia (our choice)
NECK_MASS_FRACTION = 0.010  # share of de Leva's head+neck mass given to the neck link (our choice)

# Table 1 of 004 §3.2: effort weight per joint class (before normalisation to sum n).
EFFORT_WEIGHT = {"hip": 2.5, "knee": 2.0, "ankle": 1.0, "shoulder": 1.0, "elbow": 0.5, "wrist": 0.25,
                 "head": 1.0, "neck": 1.0, "back": 2.5, "abs": 3.0}


@dataclasses.dataclass(frozen=True)
class Link:
    """One rigid body of the character.

    Attributes:
        name: link name (``"thigh_l"``).
        parent: parent link name (``"pelvis"`` for the root's children; ``""`` for the pelvis).
        joint: the joint connecting it to the parent (``"hip_l"``), class = name without side.
        axis: +1 or -1, the hinge axis along world y; chosen so a positive angle is flexion.
        origin: joint position in the parent frame ``(x, y, z)`` at zero pose (m).
        com: centre of mass in the link frame ``(x, z)`` (m).
        mass: kg.
        inertia: moment of inertia about the hinge-parallel axis through the CoM (kg m²).
        shape: ``("capsule", radius, length)`` along z, or ``("box", sx, sy, sz)``; centred at ``com``
            for capsules, at ``shape_centre`` for boxes.
        shape_centre: centre of the collision/visual shape in the link frame ``(x, z)``.
        lower: joint lower limit (rad).
        upper: joint upper limit (rad).
    """

    name: str
    parent: str
    joint: str
    axis: int
    origin: tuple[float, float, float]
    com: tuple[float, float]
    mass: float
    inertia: float
    shape: tuple
    shape_centre: tuple[float, float]
    lower: float
    upper: float

    @property
    def joint_class(self) -> str:
        return self.joint[:-2] if self.joint[-2:] in ("_l", "_r") else self.joint


@dataclasses.dataclass(frozen=True)
class Body:
    """The whole character: links in URDF order (parents first) plus derived dimensions.

    Attributes:
        links: the 17 links, pelvis first.
        mass: total mass (kg).
        height: standing height, vertex above the ground (m).
        hip_height: hip-centre height when standing straight (the root's initial z, m).
        ankle_height: ankle-centre height above the sole (m).
        foot_length: heel to toe (m).
        heel_to_ankle: horizontal heel → ankle-centre distance (m).
        head_top: vertex position in the head frame ``(x, z)``.
    """

    links: tuple[Link, ...]
    mass: float
    height: float
    hip_height: float
    ankle_height: float
    foot_length: float
    heel_to_ankle: float
    head_top: tuple[float, float]

    def link(self, name: str) -> Link:
        return next(link for link in self.links if link.name == name)

    @property
    def joint_names(self) -> list[str]:
        """The 16 internal joints, in link order (pelvis has none)."""
        return [link.joint for link in self.links[1:]]


def build_body(mass: float = 80.0, height: float = 1.60) -> Body:
    """The 17-link body scaled to ``mass`` and ``height`` (``004`` §3: 80 kg, 160 cm).

    Lengths are de Leva's scaled uniformly so that the vertex stands at ``height`` with straight
    joints and the ankle centre at ``ANKLE_HEIGHT_FRACTION * height``.
    """
    chain_mm = (DE_LEVA["head_neck"][0] + DE_LEVA["upper_trunk"][0] + DE_LEVA["middle_trunk"][0]
                + DE_LEVA["lower_trunk"][0] + DE_LEVA["thigh"][0] + DE_LEVA["shank"][0])
    ankle_h = ANKLE_HEIGHT_FRACTION * height
    s = (height - ankle_h) / (chain_mm / 1000.0)

    def seg(key: str) -> tuple[float, float, float, float]:
        length, frac, com, rg = DE_LEVA[key]
        return length / 1000.0 * s, (frac or 0.0) * mass, com, rg

    L_hn, m_hn, _, _ = seg("head_neck")
    L_head, _, c_head, r_head = seg("head")
    L_neck = L_hn - L_head
    m_neck = NECK_MASS_FRACTION * mass
    m_head = m_hn - m_neck
    L_up, m_up, c_up, r_up = seg("upper_trunk")
    L_mid, m_mid, c_mid, r_mid = seg("middle_trunk")
    L_low, m_low, c_low, r_low = seg("lower_trunk")
    L_ua, m_ua, c_ua, r_ua = seg("upper_arm")
    L_fa, m_fa, c_fa, r_fa = seg("forearm")
    L_ha, m_ha, c_ha, r_ha = seg("hand")
    L_th, m_th, c_th, r_th = seg("thigh")
    L_sh, m_sh, c_sh, r_sh = seg("shank")
    L_ft, m_ft, c_ft, r_ft = seg("foot")
    heel = HEEL_TO_ANKLE_FRACTION * L_ft
    d_sh = SHOULDER_BELOW_C7_MM / 1000.0 * s

    def I(m: float, r: float, L: float) -> float:
        return m * (r * L) ** 2

    def up(name, parent, joint, axis, origin, L, m, c_from_top, r, radius, lo, hi):
        """A segment above its joint: from z=0 to z=L, CoM measured from the top (distal) end."""
        zc = L * (1.0 - c_from_top)
        return Link(name, parent, joint, axis, origin, (0.0, zc), m, I(m, r, L),
                    ("capsule", radius, max(L - 2 * radius, 1e-3)), (0.0, L / 2), lo, hi)

    def down(name, parent, joint, axis, origin, L, m, c_from_top, r, radius, lo, hi):
        """A segment hanging below its joint: from z=0 to z=-L, CoM measured from the joint."""
        return Link(name, parent, joint, axis, origin, (0.0, -L * c_from_top), m, I(m, r, L),
                    ("capsule", radius, max(L - 2 * radius, 1e-3)), (0.0, -L / 2), lo, hi)

    pelvis = up("pelvis", "", "", 1, (0, 0, 0), L_low, m_low, c_low, r_low, 0.12, 0, 0)
    links = [
        pelvis,
        up("abdomen", "pelvis", "abs", 1, (0, 0, L_low), L_mid, m_mid, c_mid, r_mid, 0.11, -0.6, 1.2),
        up("chest", "abdomen", "back", 1, (0, 0, L_mid), L_up, m_up, c_up, r_up, 0.12, -0.6, 1.2),
        dataclasses.replace(  # de Leva has no neck segment: a solid cylinder of radius NECK_RADIUS
            up("neck", "chest", "neck", 1, (0, 0, L_up), L_neck, m_neck, 0.5, 0.3, 0.045, -0.8, 0.8),
            inertia=m_neck * (3 * NECK_RADIUS ** 2 + L_neck ** 2) / 12.0),
        up("head", "neck", "head", 1, (0, 0, L_neck), L_head, m_head, c_head, r_head, 0.095, -0.8, 0.8),
    ]
    for side, y in (("l", 1.0), ("r", -1.0)):
        links += [
            down(f"upper_arm_{side}", "chest", f"shoulder_{side}", -1, (0, 0.19 * y, L_up - d_sh),
                 L_ua, m_ua, c_ua, r_ua, 0.045, -1.3, 3.2),
            down(f"forearm_{side}", f"upper_arm_{side}", f"elbow_{side}", -1, (0, 0, -L_ua),
                 L_fa, m_fa, c_fa, r_fa, 0.038, 0.0, 2.6),
            down(f"hand_{side}", f"forearm_{side}", f"wrist_{side}", -1, (0, 0, -L_fa),
                 L_ha, m_ha, c_ha, r_ha, 0.035, -1.2, 1.2),
            down(f"thigh_{side}", "pelvis", f"hip_{side}", -1, (0, 0.09 * y, 0),
                 L_th, m_th, c_th, r_th, 0.07, -0.7, 2.6),
            down(f"shank_{side}", f"thigh_{side}", f"knee_{side}", 1, (0, 0, -L_th),
                 L_sh, m_sh, c_sh, r_sh, 0.05, 0.0, 2.7),
        ]
        foot_h = ankle_h
        links.append(Link(
            f"foot_{side}", f"shank_{side}", f"ankle_{side}", -1, (0, 0, -L_sh),
            (L_ft * c_ft - heel, -foot_h / 2), m_ft, I(m_ft, r_ft, L_ft),
            ("box", L_ft, 0.09, foot_h), (L_ft / 2 - heel, -foot_h / 2), -1.0, 0.7))
    return Body(links=tuple(links), mass=mass, height=height, hip_height=ankle_h + L_sh + L_th,
                ankle_height=ankle_h, foot_length=L_ft, heel_to_ankle=heel,
                head_top=(0.0, L_head))


# ---- URDF ------------------------------------------------------------------------------------------

ROOT_JOINTS = ("root_x", "root_z", "root_pitch")


def _geometry(shape: tuple) -> str:
    if shape[0] == "capsule":
        return f'<capsule radius="{shape[1]:.6f}" length="{shape[2]:.6f}"/>'
    return f'<box size="{shape[1]:.6f} {shape[2]:.6f} {shape[3]:.6f}"/>'


def _link_xml(link: Link, rgba: tuple[float, float, float, float]) -> str:
    cx, cz = link.com
    sx, sz = link.shape_centre
    i = max(link.inertia, 1e-6)
    geo = _geometry(link.shape)
    col = " ".join(f"{c:.3f}" for c in rgba)
    return (
        f'  <link name="{link.name}">\n'
        f'    <inertial><origin xyz="{cx:.6f} 0 {cz:.6f}"/><mass value="{link.mass:.6f}"/>'
        f'<inertia ixx="{i:.8f}" iyy="{i:.8f}" izz="{i:.8f}" ixy="0" ixz="0" iyz="0"/></inertial>\n'
        f'    <visual><origin xyz="{sx:.6f} 0 {sz:.6f}"/><geometry>{geo}</geometry>'
        f'<material name="m_{link.name}"><color rgba="{col}"/></material></visual>\n'
        f'    <collision><origin xyz="{sx:.6f} 0 {sz:.6f}"/><geometry>{geo}</geometry></collision>\n'
        f'  </link>\n')


def urdf_text(body: Body, rgba: tuple[float, float, float, float] = (0.55, 0.36, 0.2, 1.0)) -> str:
    """URDF of the planar character: a fixed world link, three root joints, the 17 links.

    Args:
        body: the character.
        rgba: colour of every link (the paper draws natural jumps brown, supernatural ones blue).
    """
    out = ['<?xml version="1.0"?>\n<robot name="planar_humanoid">\n', '  <link name="world"/>\n']
    dummy = '<inertial><mass value="0"/><inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial>'
    out.append(f'  <link name="root_x_link">{dummy}</link>\n  <link name="root_z_link">{dummy}</link>\n')
    big = 'effort="0" velocity="1000" lower="-1000" upper="1000"'
    out.append(f'  <joint name="root_x" type="prismatic"><parent link="world"/><child link="root_x_link"/>'
               f'<axis xyz="1 0 0"/><limit {big}/></joint>\n')
    out.append(f'  <joint name="root_z" type="prismatic"><parent link="root_x_link"/><child link="root_z_link"/>'
               f'<axis xyz="0 0 1"/><limit {big}/></joint>\n')
    out.append('  <joint name="root_pitch" type="continuous"><parent link="root_z_link"/><child link="pelvis"/>'
               '<axis xyz="0 1 0"/></joint>\n')
    for link in body.links:
        out.append(_link_xml(link, rgba))
    for link in body.links[1:]:
        ox, oy, oz = link.origin
        out.append(
            f'  <joint name="{link.joint}" type="revolute"><parent link="{link.parent}"/>'
            f'<child link="{link.name}"/><origin xyz="{ox:.6f} {oy:.6f} {oz:.6f}"/>'
            f'<axis xyz="0 {link.axis} 0"/><limit effort="0" velocity="100" lower="{link.lower:.4f}" '
            f'upper="{link.upper:.4f}"/></joint>\n')
    out.append("</robot>\n")
    return "".join(out)


def write_urdf(body: Body, rgba: tuple[float, float, float, float] = (0.55, 0.36, 0.2, 1.0),
               cache_dir: Optional[os.PathLike] = None) -> Path:
    """Write the URDF once to a content-addressed file and return its path.

    The file name is the SHA-1 of the text, so the same body always maps to the same file and
    concurrent writers (worker processes) cannot corrupt each other (write to a temp file, rename).

    Args:
        body: the character.
        rgba: link colour.
        cache_dir: where to write (default ``$TMPDIR/jt_standing_jump``).
    """
    text = urdf_text(body, rgba)
    digest = hashlib.sha1(text.encode()).hexdigest()[:16]
    folder = Path(cache_dir) if cache_dir else Path(tempfile.gettempdir()) / "jt_standing_jump"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"planar_humanoid_{digest}.urdf"
    if not path.exists():
        atomic.write_text(path, text)
    return path


def effort_weights(body: Body) -> dict[str, float]:
    """Table 1 weights per joint (``004`` §3.2), normalised so they sum to the number of joints."""
    raw = {j: EFFORT_WEIGHT[link.joint_class] for link, j in zip(body.links[1:], body.joint_names)}
    scale = len(raw) / sum(raw.values())
    return {j: w * scale for j, w in raw.items()}


def standing_head_height(body: Body) -> float:
    """Height of the head's centre of mass when standing straight (m)."""
    z = body.hip_height
    for name in ("abdomen", "chest", "neck", "head"):
        z += body.link(name).origin[2]
    return z + body.link("head").com[1]
