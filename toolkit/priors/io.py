"""Save and load pose priors: one HDF5 file each, found by path or by the MLflow run that made it.

File layout (written atomically with ``toolkit.store.h5.write``)::

    /          attrs: format="jt.pose_prior", version, kind, skeleton, latent_dim,
                      feature_layout (JSON), condition_names (JSON), info (JSON)
    /weights/  enc{i}_w, enc{i}_b, mu_w, mu_b, logvar_w, logvar_b, dec{i}_w, dec{i}_b  (float32)
    /norm/     x_mean, x_std, c_mean, c_std      (float64; c_* empty for a P-VAE)
    /latent/   z_mean, z_std                     (whitening of the latent action)
    /metrics/  one scalar per metric (latent_dim, recon_rmse_heldout, pca_rmse_heldout, ...)

Every problem with a prior (no reference given, no such file or run, not a prior, a truncated or
inconsistent file, the wrong kind) is one ``JtError`` line that says how to make one.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Optional

import numpy as np

from toolkit.errors import JtError
from toolkit.motion.features import FeatureLayout
from toolkit.priors.model import KINDS, PosePrior

FORMAT = "jt.pose_prior"
VERSION = 1
FILENAME = "prior.h5"


def how_to_make(kind: str = "pvae") -> str:
    """The hint every prior error ends with."""
    return f"make one with: jt run task=pose_prior action={kind if kind in KINDS else 'pvae'}"


def _first_line(e: BaseException) -> str:
    text = str(e).strip()
    return text.splitlines()[0] if text else type(e).__name__


def save_prior(prior: PosePrior, path: str | os.PathLike) -> Path:
    """Write ``prior`` to ``path`` (atomic: temp file, fsync, rename)."""
    from toolkit.store import h5

    attrs = {
        "format": FORMAT, "version": VERSION, "kind": prior.kind, "skeleton": prior.layout.skeleton,
        "latent_dim": int(prior.latent_dim), "feature_layout": prior.layout.to_json(),
        "condition_names": json.dumps(list(prior.condition_names)),
        "info": json.dumps(prior.info, default=str),
    }  # fmt: skip
    data = {
        "weights": {k: np.asarray(v, dtype=np.float32) for k, v in prior.weights.items()},
        "norm": {"x_mean": prior.x_mean, "x_std": prior.x_std, "c_mean": prior.c_mean, "c_std": prior.c_std},
        "latent": {"z_mean": prior.z_mean, "z_std": prior.z_std},
        "metrics": {k: float(v) for k, v in prior.metrics.items()},
    }
    return h5.write(path, data, attrs)


def _is_prior_file(path: Path) -> bool:
    import h5py

    try:
        with h5py.File(path, "r") as f:
            fmt = f.attrs.get("format")
    except (OSError, ValueError):
        return False
    return (fmt.decode() if isinstance(fmt, bytes) else fmt) == FORMAT


def read_prior(path: str | os.PathLike, kind: Optional[str] = None) -> PosePrior:
    """Read a prior file; ``kind`` (if given) must match.

    Raises:
        JtError: missing, unreadable, not a prior, malformed, or of another kind.
    """
    import h5py

    path = Path(path)
    hint = how_to_make(kind or "pvae")
    if not path.is_file():
        raise JtError(f"no pose prior at {path}; {hint}")
    try:
        with h5py.File(path, "r") as f:
            attrs = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
            if attrs.get("format") != FORMAT:
                raise JtError(f"{path} is not a jt pose prior (format={attrs.get('format')!r}); {hint}")
            if int(attrs.get("version", -1)) != VERSION:
                raise JtError(f"{path}: pose prior version {attrs.get('version')} is not {VERSION}; {hint}")
            groups: dict[str, dict[str, Any]] = {}
            for g in ("weights", "norm", "latent", "metrics"):
                if g not in f:
                    raise JtError(f"{path}: malformed pose prior (no /{g}); {hint}")
                groups[g] = {k: f[g][k][()] for k in f[g]}
    except JtError:
        raise
    except (OSError, KeyError, ValueError) as e:
        raise JtError(f"{path}: unreadable pose prior ({_first_line(e)}); {hint}") from e
    try:
        w, norm, lat = groups["weights"], groups["norm"], groups["latent"]
        prior = PosePrior(
            kind=str(attrs["kind"]), layout=FeatureLayout.from_json(attrs["feature_layout"]),
            latent_dim=int(attrs["latent_dim"]), weights={k: np.asarray(v) for k, v in w.items()},
            x_mean=norm["x_mean"], x_std=norm["x_std"], c_mean=norm["c_mean"], c_std=norm["c_std"],
            z_mean=lat["z_mean"], z_std=lat["z_std"],
            condition_names=tuple(json.loads(attrs.get("condition_names", "[]"))),
            metrics={k: float(v) for k, v in groups["metrics"].items()},
            info=json.loads(attrs.get("info", "{}")),
        )  # fmt: skip
        _check_shapes(prior)
    except JtError:
        raise
    except (KeyError, ValueError, TypeError) as e:
        raise JtError(f"{path}: malformed pose prior ({type(e).__name__}: {_first_line(e)}); {hint}") from e
    if kind is not None and prior.kind != kind:
        raise JtError(f"{path} holds a {prior.kind} prior, action={kind} needs a {kind} one; {how_to_make(kind)}")
    return prior


def _check_shapes(p: PosePrior) -> None:
    """Raise ValueError when arrays do not fit together (a corrupted or hand-edited file)."""
    d, k, nc = p.layout.size, p.latent_dim, p.n_cond
    if p.x_mean.shape != (d,) or p.x_std.shape != (d,):
        raise ValueError(f"feature normalisation has shape {p.x_mean.shape}, layout has {d} columns")
    if p.z_mean.shape != (k,) or p.z_std.shape != (k,):
        raise ValueError(f"latent statistics have shape {p.z_mean.shape}, latent_dim is {k}")
    if p.conditional != (nc > 0):
        raise ValueError(f"a {p.kind} prior with {nc} condition entries")
    z = np.zeros((1, k))
    c = np.zeros((1, nc)) + p.c_mean if nc else None
    out = p.decode(z, c)
    if out.shape != (1, d) or not np.all(np.isfinite(out)):
        raise ValueError("the decoder does not map a latent to a finite feature row")
    mu, _ = p.encode(np.zeros((1, d)) + p.x_mean, c)
    if mu.shape != (1, k):
        raise ValueError(f"the encoder gives {mu.shape[-1]} latents, latent_dim is {k}")


def _find(ref: str, store_root: Optional[str], kind: str) -> Path:
    """The prior file ``action.prior=ref`` names (``toolkit.store.resolve``): ``prior.h5``, else any
    pose prior file, in a folder or one folder down, or among a run's (or its nested runs') artifacts."""
    from toolkit.store.resolve import resolve

    return resolve(ref, artifact=FILENAME, store=store_root, what="action.prior", label="pose prior",
                   hint=how_to_make(kind), accept=_is_prior_file).path


def load_prior(ref: Any, store_root: Optional[str] = None, kind: Optional[str] = None) -> PosePrior:
    """Load a prior from a file path, a folder holding one, or the id of the MLflow run that made it.

    A folder is searched for ``prior.h5`` (else any pose prior file) in it and one folder down, no
    deeper; a run id as ``toolkit.store.resolve`` does (its own artifacts, else its nested runs').

    Args:
        ref: path to a ``prior.h5`` (or a folder with one), or an MLflow run id.
        store_root: store to look the run up in (``$JT_STORE`` or ``./artifacts`` when ``None``).
        kind: the kind the caller needs (``"pvae"`` / ``"cvae"``), checked if given.

    Raises:
        JtError: one line, ending with how to make a prior.
    """
    text = "" if ref is None else str(ref).strip()
    if not text:
        need = kind or "pvae"
        raise JtError(f"action={need} needs a pose prior (action.prior=RUN_ID or PATH); {how_to_make(need)}")
    if text == "auto":
        raise JtError("action.prior=auto is resolved by jt run before a run opens (toolkit.priors.auto); "
                      f"outside jt run give a run id or a path; {how_to_make(kind or 'pvae')}")
    where = (text, None if store_root is None else str(store_root), os.environ.get("JT_STORE"), kind)
    found = _FOUND.get(where)
    if found is None or not found.is_file():  # a run's artifacts do not move: look it up once per process
        found = _FOUND[where] = _find(text, store_root, kind or "pvae")
    key = (str(found), found.stat().st_mtime_ns, kind)
    if key not in _LOADED:  # a rollout worker builds 16 envs from one prior: read and check it once
        _LOADED.clear()
        _LOADED[key] = read_prior(found, kind)
    return _LOADED[key]


_FOUND: dict[tuple, Path] = {}
"""The file each ``action.prior`` reference resolved to (by reference, store, ``$JT_STORE``, kind)."""
_LOADED: dict[tuple, PosePrior] = {}
"""The last prior ``load_prior`` read, by (file, its mtime, kind); shared by the envs of a process
(a ``PosePrior`` is not changed after loading)."""
