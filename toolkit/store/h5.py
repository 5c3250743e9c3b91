"""HDF5 artifacts: nested dicts of arrays written atomically (temp file + rename).

An interrupted write never leaves a truncated file: data goes to ``<name>.tmp-<pid>`` in the same
directory, is flushed and fsynced, then renamed over the target (``toolkit.store.atomic``).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Mapping

import h5py
import numpy as np

from toolkit.store.atomic import atomic_write


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
    with atomic_write(path) as tmp:
        with h5py.File(tmp, "w") as f:
            for k, v in (attrs or {}).items():
                f.attrs[str(k)] = v if isinstance(v, (int, float, str, np.ndarray)) else str(v)
            _write_group(f, data)
            f.flush()
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


def _fmt_value(v: Any, limit: int = 80) -> str:
    if isinstance(v, bytes):
        v = v.decode(errors="replace")
    if isinstance(v, np.ndarray) and v.dtype.kind == "S":
        v = v.astype(str)
    if isinstance(v, np.ndarray):
        text = np.array2string(v, threshold=8, edgeitems=3, max_line_width=10_000)
    else:
        text = str(v)
    text = " ".join(text.split())
    return text if len(text) <= limit else text[: limit - 1] + "…"


def preview(path: str | os.PathLike, max_lines: int = 400) -> str:
    """A short text view of an HDF5 file: every group and dataset (shape, dtype, and the values
    of small ones: at most 8 elements) and every attribute, indented by depth.

    Args:
        path: the ``.h5`` file.
        max_lines: cut the listing after this many lines (says how many more there are).

    Returns:
        The text, ending with a newline (what ``<name>.h5.txt`` beside an artifact holds).
    """
    path = Path(path)
    lines = [f"{path.name}: HDF5, {path.stat().st_size} bytes", "# name  shape dtype  [= values]    @attribute = value"]

    def attrs(obj: Any, pad: str) -> None:
        for k, v in obj.attrs.items():
            lines.append(f"{pad}@{k} = {_fmt_value(v)}")

    def walk(g: "h5py.Group", pad: str) -> None:
        attrs(g, pad)
        for key, item in g.items():
            if isinstance(item, h5py.Group):
                lines.append(f"{pad}{key}/")
                walk(item, pad + "  ")
            else:
                if item.shape is None:  # an empty (null dataspace) dataset
                    lines.append(f"{pad}{key}  empty {item.dtype}")
                    attrs(item, pad + "  ")
                    continue
                shape = "scalar" if item.shape == () else "×".join(map(str, item.shape))
                text = f"{pad}{key}  {shape} {item.dtype}"
                if item.size <= 8:
                    text += f"  = {_fmt_value(item[()])}"
                lines.append(text)
                attrs(item, pad + "  ")

    with h5py.File(path, "r") as f:
        walk(f, "")
    if len(lines) > max_lines:
        lines = [*lines[:max_lines], f"… {len(lines) - max_lines} more lines"]
    return "\n".join(lines) + "\n"
