"""The ``jt`` command. Imports nothing heavy at module level: ``jt --help`` stays fast.

Every subcommand imports what it needs inside its body. User mistakes (``JtError``) print one line
``jt: ...`` and exit with status 2; ``--debug`` shows the traceback instead.
"""

from __future__ import annotations

import sys
from typing import List, Optional

import typer

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="jt: discover and learn motion strategies for simulated characters.",
    context_settings={"help_option_names": ["-h", "--help"]},
)

from toolkit.bench_cli import bench_app  # noqa: E402  (light: typer only)

app.add_typer(bench_app, name="bench")

_DEBUG = {"on": False}


@app.callback()
def _main(debug: bool = typer.Option(False, "--debug", help="Show tracebacks for errors.")) -> None:
    _DEBUG["on"] = debug


@app.command("run", context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
def run_cmd(
    overrides: Optional[List[str]] = typer.Argument(None, help="Hydra overrides: group=choice, key=value."),
    cfg: bool = typer.Option(False, "--cfg", help="Print the composed config and exit."),
) -> None:
    """Compose the config and run it (e.g. jt run task=highjump search=bds)."""
    from toolkit.config import compose, to_yaml
    from toolkit.quiet import preload_quietly

    preload_quietly()  # no native banner on the terminal, from composing on (workers do the same)
    from toolkit.execution.progress import check_env

    check_env()

    ov = list(overrides or [])
    resume = [o.split("=", 1)[1] for o in ov if o.startswith("resume=")]
    if cfg and not (resume and resume[0] not in ("", "null")):
        # print what composes (every key typed and range-checked), then say if it cannot run yet
        from toolkit.errors import JtError
        from toolkit.schema import run_checks

        conf = compose(ov, run_checks=False)
        typer.echo(to_yaml(conf), nl=False)
        try:
            run_checks(conf)
        except JtError as e:
            typer.echo(f"jt: note: this config does not run as it is: {e}", err=True)
        return
    if resume and resume[0] not in ("", "null"):
        conf = _resume_config(resume[0], ov)
    else:
        conf = compose(ov)
    if cfg:
        typer.echo(to_yaml(conf), nl=False)
        return
    from toolkit.execution.runner import run

    res = run(conf)
    from toolkit import plugins

    keys = list(getattr(plugins.load("task", str(conf.task.name)), "key_metrics", ()))
    ordered = [k for k in keys if k in res.metrics] + [k for k in res.metrics if k not in keys]
    shown = ", ".join(f"{k}={res.metrics[k]:.4g}" for k in ordered[:8])
    typer.echo(f"run {res.run_id} FINISHED  {shown}")
    typer.echo(f"  jt show {res.run_id} store={res.store.root}")
    typer.echo(f"  jt ui store={res.store.root}")


def _resume_config(run_id: str, overrides: list[str]):  # type: ignore[no-untyped-def]
    """The interrupted run's own saved config with ``resume`` set (only ``store=`` may be added)."""
    from omegaconf import OmegaConf

    from toolkit.config import validate
    from toolkit.errors import JtError
    from toolkit.execution.lifecycle import saved_config
    from toolkit.store.tracking import store_root
    from toolkit.store.opening import open_store

    others = [o for o in overrides if not o.startswith(("resume=", "store="))]
    if others:
        raise JtError(f"resume= continues a run with its own config; drop: {' '.join(others)}")
    stores = [o.split("=", 1)[1] for o in overrides if o.startswith("store=")]
    store = open_store(store_root(stores[0] if stores else None), must_exist=True)
    run = store.get_run(run_id)  # one clear line if the id is unknown
    path = saved_config(store, run_id, run)  # saved before the run existed: never missing after a kill
    if path is None and store.is_server:  # a server store, resumed on another machine
        path = store.fetch(run_id, "config.yaml", store.workdir(run_id))
    if path is None or not path.is_file():
        raise JtError(f"run {run_id} has no saved config in {store.root}; it cannot be resumed")
    old = OmegaConf.load(path)
    old.resume = run_id
    old.store = str(store.root)
    return validate(old)


@app.command("compare", context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
def compare_cmd(
    overrides: Optional[List[str]] = typer.Argument(None, help="Overrides shared by every variant."),
    vary: Optional[List[str]] = typer.Option(None, "--vary", help="KEY=a,b[,c]; repeat for a grid."),
    seeds: int = typer.Option(1, "--seeds", help="Seeds per variant (0..N-1 added to seed)."),
    runs: Optional[List[str]] = typer.Option(None, "--runs", help="Compare finished runs instead."),
) -> None:
    """Run a grid of variants over seeds and tabulate key metrics (mean ± std)."""
    from toolkit.execution.compare import compare, compare_runs
    from toolkit.quiet import preload_quietly

    preload_quietly()
    from toolkit.execution.progress import check_env

    check_env()

    extra_runs = [o for o in (overrides or []) if "=" not in o] if runs else []
    if runs:
        res = compare_runs(list(runs) + extra_runs, [o for o in (overrides or []) if "=" in o])
    else:
        res = compare(overrides or [], vary or [], seeds)
    typer.echo(res.table)
    typer.echo(f"comparison run {res.run_id}: jt show {res.run_id} store={res.store_root}")


@app.command("show", context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
def show_cmd(
    run_id: str = typer.Argument(..., help="Run id."),
    overrides: Optional[List[str]] = typer.Argument(None, help="store=PATH or store=http://host:port"),
    artifact: Optional[str] = typer.Option(None, "--artifact", help="Print one artifact: an .h5 as its "
                                           "preview (groups, datasets, shapes, attributes), text as it is."),
) -> None:
    """Print a run's description, config, metrics, summary table and artifacts (a server store's are
    downloaded), or one artifact with --artifact NAME."""
    from toolkit.execution.show import show

    typer.echo(show(run_id, _store_arg(overrides), artifact))


@app.command("ui", context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
def ui_cmd(
    overrides: Optional[List[str]] = typer.Argument(None, help="store=PATH or store=http://host:port"),
    port: int = typer.Option(5000, "--port"),
    open_browser: bool = typer.Option(False, "--open", help="Open the first URL printed in a browser."),
) -> None:
    """Serve the MLflow UI for the store on 127.0.0.1 and print where each task's runs are, in
    MLflow's "Model training" view with the task's key metrics as columns (a server store: print
    its URL)."""
    from toolkit.store.tracking import is_server_uri, store_root

    root = store_root(_store_arg(overrides))
    if is_server_uri(root):  # the tracking server serves its own UI: nothing to start here
        target = f"{root}/#/experiments?workflowType=machine_learning"
        typer.echo(f"MLflow UI: {target}  (served by the tracking server)")
        if open_browser:
            import webbrowser

            webbrowser.open(target)
        return
    from toolkit.store import ui

    ui.check(root, port)  # a busy port, a bind beyond loopback, a bad store: one line, no URL printed
    ui.ensure_store(root)
    experiments = ui.prepare(root)  # jt's experiments tagged for the UI, the newest run's first
    rows = [(name, ui.url(port, eid, view)) for eid, name, view in experiments]
    rows.append(("all experiments", ui.url(port)))
    width = max(len(r[0]) for r in rows)
    typer.echo(f"MLflow UI for {root} (Ctrl-C to stop):")
    for name, link in rows:
        typer.echo(f"  {name:<{width}}  {link}")
    if open_browser:
        ui.open_when_up(rows[0][1], port)
    ui.serve(root, port)


@app.command("plugins")
def plugins_cmd(kind: Optional[str] = typer.Argument(None, help="Only this kind (e.g. spd, search).")) -> None:
    """List installed plugins: kind, name, distribution, summary (broken ones with the reason)."""
    from toolkit import plugins
    from toolkit.errors import JtError

    kinds = list(plugins.KINDS)
    if kind:
        k = plugins.kind_of(kind)
        if k is None:
            raise JtError(f"unknown plugin kind '{kind}'; choose one of: {', '.join(kinds)}")
        kinds = [k]
    rows = [("KIND", "NAME", "DISTRIBUTION", "SUMMARY")]
    for k in kinds:
        for info in plugins.available(k):
            status, summary = plugins.describe(info)
            rows.append((k, info.name, info.dist, summary if status == "ok" else f"BROKEN: {summary}"))
    widths = [max(len(r[i]) for r in rows) for i in range(3)]
    for r in rows:
        typer.echo(f"{r[0]:<{widths[0]}}  {r[1]:<{widths[1]}}  {r[2]:<{widths[2]}}  {r[3]}".rstrip())


@app.command("study", context_settings={"allow_extra_args": True, "ignore_unknown_options": True,
                                         "help_option_names": []})
def study_cmd(ctx: typer.Context, task: Optional[str] = typer.Argument(None, help="A task with analysis tools."),
              tool: Optional[str] = typer.Argument(None, help="One of its tools (TOOL --help: its arguments).")) -> None:
    """Analysis tools the tasks ship (figures and tables from runs): jt study [TASK [TOOL ARGS...]]."""
    from toolkit import study

    if task in ("-h", "--help") or (task is None and tool is None):
        typer.echo("jt study TASK TOOL [ARGS...]: the analysis tools the tasks ship (TOOL --help: its arguments)")
        for line in study.listing():
            typer.echo(f"  {line}")
        return
    if tool is None or tool in ("-h", "--help"):
        for line in study.listing(task):
            typer.echo(line)
        return
    main_fn = study.find(task, tool)
    main_fn(list(ctx.args))


@app.command("play")
def play_cmd(
    ref: Optional[str] = typer.Argument(None, metavar="[NAME|RUN_ID|PATH]",
                                        help="A shipped skill's name, a run id, a run's folder or its ppo.h5; none: list the skills."),
    out: Optional[str] = typer.Option(None, "--out", help="Folder for NAME.gif (and NAME.mp4 with imageio-ffmpeg); "
                                                          "default ./play."),
    seconds: Optional[float] = typer.Option(None, "--seconds", help="End the episode after S simulated seconds."),
    seed: Optional[int] = typer.Option(None, "--seed", help="The environment's seed (default: the skill's / run's)."),
    start: Optional[str] = typer.Option(None, "--start", help="Where the episode starts, for tasks that offer a choice (a phase...)."),
    gui: bool = typer.Option(False, "--gui", help="Show PyBullet's window (where a display exists), at real time."),
    store: Optional[str] = typer.Option(None, "--store", help="The store a RUN_ID is looked up in (default: $JT_STORE or ./artifacts)."),
    width: int = typer.Option(320, "--width", help="Frame width, px (>= 320)."),
    height: int = typer.Option(240, "--height", help="Frame height, px (>= 240)."),
    ship: Optional[str] = typer.Option(None, "--ship", metavar="RUN_ID",
                                       help="Make the skill NAME from this run (slim policy, prior, manifest), in --out "
                                            "if given, else in its task's skills package."),
    description: str = typer.Option("", "--description", help="With --ship: the skill's one-line description."),
) -> None:
    """Replay a trained skill headless: jt play lists the shipped ones, jt play NAME writes its GIF."""
    import time

    t0 = time.perf_counter()
    from toolkit import skills
    from toolkit.errors import JtError

    if ref is None and ship is None:
        typer.echo("jt play NAME: replay a shipped skill (jt play RUN_ID | FOLDER | ppo.h5: a trained run)")
        for line in skills.listing() or ["(no skills shipped)"]:
            typer.echo(f"  {line}")
        return
    from toolkit.quiet import preload_quietly

    preload_quietly()  # no native banner on the terminal
    from toolkit import play, play_targets

    if ship is not None:
        if not ref:
            raise JtError("--ship RUN_ID NAME: give the skill's name after the run id")
        from toolkit.ship import ship as ship_run

        skill = ship_run(ship, ref, store, out, description)
        typer.echo(f"skill {skill.name} (task={skill.task}) in {skill.folder}: {skills.measure_text(skill.measure)}")
        typer.echo(f"  jt play {skill.name}" if out is None else f"  jt play {skill.folder}")
        return
    play.check_options(width, height, seconds)
    target = play_targets.target_of(ref, store)
    done = play.replay(target, out or play.DEFAULT_OUT, seconds, seed, start, gui, width, height)
    typer.echo(f"{target.label} (task={target.task_name}): {done.line}")
    files = ", ".join(str(f) for f in done.files) or "no frames"
    typer.echo(f"  {files} ({done.size[0]}x{done.size[1]}, {done.frames} frames) in {time.perf_counter() - t0:.1f} s")
    for note in done.notes:
        typer.echo(f"  {note}")


def _store_arg(overrides: Optional[List[str]]) -> Optional[str]:
    from toolkit.errors import JtError

    store = None
    for o in overrides or []:
        if o.startswith("store="):
            store = o.split("=", 1)[1]
        else:
            raise JtError(f"unexpected argument '{o}'; only store=PATH (or store=http://host:port) is accepted here")
    return store


def _usage_line(e: Exception) -> str:
    """A command-line mistake in one line, with the valid commands when one was unknown."""
    msg = " ".join(str(e.format_message()).split())  # type: ignore[attr-defined]
    ctx = getattr(e, "ctx", None)
    command = getattr(ctx, "command", None)
    if msg.startswith("No such command") and command is not None and hasattr(command, "list_commands"):
        msg += f" Valid: {', '.join(command.list_commands(ctx))}."
    if ctx is not None and getattr(ctx, "command_path", ""):
        msg += f" (see: {ctx.command_path} --help)"
    return msg


def main() -> None:
    """Console entry point: one line for user mistakes, exit status 2."""
    debug = "--debug" in sys.argv
    try:
        rc = app(standalone_mode=False)
        if isinstance(rc, int) and rc:  # typer turns Ctrl-C into exit code 130 and returns it
            if rc == 130:
                typer.echo("jt: interrupted", err=True)
            sys.exit(rc)
    except Exception as e:  # noqa: BLE001
        from toolkit.errors import JtError

        if debug:
            raise
        kinds = {c.__name__ for c in type(e).__mro__}  # click's classes, or typer's vendored copies
        if "Exit" in kinds:
            sys.exit(getattr(e, "exit_code", 0))
        if "ClickException" in kinds:
            typer.echo(f"jt: {_usage_line(e)}", err=True)
            sys.exit(2)
        if "Abort" in kinds:
            typer.echo("jt: aborted", err=True)
            sys.exit(130)
        if isinstance(e, JtError):
            typer.echo(f"jt: {e}", err=True)
            sys.exit(2)
        typer.echo(f"jt: internal error: {type(e).__name__}: {e} (rerun with --debug for the traceback)", err=True)
        sys.exit(1)
    except KeyboardInterrupt:
        typer.echo("jt: interrupted", err=True)
        sys.exit(130)


if __name__ == "__main__":  # pragma: no cover
    main()
