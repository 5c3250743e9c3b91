"""Animations a researcher can see: GIFs at least 320 px wide, smoke-sized frames left small."""

import importlib.util

import numpy as np
import pytest
from PIL import Image

from toolkit.render import enlarge, save_animation


def _frames(w, h, n=4):
    out = []
    for i in range(n):
        f = np.full((h, w, 3), 230, np.uint8)
        f[h // 4: h // 2, i * w // n: (i + 1) * w // n] = (150, 60, 20)  # a block that moves
        out.append(f)
    return out


def test_gif_is_at_least_320_px_wide_and_keeps_every_frame(tmp_path):
    frames = _frames(120, 90)
    path = save_animation(frames, tmp_path / "m.gif", fps=10)
    with Image.open(path) as im:
        assert (im.width, im.height, im.n_frames) == (360, 270, 4)  # 3 × 120: whole pixels
        im.seek(1)
        big = np.asarray(im.convert("RGB"))
    np.testing.assert_array_equal(big[::3, ::3], frames[1])  # the same picture, each pixel repeated


def test_smoke_and_large_frames_stay_as_rendered(tmp_path):
    assert enlarge(_frames(64, 48))[0].shape == (48, 64, 3)  # smoke presets: fast, not for watching
    assert enlarge(_frames(400, 300))[0].shape == (300, 400, 3)
    assert enlarge(_frames(160, 120))[0].shape == (240, 320, 3)
    with Image.open(save_animation(_frames(120, 90), tmp_path / "raw.gif", min_width=0)) as im:
        assert im.width == 120


@pytest.mark.skipif(importlib.util.find_spec("imageio_ffmpeg") is None,
                    reason="imageio-ffmpeg is not installed (the README's install has it: .[video])")
def test_mp4_keeps_every_frame_at_the_gif_size(tmp_path):
    import imageio.v3 as iio

    frames = _frames(160, 120, n=12)
    path = save_animation(frames, tmp_path / "m.mp4", fps=30)
    back = iio.imread(path)
    assert back.shape == (12, 240, 320, 3)  # enlarged as the GIF is (2 × 160)
    # lossy: the moving block is where it was in each frame, within a codec's error
    for i in (0, 5, 11):
        err = [np.abs(back[i, ::2, ::2].astype(int) - frames[j]).mean() for j in range(12)]
        assert int(np.argmin(err)) == i and err[i] < 0.5 * sorted(err)[1]
