"""Tasks (``jt.tasks``): what one evaluation does, and what a run measures."""

from __future__ import annotations

import abc
import dataclasses
from pathlib import Path
from typing import Any, Callable, ClassVar, Optional, Sequence

from toolkit.interfaces.plugin import Plugin
from toolkit.interfaces.searcher import SearchProblem, Space


@dataclasses.dataclass
class EvalContext:
    """Where and how one evaluation runs (possibly in a worker process).

    Attributes:
        index: evaluation number within the run (0-based).
        seed: seed for this evaluation, derived deterministically from the run seed and index.
        workdir: directory for this evaluation's files (HDF5 artifacts, PNGs, checkpoints). It
            survives an interruption, so an evaluation can resume from a checkpoint found there.
            Every file left in it is logged as an artifact of the evaluation's MLflow run.
        progress: optional callback ``progress(fraction, message)`` for long work.
    """

    index: int
    seed: int
    workdir: Path
    progress: Optional[Callable[[float, str], None]] = None

    def report(self, fraction: float, message: str = "") -> None:
        """Report progress in ``[0, 1]`` if anyone listens."""
        if self.progress is not None:
            self.progress(fraction, message)


@dataclasses.dataclass
class Evaluation:
    """What one evaluation returns to the runner (and through it to the searcher and MLflow).

    Attributes:
        metrics: final scalar metrics, logged on the evaluation's run.
        features: strategy feature vector ``(n_features,)`` (BDS), or empty.
        objectives: objective values ``(n_objectives,)``, all minimised (RMOO/BSOO), or empty.
        failed: True when the evaluation failed as the task defines failure (a fall, NaN state);
            a failure is a result, not an error.
        reason: why it failed.
        history: metric curves ``{name: [(step, value), ...]}`` or with the time each point was
            measured, ``[(step, value, unix_seconds), ...]`` (MLflow's wall-time axis; without it every
            point carries the time the runner logged it). Logged as ``train/<name>`` (the task's
            ``curve_prefix``; a name with a ``/`` is kept as it is), so a curve never shares its key
            with the final value in ``metrics``; ``step`` is the curve's x (samples, for training).
        artifacts: names of files in the workdir to log (default: every file there).
        point: the parameters evaluated (filled in by the runner).
        run_id: its nested MLflow run, '' when logged on the outer run (filled in by the runner
            for ``summarize`` / ``summary_artifacts`` / ``summary_table``).
    """

    metrics: dict[str, float] = dataclasses.field(default_factory=dict)
    features: Sequence[float] = ()
    objectives: Sequence[float] = ()
    failed: bool = False
    reason: str = ""
    history: dict[str, list[tuple]] = dataclasses.field(default_factory=dict)
    artifacts: Optional[list[str]] = None
    point: dict[str, float] = dataclasses.field(default_factory=dict)
    run_id: str = dataclasses.field(default="", compare=False)


class Task(Plugin, abc.ABC):
    """An experiment: what one evaluation does and which metrics matter.

    A task is built from the whole composed run config (it picks its simulator, SPD backend,
    action space, rewards and curriculum from it through the registry). It must be cheap to
    construct; heavy set-up happens in ``evaluate``, which may run in a worker process.

    Attributes:
        key_metrics: the metrics ``jt compare`` tabulates (mean ± std over seeds).
        timing_metrics: metrics that measure wall time (frames per second, time shares): they
            differ between runs by nature and are left out of same-seed checks.
        curve_prefix: where an evaluation's ``history`` curves go in MLflow (``train/``: the chart
            section "train", ``train/mean_return`` beside the final ``mean_return``).
        ignores_groups: the groups this task never reads; choosing one of them for it is
            refused at composition, in one line, instead of being silently ignored: an optional
            group (``action``, ``reward``, ``curriculum``) whenever the composed config has it, a
            group with a default (``sim``, ``spd``, ``character``, ``agent``) when the command line
            chooses it or sets one of its keys. Empty by default (a task may read any group).
        record_keys: the keys of the records its reward terms are given (None: not declared, not
            checked). With it, composition refuses a ``reward`` term that reads a key the records
            do not have (``RewardTerm.needs``), in one line, before a run opens.
        action_inputs: what its environment gives an action space besides the action
            (``"condition"``: ``set_condition``, ``"phase"``: ``set_phase``; None: not declared).
            With it, composition refuses an action space whose ``ActionSpace.needs`` it lacks.
        curriculum_attrs: the environment attributes a curriculum may drive (None: not
            declared). With it, composition refuses a curriculum that drives others
            (``Curriculum.drives``): it would set attributes nothing reads.
        needs_spd_torques: True when the task reads or changes the SPD torques each substep (its
            own force terms, limits, timing): composition then refuses a backend that computes
            its torques inside the simulator's step (``SPDBackend.steps_itself``). False by default.
        studies: the analysis tools it ships, ``{tool: "module:main"}``, run as ``jt study
            <task> <tool> ...`` (``toolkit.study``); empty by default.
        skills: the package holding its shipped trained skills, one sub-folder each with a
            ``manifest.yaml`` (``"jt_tasks.jumping.skills"``; ``jt play``, ``toolkit.skills``);
            "" (none) by default.

    Args:
        cfg: the whole composed run config (``cfg.task`` is this task's group).
    """

    key_metrics: ClassVar[tuple[str, ...]] = ()
    timing_metrics: ClassVar[tuple[str, ...]] = ()
    curve_prefix: ClassVar[str] = "train/"
    ignores_groups: ClassVar[tuple[str, ...]] = ()
    record_keys: ClassVar[Optional[frozenset[str]]] = None
    action_inputs: ClassVar[Optional[frozenset[str]]] = None
    curriculum_attrs: ClassVar[Optional[frozenset[str]]] = None
    needs_spd_torques: ClassVar[bool] = False
    studies: ClassVar[dict[str, str]] = {}
    skills: ClassVar[str] = ""

    def __init__(self, cfg: Any) -> None:
        self.cfg = cfg

    def problem(self) -> SearchProblem:
        """The outer search problem; by default an empty box (the task runs once)."""
        return SearchProblem(space=Space(params=()))

    @abc.abstractmethod
    def evaluate(self, point: dict[str, float], ctx: EvalContext) -> Evaluation:
        """Run one evaluation at ``point`` (names of ``problem().space``)."""

    def make_env(self, point: Optional[dict[str, float]] = None, seed: Optional[int] = None) -> Any:
        """A ``gymnasium.Env`` of this task at ``point`` (None: the defaults), for other RL libraries.

        Tasks that train a policy override this; ``toolkit.gym_envs`` exposes it to
        ``gymnasium.make``. The default says the task has none.
        """
        from toolkit.errors import JtError

        raise JtError(f"task {type(self).__name__} has no Gymnasium environment (it does not train a policy)")

    def summarize(self, evaluations: Sequence[Evaluation], workdir: Path) -> dict[str, Any]:
        """Run-level metrics over all evaluations; may write files (tables, plots) to ``workdir``.

        A value is a float (one metric) or a curve ``[(step, value), ...]`` logged as that metric's
        history (e.g. the hypervolume after each simulation).
        """
        return {}

    def summary_artifacts(self, evaluations: Sequence[Evaluation], folder: Path) -> list[Path]:
        """Pictures (or other files) that summarise a whole search, for its outer run.

        The runner calls this once at the end of a run, after ``summarize``, and logs every file
        returned on the outer run (a file under ``folder`` keeps its sub-folder), so the run a
        researcher opens first carries the gallery, not only its child runs. Default: none.

        Args:
            evaluations: every evaluation of the run, in order (``point``, ``metrics``, ``features``,
                ``objectives``; their files are in the run's ``work/<run>/eval_NNNN/`` folders).
            folder: an empty folder to write into.

        Returns:
            The files to log (paths that are no file are skipped with a warning).
        """
        return []

    def summary_table(self, evaluations: Sequence[Evaluation]) -> Optional[tuple[list[str], list[list]]]:
        """A table that summarises the run, ``(header, rows)``, or None (the default: no table).

        Cells are numbers or text. The runner writes it to the outer run's ``summary_table.json``
        and its description (a markdown table on the run's Overview page); ``jt show RUN_ID``
        prints it.
        """
        return None
