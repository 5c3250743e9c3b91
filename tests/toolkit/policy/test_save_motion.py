"""save_motion: the filmstrip as rendered, the GIF of every frame large enough to watch."""

import numpy as np
from PIL import Image

from toolkit.policy.train import save_motion


def test_filmstrip_and_a_gif_you_can_watch(tmp_path):
    frames = [np.full((90, 120, 3), 10 * i, np.uint8) for i in range(12)]
    assert save_motion(tmp_path, frames, n_filmstrip=4, fps=30.0) == ["filmstrip.png", "motion.gif"]
    with Image.open(tmp_path / "filmstrip.png") as im:
        assert im.size == (4 * 120, 90)
    with Image.open(tmp_path / "motion.gif") as im:
        assert im.size == (360, 270) and im.n_frames == 12
        assert im.info["duration"] in (33, 30, 40)  # ~1/30 s a frame (GIF stores 10 ms units)
    assert save_motion(tmp_path / "none", [], 4) == []
