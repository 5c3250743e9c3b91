"""What a spacetime clip decides by its name: the heading axis and the links allowed on the ground.

Both the task (to build the env's spec) and the env (a spec that leaves them ``None``) resolve them
here, so the per-clip rule is written once (research notes: the authors' code).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

#: the clips whose heading is taken from the root's z axis (authors' code; research notes)
Z_HEADING = ("backflip", "roll", "crawl")
FEET = ("right_ankle", "left_ankle")
HANDS = ("right_wrist", "left_wrist")
#: links allowed on the ground per clip (research notes: the authors' evaluation); others: the feet
ALLOWED_CONTACTS: dict[str, Any] = {
    "cartwheel": FEET + HANDS,
    "crawl": "all but root, chest, neck",
    "roll": "all",
    "getup_facedown": "all",
    "getup_faceup": "all",
}


def clip_stem(clip: str) -> str:
    """``run`` for ``run``, ``humanoid3d_run.txt`` or a path to it."""
    return Path(str(clip)).stem.replace("humanoid3d_", "")


def heading_axis(clip: str, axis: Optional[str] = None) -> str:
    """The root axis whose ground projection is the heading: ``axis`` if given, else ``z`` for the
    clips of ``Z_HEADING`` and ``x`` for the others."""
    if axis is not None:
        return str(axis)
    return "z" if clip_stem(clip) in Z_HEADING else "x"


def allowed_links(skeleton: Any, clip: str, names: Optional[list] = None) -> tuple[int, ...]:
    """Link indices allowed on the ground: ``names`` (link names, ``base``; ``["all"]``), else the
    clip's entry of ``ALLOWED_CONTACTS`` (feet by default). Indices in ``skeleton``'s link order:
    the humanoid's are the simulator's link indices (tests/plugins/jt_tasks/test_link_names.py)."""
    links = ["base"] + list(skeleton.links)
    index = {n: i - 1 for i, n in enumerate(links)}  # base = -1
    if names is None:
        entry = ALLOWED_CONTACTS.get(clip_stem(clip), FEET)
        if entry == "all":
            names = links
        elif isinstance(entry, str):  # "all but ..."
            names = [n for n in links if n not in ("base", "root", "chest", "neck")]
        else:
            names = list(entry)
    elif list(names) == ["all"]:
        names = links
    return tuple(sorted(index[str(n)] for n in names))
