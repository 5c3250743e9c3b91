"""The pose dataset: real HDF5 files, provenance, held-out clips, atomic writes."""

from __future__ import annotations

import json
import os

import h5py
import numpy as np
import pytest

from toolkit.motion.clips import load_humanoid_clips
from toolkit.motion.dataset import build_dataset, load_dataset
from toolkit.motion.features import clip_features


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    clips = load_humanoid_clips(["walk", "run", "getup_faceup"])
    path = tmp_path_factory.mktemp("ds") / "poses.h5"
    return path, clips, build_dataset(path, rate=30.0, held_out=["run"], clips=clips)


def test_written_file_and_provenance(small):
    path, clips, ds = small
    assert path.exists() and not list(path.parent.glob("*.tmp*"))
    with h5py.File(path, "r") as f:
        assert set(f) == {"train", "held_out"}
        assert f.attrs["rate_hz"] == 30.0 and bool(f.attrs["mirror"])
        assert json.loads(f.attrs["held_out"]) == ["run"]
    back = load_dataset(path)
    assert back.layout == ds.layout and back.layout.size == 147
    e = back.entries
    assert [(x["name"], x["mirrored"]) for x in e] == [(n, m) for n in ("walk", "run", "getup_faceup") for m in (False, True)]
    assert all(len(x["sha256"]) == 64 and os.path.exists(x["source"]) for x in e)
    assert {x["split"] for x in e if x["name"] == "run"} == {"held_out"}
    assert all(abs(x["rate_hz"] - 30.0) < 0.5 for x in e)
    # frame counts in the entries add up to the split sizes, and entry ids point at them
    for split, data in back.splits.items():
        ids = [i for i, x in enumerate(e) if x["split"] == split]
        assert len(data) == sum(e[i]["n_frames"] for i in ids)
        assert set(np.unique(data.entry)) == set(ids)
        assert data.features.shape == (len(data), 147) and data.conditions.shape == (len(data), 3)
        assert data.joints.shape == (len(data), 36)
    np.testing.assert_array_equal(back.train.features, ds.train.features)


def test_contents_equal_features_of_resampled_clips(small):
    _, clips, ds = small
    walk = clips[0].resample(30.0)
    f, c, _ = clip_features(walk)
    rows = ds.train.entry == 0
    np.testing.assert_allclose(ds.train.features[rows], f)
    np.testing.assert_allclose(ds.train.conditions[rows], c)
    np.testing.assert_allclose(ds.train.time[rows], walk.times)
    fm, _, _ = clip_features(walk.mirror())
    np.testing.assert_allclose(ds.train.features[ds.train.entry == 1], fm)
    assert ds.held_out is not None and np.all(np.isin(ds.held_out.entry, [2, 3]))


def test_reproducible_and_rebuild_replaces(tmp_path, small):
    _, clips, ds = small
    p = tmp_path / "again.h5"
    a = build_dataset(p, held_out=["run"], clips=clips)
    np.testing.assert_array_equal(a.train.features, ds.train.features)
    b = build_dataset(p, rate=15.0, mirror=False, clips=clips)  # overwrite in place
    assert b.held_out is None and not any(x["mirrored"] for x in b.entries)
    assert load_dataset(p).attrs["rate_hz"] == 15.0


def test_failures_leave_no_partial_file(tmp_path, small):
    _, clips, _ = small
    with pytest.raises(KeyError, match="not_a_clip"):
        build_dataset(tmp_path / "x.h5", held_out=["not_a_clip"], clips=clips)
    assert not (tmp_path / "x.h5").exists()
    target = tmp_path / "occupied"
    target.mkdir()  # os.replace onto a directory fails after the temp file is written
    with pytest.raises(OSError):
        build_dataset(target, clips=clips[:1])
    assert target.is_dir() and not list(tmp_path.glob("*.tmp*"))
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as f:
        f.attrs["format"] = "something else"
    with pytest.raises(ValueError, match="not a jt.pose_dataset"):
        load_dataset(other)


def test_full_default_dataset(tmp_path):
    ds = build_dataset(tmp_path / "all.h5")
    names = {x["name"] for x in ds.entries}
    assert len(names) == 15 and len(ds.entries) == 30 and ds.held_out is None
    assert 1800 < len(ds.train) < 2500  # ~34 s of mocap, twice, at 30 Hz
    assert np.all(np.isfinite(ds.train.features)) and np.all(np.isfinite(ds.train.conditions))
