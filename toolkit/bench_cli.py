"""``jt bench ...``: benchmarks. Speed is measured here, never in tests; quote ratios from one run."""

from __future__ import annotations

import json
import math
import platform
from pathlib import Path
from typing import List, Optional

import typer

from toolkit.errors import JtError

bench_app = typer.Typer(no_args_is_help=True, help="Benchmarks (speed is measured here, never in tests).")

def _split(value: str, valid: "tuple[str, ...] | list[str]", what: str) -> list[str]:
    items = [v.strip() for v in value.split(",") if v.strip()]
    bad = [v for v in items if v not in valid]
    if bad or not items:
        raise JtError(f"unknown {what} '{','.join(bad) or value}'; choose from: {', '.join(valid)}")
    return items


def writable(path: Optional[Path], option: str) -> None:
    """One ``JtError`` line, before any work, when ``path`` cannot be written (``toolkit.study``'s
    check, which every analysis tool makes too)."""
    if path is not None:
        from toolkit.study import writable_file

        writable_file(path, option)


def check_rates(task: str, overrides: List[str], rates: List[float]) -> None:
    """Each control rate divides the task's simulation rate into whole substeps, as ``jt run``
    requires; one ``JtError`` line naming the rates that would work."""
    from toolkit.config import compose, group_of

    sim_hz = float(group_of(group_of(compose([f"task={task}", *overrides]), "sim"), "sim_hz"))
    bad = [r for r in rates if abs(sim_hz / r - round(sim_hz / r)) > 1e-6 or round(sim_hz / r) < 1]
    if bad:
        ok = [sim_hz / n for n in range(1, 61) if (sim_hz / n).is_integer()][:8]
        raise JtError(f"--rates {','.join(f'{r:g}' for r in bad)}: task={task} simulates at {sim_hz:g} Hz and a control "
                      f"rate must divide it into whole substeps (e.g. {', '.join(f'{r:g}' for r in ok)})")


def machine_info() -> dict:
    """What the numbers were measured on."""
    import os

    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "python": platform.python_version(),
            "platform": platform.platform()}


@bench_app.command("spd")
def bench_spd(
    models: str = typer.Option("", "--models", help="Comma list of characters (the character config group); "
                                                  "default: the simulator's benchmark set."),
    backends: str = typer.Option("", "--backends", help="Comma list of installed SPD backends (jt plugins); "
                                                      "default: the simulator's benchmark set."),
    sim_name: str = typer.Option("", "--sim", help="Simulator plugin; default: the one installed."),
    samples: int = typer.Option(200, "--samples", help="Timed calls per (model, backend)."),
    seed: int = typer.Option(0, "--seed"),
    json_out: Optional[Path] = typer.Option(None, "--json", help="Write the results as JSON here."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Log-log plot of solve time vs DoF (PNG)."),
    check: bool = typer.Option(False, "--check", help="Only check that all backends agree (≤ 1e-8)."),
) -> None:
    """Time the SPD solve and the whole simulation step per model and backend (thesis Tables 2.2/2.3)."""
    from toolkit import plugins
    from toolkit.config import group_options
    from toolkit.quiet import preload_quietly

    preload_quietly()  # no native banner among the rows
    if samples < 1:
        raise JtError(f"--samples must be >= 1, got {samples}")
    writable(json_out, "--json")
    writable(plot, "--plot")
    sim = plugins.load("sim", sim_name or plugins.sole("sim", "--sim"))  # the benchmark and its characters
    bench, loader = getattr(sim, "spd_bench", lambda: None)(), sim.load_character
    if bench is None:
        raise JtError(f"sim={sim_name or sim.__name__} has no SPD benchmark (spd_bench)")
    model_list = _split(models or ",".join(bench.MODELS), group_options("character"), "model")
    if check:
        worst = bench.check_agreement(model_list, n_states=20, seed=seed, loader=loader)
        typer.echo(f"largest relative torque difference between backends: {worst:.3e} (limit 1e-8)")
        if not worst <= 1e-8:
            raise typer.Exit(1)
        return
    backend_list = _split(backends or ",".join(bench.BACKENDS), plugins.names("spd"), "backend")
    rows = bench.time_spd(model_list, backend_list, n_samples=samples, seed=seed, loader=loader)
    header = f"{'model':<10} {'dof':>4} {'depth':>5} {'backend':<8} {'solve_us':>10} {'step_us':>10} {'share%':>7}"
    typer.echo(header)
    for r in rows:
        share = 100.0 * r["solve_us_median"] / r["step_us_median"] if r.get("step_us_median") else float("nan")
        typer.echo(f"{r['model']:<10} {r['dof']:>4} {r['depth']:>5} {r['backend']:<8} "
                   f"{r['solve_us_median']:>10.1f} {r['step_us_median']:>10.1f} {share:>7.1f}")
    result = {"machine": machine_info(), "results": rows}
    if json_out:
        json_out.parent.mkdir(parents=True, exist_ok=True)
        json_out.write_text(json.dumps(result, indent=2))
        typer.echo(f"wrote {json_out}")
    png = plot or (json_out.with_suffix(".png") if json_out else None)
    if png:
        _plot(rows, png)
        typer.echo(f"wrote {png}")


def _plot(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 4))
    for b in sorted({r["backend"] for r in rows}):
        pts = sorted((r["dof"], r["solve_us_median"]) for r in rows if r["backend"] == b and r["solve_us_median"] == r["solve_us_median"])
        if pts:
            ax.plot(*zip(*pts), marker="o", label=b)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("degrees of freedom")
    ax.set_ylabel("SPD solve time (µs, median)")
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


@bench_app.command("ppo")
def bench_ppo(
    env: str = typer.Option("Pendulum-v1", "--env", help="Gymnasium id with a Box action space."),
    samples: int = typer.Option(200_000, "--samples", help="Sample budget."),
    seed: int = typer.Option(0, "--seed"),
    target: float = typer.Option(-400.0, "--target", help="Return the final policy must reach."),
    json_out: Optional[Path] = typer.Option(None, "--json", help="Write the curve as JSON here."),
) -> None:
    """PPO sanity benchmark: a small standard control task must reach a known return (docs/ppo.md)."""
    from toolkit.rl.sanity import run_sanity

    res = run_sanity(env_id=env, total_samples=samples, seed=seed, verbose=True)
    ok = res["final_return"] >= target
    typer.echo(f"{env}: final return {res['final_return']:.1f} after {res['samples']} samples "
               f"in {res['seconds']:.0f}s (target {target}): {'PASS' if ok else 'FAIL'}")
    if json_out:
        json_out.parent.mkdir(parents=True, exist_ok=True)
        json_out.write_text(json.dumps({"machine": machine_info(), **res}, indent=2, default=float))
    if not ok:
        raise typer.Exit(1)


@bench_app.command("rollout", context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
def bench_rollout(
    overrides: Optional[List[str]] = typer.Argument(None, help="Hydra overrides added to every task's config "
                                                    "(e.g. agent.samples_per_iteration=1024), after the bench's own."),
    tasks: str = typer.Option("highjump", "--tasks", help="Comma list of policy tasks (their envs)."),
    spd: str = typer.Option("task", "--spd", help="SPD backend: task (the task's own) or an installed one (jt plugins)."),
    action: str = typer.Option("task", "--action",
                               help="Action space: task (the task's own; one that needs a trained prior is "
                                    "replaced by raw) or an action group to use."),
    rates: str = typer.Option("10,30", "--rates", help="Control rates (Hz) of the env measurement."),
    steps: int = typer.Option(400, "--steps", help="Timed control steps per rate."),
    collect_steps: int = typer.Option(256, "--collect-steps",
                                      help="Collection steps per env (16 envs per worker; 256: a 4096-sample PPO "
                                           "iteration each, long enough for a steady 1 -> 2 worker figure)."),
    workers: str = typer.Option("1,2", "--workers", help="Worker counts of the collection measurement."),
    loops: str = typer.Option("auto", "--loops", help="Comma list of substep loops (sim.loop): auto, compiled, python."),
    repeats: int = typer.Option(3, "--repeats", help="Env measurements per rate (fresh env each); the median is shown."),
    train_iterations: int = typer.Option(2, "--train-iterations",
                                         help="PPO iterations of the training measurement (jt run, the task's own "
                                              "agent, updates included; the first is left out as warm-up); 0: none."),
    train_workers: str = typer.Option("1,2", "--train-workers", help="agent.n_workers of the training measurement."),
    json_out: Optional[Path] = typer.Option(None, "--json", help="Write the results as JSON here."),
) -> None:
    """Where a policy env's time goes per 600 Hz substep and per reset, PPO collection samples/s per
    worker, and training's samples/s with the PPO updates (as jt run trains)."""
    from toolkit import plugins
    from toolkit.config import group_options
    from toolkit.quiet import preload_quietly
    from toolkit.rl.rollout_bench import check_policy_task, format_table, run_bench, task_overrides

    if spd != "task" and len(_split(spd, plugins.names("spd"), "backend")) != 1:
        raise JtError(f"--spd takes one backend, got {spd!r}; choose from: task, {', '.join(plugins.names('spd'))}")
    actions = group_options("action")
    if action != "task" and action not in actions:
        raise JtError(f"unknown --action '{action}'; choose from: task, {', '.join(actions)}")
    names = [t.strip() for t in tasks.split(",") if t.strip()]
    if not names:
        raise JtError(f"--tasks takes a comma list of policy tasks, got {tasks!r}")
    for t in names:
        check_policy_task(t)  # one clear line for an unknown task or one that trains no policy
    try:
        rate_list = [float(r) for r in rates.split(",") if r.strip()]
        worker_list = tuple(int(w) for w in workers.split(",") if w.strip())
        train_list = tuple(int(w) for w in train_workers.split(",") if w.strip())
    except ValueError:
        raise JtError(f"--rates, --workers and --train-workers take comma lists of numbers, got {rates!r}, "
                      f"{workers!r}, {train_workers!r}") from None
    if not rate_list or not all(math.isfinite(r) and r > 0 for r in rate_list):
        raise JtError(f"--rates takes positive control rates (Hz), got {rates!r}")
    if collect_steps < 1:
        raise JtError(f"--collect-steps must be >= 1 (steps per env of the collection measurement), got {collect_steps}")
    if not worker_list or any(w < 1 for w in worker_list):
        raise JtError(f"--workers takes worker counts >= 1, got {workers!r}")
    if repeats < 1 or steps < 1:
        raise JtError(f"--repeats and --steps must be >= 1, got {repeats} and {steps}")
    if train_iterations < 0:
        raise JtError(f"--train-iterations must be >= 0 (0: no training measurement), got {train_iterations}")
    if not train_list or any(w < 1 for w in train_list):
        raise JtError(f"--train-workers takes worker counts >= 1, got {train_workers!r}")
    loop_list = [x.strip() for x in loops.split(",") if x.strip()]
    bad = [x for x in loop_list if x not in ("auto", "compiled", "python")]
    if bad or not loop_list:
        raise JtError(f"--loops {loops!r}: choose from auto, compiled, python (a comma list)")
    extra = list(overrides or [])
    dashed = [o for o in extra if o.startswith("-")]
    if dashed:  # a mistyped option would otherwise read as a Hydra override
        raise JtError(f"no such option: {dashed[0]} (see: jt bench rollout --help)")
    writable(json_out, "--json")  # before the benchmark, not after it
    preload_quietly()  # no native banner among the figures
    plans = [(t, loop, *task_overrides(t, action, spd, [f"sim.loop={loop}", *extra]))  # every config composes first
             for t in names for loop in loop_list]
    for t, _, over, _ in plans:  # a rate jt run would refuse (600 / 7 substeps) is refused here too
        check_rates(t, over, rate_list)
    out = {"machine": machine_info(), "results": []}
    for t, loop, over, header in plans:
        typer.echo(f"{t}, sim.loop={loop}: measuring ...")
        res = run_bench(t, over, rate_list, steps, collect_steps, worker_list, echo=typer.echo, repeats=repeats,
                        train_iterations=train_iterations, train_workers=train_list, header=header)
        typer.echo(format_table(res))
        out["results"].append(res)
    if json_out:
        json_out.parent.mkdir(parents=True, exist_ok=True)
        json_out.write_text(json.dumps(out, indent=2))
        typer.echo(f"wrote {json_out}")


@bench_app.command("evaluation", context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
def bench_evaluation(
    overrides: Optional[List[str]] = typer.Argument(None, help="jt run's overrides (e.g. task=TASK "
                                                    "experiment=laptop)."),
    store: Optional[Path] = typer.Option(None, "--store", help="The store to run in (a kept one reuses its pose "
                                         "prior); default: a fresh temporary one, removed after."),
    json_out: Optional[Path] = typer.Option(None, "--json", help="Write the breakdown as JSON here."),
    quiet: bool = typer.Option(False, "--quiet", help="Do not show the run's own output."),
) -> None:
    """Where one jt run's wall time goes: collection, PPO update, the task's hooks (curriculum
    rollouts), checkpoints, final rollout, pictures, measures, prior, and the rest (process start,
    store); samples per wall-second (docs/performance.md)."""
    import shutil
    import tempfile

    from toolkit.eval_bench import breakdown, format_breakdown

    extra = list(overrides or [])
    dashed = [o for o in extra if o.startswith("-")]
    if dashed:
        raise JtError(f"no such option: {dashed[0]} (see: jt bench evaluation --help)")
    if not extra:
        raise JtError("jt bench evaluation needs jt run's overrides, e.g.: jt bench evaluation task=TASK "
                      "experiment=laptop")
    from toolkit.config import compose

    compose(extra)  # a mistake is one line before anything runs
    writable(json_out, "--json")
    tmp = None if store is not None else Path(tempfile.mkdtemp(prefix="jt-bench-eval-"))
    try:
        res = breakdown(extra, store if store is not None else tmp, echo=None if quiet else typer.echo)
    finally:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
    typer.echo(format_breakdown(res))
    if json_out:
        json_out.parent.mkdir(parents=True, exist_ok=True)
        json_out.write_text(json.dumps({"machine": machine_info(), **res}, indent=2))
        typer.echo(f"wrote {json_out}")
