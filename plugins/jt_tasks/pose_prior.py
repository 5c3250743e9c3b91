"""``task=pose_prior``: train the natural-pose prior that ``action=pvae`` / ``action=cvae`` decode.

``jt run task=pose_prior action=pvae`` trains the P-VAE of ``000`` §4.2; ``action=cvae`` the C-VAE
of ``003`` §3.5 (conditioned on neck height and torso angles). One evaluation:

1. load the pose dataset (``task.dataset``) or build it from ``pybullet_data``'s humanoid clips
   (30 Hz, with mirrors) in a temporary folder, holding out ``task.held_out`` (default: ``walk``,
   a common motion whose poses the rest of the data covers but never repeats);
2. choose the latent size by PCA at 85 % variance of the normalised training features (``000``
   §4.2) unless ``task.latent_dim`` fixes it;
3. train (seeded by the evaluation seed, one thread) with the paper's settings for the kind;
4. compare with PCA of the same size on the held-out clip (``recon_rmse_heldout`` vs
   ``pca_rmse_heldout``, normalised feature units);
5. write ``prior.h5`` (``toolkit.priors.io``) and ``prior_samples.png``, decoded random latents.

The run's id is then what ``action.prior=RUN_ID`` takes.
"""

from __future__ import annotations

import dataclasses
import json
import math
import tempfile
from pathlib import Path
from typing import Any, ClassVar, Optional

from toolkit.errors import JtError
from toolkit.interfaces.plugin import Plugin
from toolkit.interfaces.task import EvalContext, Evaluation, Task

#: optimiser updates of the papers' trainings: 000 §4.2: ~20,000 poses / 128 × 80 epochs;
#: 003 §3.5: ~36,000 frames / 128 × 100 epochs
PAPER_UPDATES = {"pvae": math.ceil(20000 / 128) * 80, "cvae": math.ceil(36000 / 128) * 100}


class PosePriorTask(Task):
    """Train the P-VAE (000 §4.2) or C-VAE (003 §3.5) pose prior for the run's action space."""

    ignores_groups: ClassVar[tuple[str, ...]] = ("reward", "curriculum", "sim", "spd", "character", "agent")

    key_metrics: ClassVar[tuple[str, ...]] = ("latent_dim", "recon_rmse_heldout", "pca_rmse_heldout")

    @dataclasses.dataclass
    class Config:
        name: str = "pose_prior"
        dataset: str = ""
        """A pose dataset (python -m toolkit.motion.dataset); "" = build from pybullet_data's 15 clips."""
        held_out: list[str] = dataclasses.field(default_factory=lambda: ["walk"])
        """Clips kept out of training, for recon_rmse_heldout vs pca_rmse_heldout."""
        rate: float = 30.0
        """Hz, when building the dataset (000 §6.1.3 top control rate)."""
        mirror: bool = True
        """Add left/right mirrors when building the dataset."""
        variance: float = 0.85
        """000 §4.2, 003 §3.5: latent size = PCA components covering 85 % of the variance."""
        latent_dim: int = 0
        """Fix the latent size instead (0 = by PCA)."""
        hidden: list[int] = dataclasses.field(default_factory=lambda: [256, 256])
        """000 §4.2, 003 §3.5: encoder/decoder 2 x 256 tanh."""
        beta: Optional[float] = None
        """Null = the paper's: 1e-5 for pvae (000 §4.2), 1e-6 for cvae (003 §3.5)."""
        lr: float = 1e-4
        """000 §4.2, 003 §3.5: Adam."""
        batch_size: int = 128
        """000 §4.2, 003 §3.5."""
        epochs: Optional[int] = None
        """Null = the paper's number of Adam updates (000: 80 epochs of ~20k poses; 003: 100 of ~36k) on our data; see docs/priors.md."""
        samples: int = 8
        """Decoded random latents in prior_samples.png."""

        def check(self) -> None:
            """A ``task.dataset`` is read at composition (one line naming the file), before a run opens."""
            if not str(self.dataset).strip():
                return
            from toolkit.errors import JtError
            from toolkit.motion.dataset import load_dataset

            try:
                load_dataset(self.dataset)
            except (OSError, ValueError, KeyError) as e:
                raise JtError(f"task.dataset={self.dataset}: not a jt pose dataset ({str(e).splitlines()[0][:160]}); "
                              "make one with: python -m toolkit.motion.dataset, or leave it empty") from None

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        group = cfg.get("task") if cfg is not None and hasattr(cfg, "get") else None
        self.params = self.Config(**Plugin.params_of(group)) if group is not None else self.Config()

    def kind(self) -> str:
        """``pvae`` or ``cvae``: the run's action space."""
        action = self.cfg.get("action") if self.cfg is not None and hasattr(self.cfg, "get") else None
        name = str(action.get("name")) if action is not None and hasattr(action, "get") else ""
        if name not in ("pvae", "cvae"):
            got = f"action={name}" if name else "no action"
            raise JtError(f"task=pose_prior trains the prior of action=pvae or action=cvae ({got} given); "
                          "run: jt run task=pose_prior action=pvae")  # fmt: skip
        return name

    def problem(self) -> Any:
        """No parameters: the task runs once. Checks the action choice first, so a wrong one
        fails before a run is opened."""
        self.kind()
        return super().problem()

    def settings(self, kind: str, n_train: int) -> Any:
        """``VAESettings`` for ``kind``: the paper's, with this config's overrides."""
        from toolkit.priors.vae import PAPER_SETTINGS

        p = self.params
        paper = PAPER_SETTINGS[kind]
        epochs = p.epochs
        if epochs is None:  # the paper's number of optimiser updates on our (smaller) data set
            epochs = max(paper.epochs, math.ceil(PAPER_UPDATES[kind] / math.ceil(n_train / p.batch_size)))
        return dataclasses.replace(paper, hidden=tuple(p.hidden), beta=paper.beta if p.beta is None else p.beta,
                                   lr=p.lr, batch_size=p.batch_size, epochs=int(epochs))  # fmt: skip

    def dataset(self, folder: Path) -> Any:
        """The pose dataset: ``task.dataset`` or one built into ``folder``."""
        from toolkit.motion.dataset import build_dataset, load_dataset

        p = self.params
        if p.dataset:
            try:
                ds = load_dataset(p.dataset)
            except (OSError, ValueError) as e:
                raise JtError(f"task.dataset: {str(e).splitlines()[0]}") from e
            held = json.loads(ds.attrs.get("held_out", "[]"))
            if sorted(held) != sorted(p.held_out):
                raise JtError(f"task.dataset holds out {held}, task.held_out is {list(p.held_out)}; "
                              "rebuild it with python -m toolkit.motion.dataset --held-out ...")  # fmt: skip
            return ds
        try:
            return build_dataset(folder / "poses.h5", rate=p.rate, mirror=p.mirror, held_out=list(p.held_out))
        except KeyError as e:
            raise JtError(f"task.held_out: {e.args[0]}") from e

    def evaluate(self, point: dict[str, float], ctx: EvalContext) -> Evaluation:
        import numpy as np

        from toolkit.priors.io import FILENAME, save_prior
        from toolkit.priors.render import save_filmstrip
        from toolkit.priors.train import fit_prior

        kind = self.kind()
        workdir = Path(ctx.workdir)
        with tempfile.TemporaryDirectory(prefix="jt-poses-") as tmp:
            ctx.report(0.0, "pose dataset")
            ds = self.dataset(Path(tmp))
        tr, ho = ds.train, ds.held_out
        settings = self.settings(kind, len(tr))
        info = {
            "dataset": {"source": self.params.dataset or "pybullet_data", "held_out": list(self.params.held_out),
                        "rate_hz": ds.attrs.get("rate_hz"), "mirror": bool(ds.attrs.get("mirror")),
                        "clips": [e["name"] + ("~" if e["mirrored"] else "") for e in ds.entries],
                        "sha256": sorted({e["name"]: e["sha256"] for e in ds.entries}.items())},
            "seed": int(ctx.seed),
        }  # fmt: skip
        res = fit_prior(
            kind, ds.layout, tr.features, tr.conditions, None if ho is None else ho.features,
            None if ho is None else ho.conditions, settings=settings, variance=self.params.variance,
            latent_dim=self.params.latent_dim, seed=ctx.seed,
            condition_names=tuple(json.loads(ds.attrs.get("condition_names", "[]"))), info=info,
            progress=lambda f, m: ctx.report(0.05 + 0.85 * f, m),
        )  # fmt: skip
        prior = res.prior
        prior.metrics["epochs"] = float(settings.epochs)
        save_prior(prior, workdir / FILENAME)
        ctx.report(0.92, "rendering decoded samples")
        rng = np.random.default_rng(ctx.seed)
        n = max(int(self.params.samples), 1)
        a = np.vstack([np.zeros((1, prior.latent_dim)), rng.standard_normal((n - 1, prior.latent_dim))])
        cond = None
        if prior.conditional:  # conditions of random training frames, the first one upright
            cond = tr.conditions[rng.integers(0, len(tr), n)]
            cond[0] = tr.conditions[np.argmax(tr.conditions[:, 0])]
        dofs = prior.decode_targets(prior.latent_from_action(a), cond)
        save_filmstrip(prior.skeleton, dofs, workdir / "prior_samples.png", columns=min(n, 8))
        ctx.report(1.0, "done")
        return Evaluation(metrics=dict(prior.metrics), history=res.history)
