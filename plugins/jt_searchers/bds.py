"""``search=bds``: Bayesian Diversity Search (``000`` §5.1 Alg. 1; ``001`` §3.5.1), with batches.

Algorithm 1: ``n_init`` random samples initialise a GP surrogate of the feature map ``g(x)``; then
model-based picks alternate ``n_exp`` exploration picks (argmax posterior std, eq 9, by
multi-start L-BFGS-B) and ``n_opt`` diversity picks (argmax of the Monte-Carlo expected minimum
feature distance to the observed features, eq 7, by DIRECT). The GP's hyperparameters are re-learned
after every tell (Alg. 1 line 11).

Batches (beyond the paper, which is sequential; its §8 suggests batched BDS as future work): an
``ask(q)`` makes ``q`` picks greedily; after each pick the model *believes* its posterior mean
there (kriging believer: the point is added to the GP data with the mean as its value and to the
observed feature set, hyperparameters unchanged), so exploration picks stop seeing uncertainty at
the picked point and diversity picks see its predicted strategy as taken — the ``q`` points are
diverse among themselves. Points asked but not yet told are believed the same way. Picks keep
alternating exploration/diversity across the batch exactly as in the sequential schedule.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Optional, Sequence

import numpy as np

from jt_searchers.acquisition import ExpectedDiversity, Exploration
from jt_searchers.base import BudgetedSearcher, check_budget, feasible_mask, feasible_samples, seed_int
from jt_searchers.distances import resolve
from jt_searchers.feasibility import KnownConstraint, combine, feasibility
from jt_searchers.gp import FeatureGP
from jt_searchers.optimize import maximize_direct, maximize_lbfgsb
from toolkit.errors import JtError

KINDS = ("init", "explore", "diversity")
FAILURES = ("avoid", "believe")


class BDSSearcher(BudgetedSearcher):
    """Bayesian Diversity Search: GP surrogate of features, alternating exploration / diversity picks.

    A known constraint of the problem (``SearchProblem.constraint``) is kept: the initial samples
    are drawn within it and both acquisitions are zero outside it (``KnownConstraint``)."""

    honours_constraint = True

    @dataclasses.dataclass
    class Config:

        def check(self) -> None:

            """budget and batch >= 1, a known ``failures`` rule (one JtError line)."""

            from jt_searchers.distances import BY_NAME
            from toolkit.schema import require

            check_budget(self)
            if self.failures not in FAILURES:
                raise JtError(f"search.failures={self.failures!r}: choose one of {', '.join(FAILURES)}")
            require(self.n_init >= 1, "search.n_init", self.n_init, "must be >= 1")
            require(self.n_exp >= 0 and self.n_opt >= 0 and self.n_exp + self.n_opt >= 1, "search.n_exp/n_opt",
                    (self.n_exp, self.n_opt), "must be >= 0 with n_exp + n_opt >= 1")
            require(self.init_method in ("uniform", "sobol"), "search.init_method", self.init_method, "uniform or sobol")
            require(self.feature_distance is None or self.feature_distance in BY_NAME, "search.feature_distance",
                    self.feature_distance, f"one of {', '.join(sorted(BY_NAME))} (null: the task's)")
            for key in ("n_mc", "direct_maxfun", "lbfgs_starts"):
                require(getattr(self, key) >= 1, f"search.{key}", getattr(self, key), "must be >= 1")
            require(self.gp_restarts >= 0, "search.gp_restarts", self.gp_restarts, "must be >= 0")

        budget: int = 10
        """Total evaluations incl. initial samples; 000 §7.1.1 reports the first ten."""
        batch: int = 1
        """1 = Algorithm 1 as published; >1 = batch BDS (kriging believer, ours; 000 §8 future work)."""
        n_init: int = 3
        """Random samples initialising the GP (000 Alg. 1 line 2 gives no number; ours)."""
        n_exp: int = 3
        """Exploration picks per round, argmax posterior std by L-BFGS (000 §6.2, eq 9)."""
        n_opt: int = 3
        """Diversity picks per round, argmax eq 7 by DIRECT (000 §6.2)."""
        init_method: str = "uniform"
        """"uniform" or "sobol" initial samples (000 Alg. 1: "random samples")."""
        n_mc: int = 128
        """Monte-Carlo draws for eq 7, fixed and seeded (000 §5.1 uses MC; count ours)."""
        direct_maxfun: int = 2000
        """DIRECT evaluations per diversity pick (ours; 000 §5.1: "does not have to be perfectly accurate")."""
        lbfgs_starts: int = 8
        """L-BFGS-B starts per exploration pick (ours)."""
        gp_restarts: int = 3
        """Extra seeded restarts of the GP marginal-likelihood fit (ours)."""
        feature_distance: Optional[str] = None
        """Euclidean | angle | quaternion; null = the task's (SearchProblem.feature_distance)."""
        failures: str = "avoid"
        """Told points without a feature: "avoid" weights both acquisitions by the probability of a
        feature (a +-1 label GP, as in constrained BO, Gelbart et al. 2014; ours, 000 is silent and
        a laptop run re-sampled one failed corner three times) | "believe" only kriging-believes them."""

    def __init__(self, problem: Any, cfg: Any, seed: int) -> None:
        super().__init__(problem, cfg, seed)
        c = self.cfg
        if problem.n_features <= 0:
            raise JtError("bds needs a task whose problem() declares n_features > 0")
        if c.n_init < 1 or c.n_exp < 0 or c.n_opt < 0 or c.n_exp + c.n_opt < 1:
            raise JtError("bds needs n_init >= 1 and n_exp + n_opt >= 1")
        m = problem.n_features
        low = np.asarray(problem.feature_low if problem.feature_low is not None else [-1.0] * m, float)
        high = np.asarray(problem.feature_high if problem.feature_high is not None else [1.0] * m, float)
        half = 0.5 * (high - low)
        self._centre = 0.5 * (low + high)  # prior mean = centre of the feature range (000 §6.1.5)
        self._half = np.where(half > 0, half, 1.0)
        self._distance = resolve(c.feature_distance or problem.feature_distance)
        self._init = feasible_samples(problem, self.box, c.n_init, seed_int(seed, 0), c.init_method)
        self._known = KnownConstraint(problem, self.box) if problem.constraint is not None else None
        self._z = np.random.default_rng(seed_int(seed, 1)).standard_normal((c.n_mc, m))
        self._gp = FeatureGP(self.box.dim, self._centre, self._half)
        self._fitted_at = -1  # n_told when the hyperparameters were last learned
        self.U: list[np.ndarray] = []  # told unit points
        self.F: list[np.ndarray] = []  # told features (NaN row when failed / missing)
        self.kinds: list[str] = []  # kind of every asked point
        self.acq: list[float] = []  # acquisition value of every asked point (NaN for init)
        self._n_model_picks = 0

    # ---- the model ------------------------------------------------------------------------------

    def _observed(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Told data: unit points ``(t, dim)``, features ``(t, m)``, mask of usable rows ``(t,)``."""
        m = self.problem.n_features
        U = np.array(self.U).reshape(-1, self.box.dim)
        F = np.array(self.F).reshape(-1, m)
        return U, F, np.all(np.isfinite(F), axis=1)

    def _model(self) -> FeatureGP:
        """GP fitted on the told data, then believing every point without a usable feature.

        Points asked but not told, and told failures without features, are believed at the posterior
        mean: they carry no feature information, but they are no longer unexplored.
        """
        U, F, ok = self._observed()
        if self._fitted_at != self.n_told:
            # Learned from fixed initial hyperparameters (no warm start), so the fit depends only on
            # the data and the seed: a replayed run refits to exactly the same model.
            self._gp = FeatureGP(self.box.dim, self._centre, self._half)
            self._gp.fit(U[ok], F[ok], seed=seed_int(self.seed, 2, self.n_told),
                         n_restarts=self.cfg.gp_restarts)
            self._fitted_at = self.n_told
        gp = FeatureGP(self.box.dim, self._centre, self._half, self._gp.lengthscales,
                       self._gp.amplitude, self._gp.noise).condition(U[ok], self._gp.standardise(F[ok]))
        for u in list(U[~ok]) + list(self._pending):
            gp = gp.fantasise(u)
        return gp

    def _believed_features(self, gp: FeatureGP) -> np.ndarray:
        """Observed features plus the believed ones of pending points, raw units ``(t', m)``."""
        _, F, ok = self._observed()
        if not self._pending:
            return F[ok]
        mean, _ = gp.predict(np.array(self._pending))
        return np.vstack([F[ok], mean])

    # ---- picks ----------------------------------------------------------------------------------

    def _feasibility(self) -> Any:
        """The weight of both acquisitions, or None when neither part applies (Alg. 1 unchanged).

        ``p(feature | x)`` from the told outcomes (``failures="avoid"`` and a failure told) times
        the known constraint's indicator."""
        learned = None
        if self.cfg.failures == "avoid":
            U, _, ok = self._observed()
            learned = feasibility(U, ok, self._gp.lengthscales)
        return combine(learned, self._known)

    def _candidates(self, j: int, kind: int) -> tuple[np.ndarray, np.random.Generator]:
        """512 seeded unit candidates ``(n, dim)`` for pick ``j`` (the feasible ones, with a constraint)."""
        rng = np.random.default_rng(seed_int(self.seed, kind, j))
        cand = rng.random((512, self.box.dim))
        if self._known is not None:
            cand = cand[feasible_mask(self.problem, self.box, cand)]
            if len(cand) == 0:
                cand = feasible_samples(self.problem, self.box, 64, seed_int(self.seed, kind, j, 1))
        return cand, rng

    def _explore(self, gp: FeatureGP, j: int, feasible: Any = None) -> tuple[np.ndarray, float]:
        """argmax sigma (eq 9) by L-BFGS-B from the best of 512 seeded candidates + random starts."""
        acq = Exploration(gp, feasible)
        cand, rng = self._candidates(j, 3)
        vals = acq(cand)
        order = np.argsort(-vals, kind="stable")
        others = rng.choice(order[1:], min(self.cfg.lbfgs_starts - 1, len(order) - 1), replace=False)
        starts = cand[np.concatenate([order[:1], others])]
        u, v = maximize_lbfgsb(acq.value_and_grad, starts)
        return self._keep_feasible(u, v, cand, vals)

    def _diversify(self, gp: FeatureGP, observed: np.ndarray, j: int, feasible: Any = None) -> tuple[np.ndarray, float]:
        """argmax of the MC expected minimum feature distance (eq 7) by DIRECT."""
        acq = ExpectedDiversity(gp, observed, self._distance, self._z, feasible)
        u, v = maximize_direct(acq.scalar(), self.box.dim, maxfun=self.cfg.direct_maxfun)
        if self._known is None or feasible_mask(self.problem, self.box, u[None])[0]:
            return u, v
        cand, _ = self._candidates(j, 4)
        return self._keep_feasible(u, v, cand, acq(cand))

    def _keep_feasible(self, u: np.ndarray, v: float, cand: np.ndarray, vals: np.ndarray) -> tuple[np.ndarray, float]:
        """``(u, v)`` when ``u`` meets the known constraint (or there is none), else the best candidate."""
        if self._known is None or feasible_mask(self.problem, self.box, u[None])[0]:
            return u, v
        i = int(np.argmax(vals))
        return cand[i], float(vals[i])

    def _propose(self, k: int) -> np.ndarray:
        c = self.cfg
        if self.n_asked < c.n_init:  # Alg. 1 line 2: random samples initialise the GP
            u = self._init[self.n_asked : min(c.n_init, self.n_asked + k)]
            self.kinds += ["init"] * len(u)
            self.acq += [float("nan")] * len(u)
            return u
        gp = self._model()
        observed = self._believed_features(gp)
        feasible = self._feasibility()
        picks = []
        for _ in range(k):
            j = self._n_model_picks
            if j % (c.n_exp + c.n_opt) < c.n_exp:  # Alg. 1 line 4
                u, v = self._explore(gp, j, feasible)
                self.kinds.append("explore")
            else:
                u, v = self._diversify(gp, observed, j, feasible)
                self.kinds.append("diversity")
            self.acq.append(v)
            self._n_model_picks += 1
            picks.append(u)
            mean, _ = gp.predict(u[None])  # kriging believer for the rest of the batch
            observed = np.vstack([observed, mean])
            gp = gp.fantasise(u)
        return np.array(picks)

    def _observe(self, u: np.ndarray, results: Sequence[Any]) -> None:
        m = self.problem.n_features
        for row, r in zip(u, results):
            f = np.asarray(r.features, dtype=float).ravel()
            if r.failed or f.size != m:
                f = np.full(m, np.nan)
            self.U.append(row)
            self.F.append(f)

    def summary(self) -> dict[str, Any]:
        U, F, ok = self._observed()
        out = {
            "X": self.box.from_unit(U),  # told points (n, dim)
            "features": F,  # (n, m), NaN rows for failures
            "usable": ok,  # rows in the GP's training data
            "pick_kind": np.array(self.kinds[: len(U)], dtype=str),  # "init" | "explore" | "diversity"
            "acquisition": np.array(self.acq[: len(U)], dtype=float),
        }
        out.update({f"gp_{k}": v for k, v in self._gp.hyperparameters().items()})
        return out
