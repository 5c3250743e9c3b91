"""Fixtures for the action-space tests: tiny trained P-VAE and C-VAE priors as real HDF5 files."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def action_priors(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """``{"pvae": path, "cvae": path, "dataset": PoseDataset}``: priors trained 2 epochs on the
    humanoid pose dataset (``walk`` held out)."""
    from toolkit.motion import build_dataset
    from toolkit.priors.io import save_prior
    from toolkit.priors.train import fit_prior
    from toolkit.priors.vae import PAPER_SETTINGS

    root = tmp_path_factory.mktemp("action_priors")
    ds = build_dataset(root / "poses.h5", held_out=["walk"])
    out: dict = {"dataset": ds}
    for kind in ("pvae", "cvae"):
        s = dataclasses.replace(PAPER_SETTINGS[kind], epochs=2)
        fit = fit_prior(kind, ds.layout, ds.train.features, ds.train.conditions, settings=s, seed=0)
        out[kind] = save_prior(fit.prior, root / kind / "prior.h5")
    return out
