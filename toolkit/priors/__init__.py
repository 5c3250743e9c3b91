"""Natural-pose priors: the P-VAE of ``000`` §4.2 and the C-VAE of ``003`` §3.5 (docs/priors.md).

Shared by the ``pose_prior`` task (which trains them) and the ``pvae`` / ``cvae`` action spaces
(which decode them), so it lives in the toolkit: a plugin never imports another plugin.

| module | what |
|---|---|
| ``pca`` | PCA, latent size at 85 % variance, the linear baseline |
| ``vae`` | the β-VAE / C-VAE in torch and its seeded training (torch imported there only) |
| ``model`` | ``PosePrior``: a trained prior evaluated in numpy (decode → PD targets) |
| ``train`` | ``fit_prior``: normalise, PCA, train, compare with PCA on held-out poses |
| ``io`` | ``save_prior`` / ``load_prior`` (path or MLflow run id), one HDF5 file |
| ``limits`` | joint limits of the dof layout; ``limit_targets`` |
| ``render`` | filmstrip PNG of decoded poses (PyBullet TinyRenderer) |

Importing this package loads numpy only; torch, h5py and PyBullet are imported where needed.
"""

from toolkit.priors.limits import joint_limits, limit_targets, within_limits
from toolkit.priors.model import KINDS, PosePrior
from toolkit.priors.pca import DEFAULT_VARIANCE, Pca, fit_pca

__all__ = [
    "DEFAULT_VARIANCE",
    "KINDS",
    "Pca",
    "PosePrior",
    "fit_pca",
    "joint_limits",
    "limit_targets",
    "load_prior",
    "save_prior",
    "within_limits",
]


def load_prior(ref, store_root=None, kind=None):  # noqa: ANN001, ANN201 - thin lazy wrapper
    """See ``toolkit.priors.io.load_prior`` (imported lazily: it pulls in h5py)."""
    from toolkit.priors.io import load_prior as _load

    return _load(ref, store_root, kind)


def save_prior(prior, path):  # noqa: ANN001, ANN201
    """See ``toolkit.priors.io.save_prior``."""
    from toolkit.priors.io import save_prior as _save

    return _save(prior, path)
