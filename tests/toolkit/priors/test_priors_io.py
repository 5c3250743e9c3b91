"""Saving and loading priors: one HDF5 file, found by path, folder or MLflow run id; clear errors."""

import shutil

import h5py
import numpy as np
import pytest

from toolkit.errors import JtError
from toolkit.priors.io import load_prior, read_prior, save_prior

HINT = "jt run task=pose_prior action="


def _one_line(excinfo):
    msg = str(excinfo.value)
    assert "\n" not in msg and HINT in msg
    return msg


def test_round_trip_gives_the_same_outputs(pvae_fit, pvae_file):
    p, q = pvae_fit.prior, load_prior(pvae_file)
    assert (q.kind, q.latent_dim, q.layout) == (p.kind, p.latent_dim, p.layout)
    assert q.metrics == pytest.approx(p.metrics)
    rng = np.random.default_rng(0)
    a = rng.standard_normal((5, p.latent_dim))
    np.testing.assert_allclose(q.decode_targets(q.latent_from_action(a)), p.decode_targets(p.latent_from_action(a)),
                               atol=1e-6)
    np.testing.assert_array_equal(q.x_std, p.x_std)
    assert load_prior(pvae_file.parent).latent_dim == p.latent_dim  # a folder holding one
    with h5py.File(pvae_file, "r") as f:
        assert f.attrs["format"] == "jt.pose_prior" and "metrics/recon_rmse_heldout" in f


def test_cvae_round_trip_and_kind_check(cvae_fit, tmp_path):
    path = save_prior(cvae_fit.prior, tmp_path / "c.h5")
    q = load_prior(path, kind="cvae")
    np.testing.assert_array_equal(q.c_mean, cvae_fit.prior.c_mean)
    with pytest.raises(JtError) as e:
        load_prior(path, kind="pvae")
    assert "cvae prior" in _one_line(e)


def test_missing_and_malformed_priors_are_one_line_errors(pvae_file, tmp_path):
    with pytest.raises(JtError) as e:
        load_prior("")
    assert "action.prior" in _one_line(e)
    with pytest.raises(JtError) as e:
        load_prior(tmp_path / "nope.h5")
    _one_line(e)
    (tmp_path / "text.h5").write_text("not hdf5")
    with pytest.raises(JtError) as e:
        read_prior(tmp_path / "text.h5")
    _one_line(e)
    with h5py.File(tmp_path / "other.h5", "w") as f:
        f.attrs["format"] = "jt.pose_dataset"
    with pytest.raises(JtError) as e:
        read_prior(tmp_path / "other.h5")
    assert "not a jt pose prior" in _one_line(e)
    trunc = tmp_path / "trunc.h5"
    trunc.write_bytes(pvae_file.read_bytes()[:4000])
    with pytest.raises(JtError) as e:
        read_prior(trunc)
    _one_line(e)
    for edit in ("drop_group", "bad_shape"):
        bad = tmp_path / f"{edit}.h5"
        shutil.copy(pvae_file, bad)
        with h5py.File(bad, "a") as f:
            if edit == "drop_group":
                del f["latent"]
            else:
                del f["norm/x_mean"]
                f["norm/x_mean"] = np.zeros(5)
        with pytest.raises(JtError) as e:
            read_prior(bad)
        assert "malformed" in _one_line(e)
    with pytest.raises(JtError) as e:
        load_prior(tmp_path)  # a folder with no prior in it
    _one_line(e)


def test_load_by_run_id_from_a_real_store(pvae_file, tmp_path):
    from toolkit.store.tracking import Store

    root = tmp_path / "store"
    with pytest.raises(JtError) as e:  # no store there yet
        load_prior("0" * 32, store_root=str(root))
    _one_line(e)
    store = Store(root)
    run = store.start_run("pose_prior")
    store.log_artifact(run, pvae_file)
    store.end_run(run)
    got = load_prior(run, store_root=str(root), kind="pvae")
    assert got.latent_dim == read_prior(pvae_file).latent_dim
    parent = store.start_run("pose_prior")  # a prior logged on a nested evaluation run
    child = store.start_run("pose_prior", parent_run_id=parent)
    store.log_artifact(child, pvae_file, artifact_path="eval")
    assert load_prior(parent, store_root=str(root)).latent_dim == got.latent_dim
    empty = store.start_run("pose_prior")
    with pytest.raises(JtError) as e:
        load_prior(empty, store_root=str(root))
    assert "no pose prior" in _one_line(e)
    with pytest.raises(JtError) as e:
        load_prior("f" * 32, store_root=str(root))
    _one_line(e)
