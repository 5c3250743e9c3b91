"""HDF5 artifacts: nested dicts of arrays written atomically (temp file + rename).

An interrupted write never leaves a truncated file: data goes to ``<name>.tmp-<pid>`` in the same
directory, is flushed and fsynced, then renamed over the target with ``os.replace``.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Mapping

import h5py
import numpy as np


def _write_group(g: "h5py.Group", data: Mapping[str, Any]) -> None:
    for key, value in data.items():
        key = str(key)
        if isinstance(value, Mapping):
            _write_group(g.create_group(key), value)
        elif value is None:
            g.attrs[key] = "None"
        elif isinstance(value, (str, bytes)):
            g.create_dataset(key, data=value)
        else:
            arr = np.asarray(value)
            if arr.dtype.kind in "UO":
                g.create_dataset(key, data=arr.astype(object).astype(str).astype("S"))
            else:
                g.create_dataset(key, data=arr)


def write(path: str | os.PathLike, data: Mapping[str, Any], attrs: Mapping[str, Any] | None = None) -> Path:
    """Write ``data`` (nested dicts of arrays/scalars/strings) to ``path`` atomically.

    Args:
        path: target ``.h5`` file; parent directories are created.
        data: ``{name: array | scalar | str | nested dict}``; nested dicts become HDF5 groups.
        attrs: root attributes (provenance: versions, config, seeds).

    Returns:
        The path written.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f"{path.name}.tmp-{os.getpid()}")
    try:
        with h5py.File(tmp, "w") as f:
            for k, v in (attrs or {}).items():
                f.attrs[str(k)] = v if isinstance(v, (int, float, str, np.ndarray)) else str(v)
            _write_group(f, data)
            f.flush()
        with open(tmp, "rb") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def _read_group(g: "h5py.Group") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, item in g.items():
        if isinstance(item, h5py.Group):
            out[key] = _read_group(item)
        else:
            value = item[()]
            if isinstance(value, bytes):
                value = value.decode()
            elif isinstance(value, np.ndarray) and value.dtype.kind == "S":
                value = value.astype(str)
            out[key] = value
    for key, value in g.attrs.items():
        if value == "None":
            out[key] = None
    return out


def read(path: str | os.PathLike) -> dict[str, Any]:
    """Read a file written by ``write`` back into nested dicts of numpy arrays."""
    with h5py.File(path, "r") as f:
        return _read_group(f)


def read_attrs(path: str | os.PathLike) -> dict[str, Any]:
    """Root attributes of an HDF5 file."""
    with h5py.File(path, "r") as f:
        return {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
