"""The pose dataset for the pose priors (P-VAE ``000`` §4.2, C-VAE ``003`` §3.5), in HDF5.

``build_dataset`` resamples every humanoid clip of ``pybullet_data`` (30 Hz by default), adds
the left/right mirror of each, computes pose features and get-up conditions, and writes one HDF5
file atomically with ``toolkit.store.h5.write`` (a temp file next to it, fsync, ``os.replace``).
Clips named in ``held_out`` (and their mirrors) go to the ``held_out`` group instead of ``train``.

File layout::

    /            attrs: format, version, skeleton, rate_hz, mirror, held_out (JSON),
                        feature_layout (JSON), condition_names (JSON), ground_height,
                        entries (JSON: one record per clip copy: name, source, sha256,
                        mirrored, split, loop, rate_hz, n_frames, source_fps)
    /<split>/features    (n, n_features) float64   pose features (features.py)
    /<split>/conditions  (n, 3)          float64   (h, theta_side, theta_front)
    /<split>/root_pos    (n, 3)  /root_rot (n, 4) /joints (n, n_q)   the raw poses
    /<split>/entry       (n,) int32      index into the entries record
    /<split>/time        (n,) float64    time of the frame in its clip
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
from typing import Sequence

import numpy as np

from toolkit.motion.clips import Clip, load_humanoid_clips
from toolkit.motion.features import CONDITION_NAMES, FeatureLayout, clip_features

FORMAT = "jt.pose_dataset"
VERSION = 1
DEFAULT_RATE = 30.0  # Hz: the top control rate of 000 §4.1 / §6.1.3 and the control rate of 002 §5
ARRAYS = ("features", "conditions", "root_pos", "root_rot", "joints", "entry", "time")


@dataclasses.dataclass
class PoseSplit:
    """One split's per-frame arrays (see the module docstring for shapes)."""

    features: np.ndarray
    conditions: np.ndarray
    root_pos: np.ndarray
    root_rot: np.ndarray
    joints: np.ndarray
    entry: np.ndarray
    time: np.ndarray

    def __len__(self) -> int:
        return int(self.features.shape[0])


@dataclasses.dataclass
class PoseDataset:
    """A loaded pose dataset.

    Attributes:
        layout: the feature layout.
        entries: one dict per clip copy (name, mirrored, split, n_frames, rate_hz, ...).
        splits: ``"train"`` and, if any clip was held out, ``"held_out"``.
        attrs: the file's root attributes (provenance).
    """

    layout: FeatureLayout
    entries: list[dict]
    splits: dict[str, PoseSplit]
    attrs: dict

    @property
    def train(self) -> PoseSplit:
        return self.splits["train"]

    @property
    def held_out(self) -> PoseSplit | None:
        return self.splits.get("held_out")


def _sha256(path: str) -> str:
    if not path:
        return ""
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def build_dataset(
    path: str | os.PathLike,
    rate: float = DEFAULT_RATE,
    mirror: bool = True,
    held_out: Sequence[str] = (),
    clips: Sequence[Clip] | None = None,
    ground_height: float = 0.0,
) -> PoseDataset:
    """Build the pose dataset and write it to ``path``.

    Args:
        path: output ``.h5`` file (parent folders are created).
        rate: resampling rate in Hz.
        mirror: add the left/right mirror of every clip.
        held_out: clip names whose frames go to the ``held_out`` split.
        clips: clips to use; all ``humanoid3d_*`` clips of ``pybullet_data`` when ``None``.
        ground_height: ground level for the neck-height condition.

    Returns:
        The dataset as ``load_dataset`` would read it back.
    """
    from toolkit.store import h5  # imports h5py

    clips = list(load_humanoid_clips() if clips is None else clips)
    if not clips:
        raise ValueError("no clips to build a dataset from")
    names = [c.name for c in clips]
    unknown = [n for n in held_out if n not in names]
    if unknown:
        raise KeyError(f"held-out clips {unknown} are not among {names}")
    if len({c.skeleton.name for c in clips}) != 1:
        raise ValueError("all clips of a dataset must share one skeleton")

    rows: dict[str, dict[str, list]] = {"train": {k: [] for k in ARRAYS}, "held_out": {k: [] for k in ARRAYS}}
    entries, layout = [], None
    for clip in clips:
        sha = _sha256(clip.source)
        base = clip.resample(rate)
        for copy in [base, base.mirror()] if mirror else [base]:
            split = "held_out" if clip.name in held_out else "train"
            feats, cond, layout = clip_features(copy, ground_height)
            r = rows[split]
            for key, val in (("features", feats), ("conditions", cond), ("root_pos", copy.root_pos),
                             ("root_rot", copy.root_rot), ("joints", copy.joints),
                             ("entry", np.full(copy.n_frames, len(entries), np.int32)), ("time", copy.times)):
                r[key].append(val)  # fmt: skip
            entries.append({
                "name": clip.name, "source": clip.source, "sha256": sha, "mirrored": bool(copy.mirrored),
                "split": split, "loop": bool(copy.loop), "rate_hz": float(copy.fps),
                "n_frames": int(copy.n_frames), "source_fps": float(clip.fps),
            })  # fmt: skip

    attrs = {
        "format": FORMAT, "version": VERSION, "skeleton": clips[0].skeleton.name,
        "rate_hz": float(rate), "mirror": bool(mirror), "held_out": json.dumps(list(held_out)),
        "feature_layout": layout.to_json(), "condition_names": json.dumps(list(CONDITION_NAMES)),
        "ground_height": float(ground_height), "entries": json.dumps(entries), "clip_names": json.dumps(names),
    }  # fmt: skip
    data = {split: {k: np.concatenate(r[k], axis=0) for k in ARRAYS} for split, r in rows.items() if r["features"]}
    h5.write(path, data, attrs)  # temp file in the same folder, fsync, os.replace
    return load_dataset(path)


def load_dataset(path: str | os.PathLike) -> PoseDataset:
    """Read a file written by ``build_dataset``.

    Raises:
        ValueError: the file is not a jt pose dataset of a known version.
    """
    import h5py

    path = os.fspath(path)
    with h5py.File(path, "r") as f:
        attrs = {k: (v.item() if isinstance(v, np.generic) else v) for k, v in f.attrs.items()}
        if attrs.get("format") != FORMAT or attrs.get("version") != VERSION:
            found = f"format={attrs.get('format')!r}, version={attrs.get('version')!r}"
            raise ValueError(f"{path}: not a {FORMAT} v{VERSION} file ({found})")
        splits = {name: PoseSplit(**{k: f[name][k][()] for k in ARRAYS}) for name in ("train", "held_out") if name in f}
    return PoseDataset(
        layout=FeatureLayout.from_json(attrs["feature_layout"]), entries=json.loads(attrs["entries"]),
        splits=splits, attrs=attrs,
    )  # fmt: skip


def main(argv: Sequence[str] | None = None) -> None:
    """``python -m toolkit.motion.dataset OUT.h5 [--rate 30] [--no-mirror] [--held-out NAME ...]``."""
    import argparse

    ap = argparse.ArgumentParser(description="Build jt's pose dataset from the humanoid clips shipped in pybullet_data.")
    ap.add_argument("out")
    ap.add_argument("--rate", type=float, default=DEFAULT_RATE)
    ap.add_argument("--no-mirror", action="store_true")
    ap.add_argument("--held-out", nargs="*", default=[])
    a = ap.parse_args(argv)
    ds = build_dataset(a.out, a.rate, not a.no_mirror, a.held_out)
    sizes = {k: len(v) for k, v in ds.splits.items()}
    print(f"{a.out}: {sizes} frames, {ds.layout.size} features, {len(ds.entries)} clip copies")


if __name__ == "__main__":  # pragma: no cover
    main()
