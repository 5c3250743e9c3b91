"""Pictures of decoded poses: still poses rendered by the simulator that renders a skeleton's
character (``Simulator.render_poses``, found by ``toolkit.motion.kinematics.engine``), tiled into
one PNG filmstrip with ``toolkit.render``. The camera looks at the root from the character's right
side (+z in the DeepMimic y-up world).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from toolkit.motion.skeletons import Skeleton
from toolkit.render import filmstrip


def save_filmstrip(skeleton: Skeleton, dofs: np.ndarray, path: str | Path, columns: int = 0) -> Path:
    """Render poses ``(n, n_dof)`` (dof layout; root at the origin, upright) and write them as one
    PNG filmstrip."""
    import imageio.v3 as iio

    from toolkit.motion.kinematics import engine

    frames = engine("render_poses").render_poses(skeleton, dofs)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    iio.imwrite(path, filmstrip(frames, columns))
    return path
