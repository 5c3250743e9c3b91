"""PCA latent-size selection and reconstruction, checked against analytic cases and scikit-learn."""

import numpy as np
import pytest

from toolkit.priors.pca import fit_pca, rmse


def _data(n=4000, seed=0):
    """Axis-aligned Gaussian data with variances 8, 4, 2, 1, 0.5 (total 15.5), then rotated."""
    rng = np.random.default_rng(seed)
    x = rng.standard_normal((n, 5)) * np.sqrt([8.0, 4.0, 2.0, 1.0, 0.5])
    q, _ = np.linalg.qr(rng.standard_normal((5, 5)))
    return (x - x.mean(0)) / x.std(0) * np.sqrt([8.0, 4.0, 2.0, 1.0, 0.5]) @ q.T + 3.0


def test_variance_fraction_picks_the_analytic_component_count():
    pca = fit_pca(_data())
    # cumulative: 8/15.5 = .516, 12/15.5 = .774, 14/15.5 = .903, 15/15.5 = .968
    assert pca.n_components(0.5) == 1
    assert pca.n_components(0.77) == 2
    assert pca.n_components(0.85) == 3
    assert pca.n_components(0.95) == 4
    assert pca.n_components(1.0) == 5
    with pytest.raises(ValueError):
        pca.n_components(0.0)


def test_matches_scikit_learn():
    from sklearn.decomposition import PCA

    x = _data(seed=3)
    ours, ref = fit_pca(x), PCA().fit(x)
    np.testing.assert_allclose(ours.explained_ratio, np.cumsum(ref.explained_variance_ratio_), atol=1e-10)
    for k in (1, 3):
        sk = PCA(n_components=k).fit(x)
        np.testing.assert_allclose(ours.reconstruct(x, k), sk.inverse_transform(sk.transform(x)), atol=1e-9)


def test_reconstruction_is_exact_with_every_component_and_rmse():
    x = _data(n=50)
    pca = fit_pca(x)
    np.testing.assert_allclose(pca.reconstruct(x, 5), x, atol=1e-10)
    assert rmse(pca.reconstruct(x, 2), x) > rmse(pca.reconstruct(x, 3), x) > 0.0
    assert rmse(np.zeros(4), np.full(4, 2.0)) == pytest.approx(2.0)
    with pytest.raises(ValueError):
        fit_pca(np.zeros((1, 3)))
