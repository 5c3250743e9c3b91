"""Fixtures for the pose-prior tests: one small pose dataset and tiny trained priors (real HDF5)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def pose_dataset(tmp_path_factory: pytest.TempPathFactory):
    """The humanoid pose dataset at 30 Hz with mirrors, ``walk`` held out (built once, ~2 s)."""
    from toolkit.motion import build_dataset

    return build_dataset(tmp_path_factory.mktemp("poses") / "poses.h5", held_out=["walk"])


def _fit(ds, kind: str, epochs: int = 3, seed: int = 0):
    from toolkit.priors.train import fit_prior
    from toolkit.priors.vae import PAPER_SETTINGS

    s = dataclasses.replace(PAPER_SETTINGS[kind], epochs=epochs)
    return fit_prior(kind, ds.layout, ds.train.features, ds.train.conditions, ds.held_out.features,
                     ds.held_out.conditions, settings=s, seed=seed, condition_names=("h", "side", "front"))


@pytest.fixture(scope="session")
def fit_small():
    """``fit_small(ds, kind, epochs=3, seed=0)`` → ``FitResult``."""
    return _fit


@pytest.fixture(scope="session")
def pvae_fit(pose_dataset):
    return _fit(pose_dataset, "pvae")


@pytest.fixture(scope="session")
def cvae_fit(pose_dataset):
    return _fit(pose_dataset, "cvae")


@pytest.fixture(scope="session")
def pvae_file(pvae_fit, tmp_path_factory: pytest.TempPathFactory) -> Path:
    from toolkit.priors.io import save_prior

    return save_prior(pvae_fit.prior, tmp_path_factory.mktemp("pvae") / "prior.h5")
