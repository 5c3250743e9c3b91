"""The VAE: numpy inference equals torch, seeded training is reproducible, decoded poses are usable."""

import dataclasses

import numpy as np
import pytest

from toolkit.motion import HUMANOID
from toolkit.priors.limits import limit_targets, within_limits
from toolkit.priors.model import PosePrior
from toolkit.priors.pca import fit_pca


def test_numpy_inference_matches_torch():
    import torch

    from toolkit.motion.features import feature_layout
    from toolkit.priors.vae import VAE

    torch.manual_seed(1)
    layout = feature_layout(HUMANOID)
    net = VAE(layout.size, 3, 5)
    prior = PosePrior("cvae", layout, 5, net.numpy_weights(), np.zeros(layout.size), np.ones(layout.size),
                      np.zeros(3), np.ones(3), np.zeros(5), np.ones(5))
    rng = np.random.default_rng(0)
    x, c, z = rng.standard_normal((4, layout.size)), rng.standard_normal((4, 3)), rng.standard_normal((4, 5))
    with torch.no_grad():
        mu, lv = net.encode(torch.tensor(x, dtype=torch.float32), torch.tensor(c, dtype=torch.float32))
        dec = net.decode(torch.tensor(z, dtype=torch.float32), torch.tensor(c, dtype=torch.float32))
    np.testing.assert_allclose(prior.encode(x, c)[0], mu.numpy(), atol=1e-5)
    np.testing.assert_allclose(prior.encode(x, c)[1], lv.numpy(), atol=1e-5)
    np.testing.assert_allclose(prior.decode(z, c), dec.numpy(), atol=1e-5)
    with pytest.raises(ValueError):
        prior.decode(z)  # a C-VAE needs its condition
    with pytest.raises(ValueError):
        prior.decode(z, c[:, :2])


def test_fit_reports_pca_latent_size_and_is_seeded(pose_dataset, pvae_fit, fit_small):
    prior, m = pvae_fit.prior, pvae_fit.prior.metrics
    xn = prior.normalize(pose_dataset.train.features)
    assert prior.latent_dim == fit_pca(xn).n_components(0.85) == m["latent_dim"]
    assert m["pca_variance_at_latent"] >= 0.85
    for key in ("recon_rmse_heldout", "pca_rmse_heldout", "recon_rot_err_heldout", "pca_rmse_train"):
        assert np.isfinite(m[key]) and m[key] > 0
    assert [e for e, _ in pvae_fit.history["loss"]] == [0, 1, 2]
    assert pvae_fit.history["loss"][-1][1] < pvae_fit.history["loss"][0][1]
    again = fit_small(pose_dataset, "pvae", epochs=3, seed=0).prior
    other = fit_small(pose_dataset, "pvae", epochs=3, seed=1).prior
    for k, w in prior.weights.items():
        np.testing.assert_array_equal(again.weights[k], w)
    assert not np.array_equal(other.weights["dec0_w"], prior.weights["dec0_w"])
    # normalisation kept with the model: constant columns (revolute 6D z parts) keep std 1
    assert np.all(prior.x_std > 0) and np.sum(prior.x_std == 1.0) >= 8


def _root_to_ankles(dofs):
    from toolkit.motion.kinematics import forward_kinematics

    kin = forward_kinematics(HUMANOID, np.zeros((len(dofs), 3)), np.tile([0, 0, 0, 1.0], (len(dofs), 1)),
                             HUMANOID.dofs_to_joints(dofs))
    ankles = [kin.index("right_ankle"), kin.index("left_ankle")]
    return -kin.joint_pos[:, ankles, 1].mean(axis=1)  # y-up: how far the ankles hang below the root


def test_decoded_zero_latent_is_a_standing_like_pose(pvae_fit, cvae_fit, pose_dataset):
    rest = _root_to_ankles(np.zeros((1, 28)))[0]
    assert rest == pytest.approx(0.836, abs=0.01)  # docs/motion.md: root to ankle at rest
    p = pvae_fit.prior
    zero = p.decode_targets(p.latent_from_action(np.zeros(p.latent_dim)))
    assert zero.shape == (28,) and within_limits(HUMANOID, limit_targets(HUMANOID, zero))
    assert _root_to_ankles(zero[None])[0] > 0.8 * rest  # legs under the root, roughly straight
    q = cvae_fit.prior
    upright = pose_dataset.train.conditions[np.argmax(pose_dataset.train.conditions[:, 0])]
    zc = q.decode_targets(q.latent_from_action(np.zeros(q.latent_dim)), upright)
    assert _root_to_ankles(zc[None])[0] > 0.8 * rest


def test_cvae_decodes_the_condition(cvae_fit, pose_dataset):
    q = cvae_fit.prior
    assert q.conditional and q.n_cond == 3 and q.condition_names == ("h", "side", "front")
    conds = pose_dataset.train.conditions[[0, np.argmin(pose_dataset.train.conditions[:, 0])]]
    a = np.zeros((2, q.latent_dim))
    out = q.decode_targets(q.latent_from_action(a), conds)
    assert out.shape == (2, 28) and not np.allclose(out[0], out[1])


def test_settings_defaults_are_the_papers():
    from toolkit.priors.vae import PAPER_SETTINGS

    p, c = PAPER_SETTINGS["pvae"], PAPER_SETTINGS["cvae"]
    assert (p.hidden, p.beta, p.lr, p.batch_size, p.epochs) == ((256, 256), 1e-5, 1e-4, 128, 80)
    assert dataclasses.replace(c, beta=1e-5, epochs=80) == p and (c.beta, c.epochs) == (1e-6, 100)


def test_vectorised_target_map_equals_the_motion_layer(pose_dataset):
    from toolkit.motion.features import features_to_joints
    from toolkit.priors.model import TargetMap

    tm = TargetMap(pose_dataset.layout)
    rng = np.random.default_rng(0)
    noisy = pose_dataset.train.features[:300] + 0.3 * rng.standard_normal((300, pose_dataset.layout.size))
    for x in (pose_dataset.train.features, noisy, noisy[7]):
        np.testing.assert_allclose(tm(x), HUMANOID.joints_to_dofs(features_to_joints(x, pose_dataset.layout)),
                                   atol=1e-12)


def test_one_pose_through_the_compiled_kernel_has_the_bits_of_the_batched_path(pose_dataset):
    """An env decodes one action per step through the compiled kernel: the same bits as numpy's
    batched path (a last-digit change would change every trajectory), near the series branch, at
    ``pi``, and for degenerate 6D blocks too."""
    from toolkit.priors.model import TargetMap

    tm = TargetMap(pose_dataset.layout)
    rng = np.random.default_rng(0)
    base = pose_dataset.train.features[:200]
    x = np.concatenate([base, base + 0.3 * rng.standard_normal(base.shape), 3.0 * rng.standard_normal(base.shape)])
    odd = np.repeat(base[:1], 4, axis=0)
    cols = tm.cols.ravel()
    odd[0, cols] = 0.0  # zero blocks: the fallback columns
    odd[1, tm.cols[:, 3:].ravel()] = odd[1, tm.cols[:, :3].ravel()]  # parallel columns: the degenerate b2
    odd[2, cols] = np.tile([1.0, 0, 0, 0, 1.0, 0], len(tm.cols))  # identity: the exp maps' series branch
    odd[3, cols] = np.tile([-1.0, 0, 0, 0, -1.0, 0], len(tm.cols))  # a half turn about z: Shepperd's k = 2
    x = np.concatenate([x, odd])
    batched = tm(x)
    one = np.array([tm(row) for row in x])
    assert one.shape == (len(x), HUMANOID.n_dof)
    assert np.array_equal(batched.view(np.uint64), one.view(np.uint64))
