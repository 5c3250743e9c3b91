"""task=pose_prior: trains the prior of the run's action space, writes prior.h5 + a filmstrip PNG."""

from __future__ import annotations

import math

import numpy as np
import pytest
from omegaconf import OmegaConf

from jt_tasks.pose_prior import PAPER_UPDATES, PosePriorTask
from toolkit import plugins
from toolkit.errors import JtError
from toolkit.interfaces import EvalContext

REGISTERED = "pose_prior" in plugins.names("task") and "pvae" in plugins.names("action")


@pytest.fixture(scope="module")
def dataset_path(tmp_path_factory):
    from toolkit.motion import build_dataset

    path = tmp_path_factory.mktemp("poses") / "poses.h5"
    build_dataset(path, held_out=["walk"])
    return str(path)


def _task(action: str | None, **task):
    cfg = {"task": {"name": "pose_prior", **task}}
    if action is not None:
        cfg["action"] = {"name": action}
    return PosePriorTask(OmegaConf.create(cfg))


def test_needs_a_prior_action():
    for action in (None, "raw", "ffc_fbc"):
        with pytest.raises(JtError) as e:
            _task(action).problem()  # the runner asks for the problem before it opens a run
        assert "action=pvae or action=cvae" in str(e.value) and "\n" not in str(e.value)
    assert _task("cvae").kind() == "cvae"
    assert PosePriorTask.key_metrics == ("latent_dim", "recon_rmse_heldout", "pca_rmse_heldout")


def test_settings_follow_the_papers():
    p = _task("pvae").settings("pvae", 1954)
    assert (p.beta, p.lr, p.batch_size, p.hidden) == (1e-5, 1e-4, 128, (256, 256))
    assert p.epochs == math.ceil(PAPER_UPDATES["pvae"] / 16) == 785  # 12,560 Adam updates, as 000 §4.2
    c = _task("cvae").settings("cvae", 1954)
    assert c.beta == 1e-6 and c.epochs == math.ceil(PAPER_UPDATES["cvae"] / 16)
    assert _task("pvae", epochs=3, beta=1e-3).settings("pvae", 1954).epochs == 3
    assert _task("pvae", beta=1e-3).settings("pvae", 100).beta == 1e-3


def test_evaluate_writes_prior_and_filmstrip_deterministically(dataset_path, tmp_path):
    from toolkit.priors.io import load_prior

    evs = []
    for i in range(2):
        task = _task("cvae", dataset=dataset_path, epochs=2, samples=3)
        evs.append(task.evaluate({}, EvalContext(index=0, seed=7, workdir=tmp_path / f"w{i}")))
    ev = evs[0]
    for key in ("latent_dim", "recon_rmse_heldout", "pca_rmse_heldout", "recon_rot_err_heldout", "epochs"):
        assert np.isfinite(ev.metrics[key])
    assert ev.metrics["epochs"] == 2 and len(ev.history["loss"]) == 2
    same = {k: v for k, v in ev.metrics.items() if k != "train_seconds"}
    assert same == {k: v for k, v in evs[1].metrics.items() if k != "train_seconds"}  # same seed, same numbers
    prior = load_prior(tmp_path / "w0", kind="cvae")
    assert prior.latent_dim == ev.metrics["latent_dim"] and prior.info["seed"] == 7
    import imageio.v3 as iio

    img = iio.imread(tmp_path / "w0" / "prior_samples.png")
    assert img.shape[1] > 2 * img.shape[0] and img.std() > 5  # three frames side by side, not blank
    with pytest.raises(JtError):
        _task("pvae", dataset=dataset_path, held_out=["run"]).dataset(tmp_path)


@pytest.mark.skipif(not REGISTERED, reason="entry points jt.tasks:pose_prior / jt.actions:pvae not registered yet")
def test_run_then_load_by_run_id(store_dir):
    from toolkit.config import compose
    from toolkit.execution.runner import run
    from toolkit.priors.io import load_prior

    res = run(compose(["task=pose_prior", "action=pvae", "experiment=smoke", f"store={store_dir}"]))
    assert res.store.get_run(res.run_id).info.status == "FINISHED"
    art = res.store.artifact_dir(res.run_id)
    assert list(art.rglob("prior.h5")) and list(art.rglob("prior_samples.png"))
    prior = load_prior(res.run_id, store_root=str(store_dir), kind="pvae")
    assert prior.metrics["epochs"] == 3 and prior.latent_dim == res.evaluations[0].metrics["latent_dim"]
    from jt_actions.pvae import PVAEActionSpace

    space = PVAEActionSpace({"prior": res.run_id, "store": str(store_dir)})
    assert space.dim == prior.latent_dim + 28


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["pvae", "cvae"])
def test_full_training_beats_pca_on_the_held_out_clip(kind, dataset_path, tmp_path):
    ev = _task(kind, dataset=dataset_path).evaluate({}, EvalContext(index=0, seed=0, workdir=tmp_path))
    print(kind, {k: round(v, 4) for k, v in ev.metrics.items()})
    assert ev.metrics["recon_rmse_heldout"] <= ev.metrics["pca_rmse_heldout"]
