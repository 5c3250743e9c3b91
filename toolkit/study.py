"""``jt study TASK TOOL ...``: the analysis tools a task ships, behind one door.

A task declares its tools by name (``Task.studies``: ``{"survival": "jt_tasks.spacetime.analysis.
survival_plot:main"}``), each a ``main(argv)`` that reads runs or files and writes figures or
tables: the registry finds them, so the core names no task. ``jt study`` lists every task's tools,
``jt study TASK`` one task's, ``jt study TASK TOOL --help`` a tool's arguments.

A tool builds its parser with ``parser(...)``: a mistake in its arguments is one ``JtError`` line
(``jt: <tool>: <what>``, exit 2), as everywhere in jt, instead of argparse's usage block. Before any
work it checks its inputs with ``existing_file``, ``writable_file`` / ``writable_folder`` and
``task_of`` (the task of the run that wrote a file), each failure one ``JtError`` line too.
"""

from __future__ import annotations

import argparse
import importlib
import tempfile
from pathlib import Path
from typing import Any, Callable, Optional, Sequence

from toolkit.errors import JtError


class _OneLineParser(argparse.ArgumentParser):
    """``argparse`` whose errors are one ``JtError`` line naming the tool (``--help`` unchanged)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        raise JtError(f"{self.prog}: {message} (see {self.prog} --help)")


def parser(prog: str, description: str) -> argparse.ArgumentParser:
    """An argument parser for a study tool whose mistakes are one line.

    Args:
        prog: how the tool is called, e.g. ``jt study spacetime survival``.
        description: the tool's one-paragraph help.
    """
    return _OneLineParser(prog=prog, description=description)


def existing_file(path: Any, what: str) -> Path:
    """``path`` as a ``Path`` when it is a file; else one ``JtError`` line (``<what> <path>: no such
    file``, or ``... is a folder``)."""
    p = Path(path).expanduser()
    if p.is_dir():
        raise JtError(f"{what} {path}: is a folder, not a file")
    if not p.is_file():
        raise JtError(f"{what} {path}: no such file")
    return p


def writable_file(path: Any, option: str, suffix: Optional[str] = None) -> Path:
    """``path`` as a ``Path`` when a file can be written there (its folder is created as writing
    would create it; a file made for the check is removed again); else one ``JtError`` line naming
    ``option``. ``suffix`` (``".png"``): the file must end so."""
    p = Path(path).expanduser()
    if suffix is not None and p.suffix.lower() != suffix:
        raise JtError(f"{option}={path}: the output is a {suffix} file (e.g. {option} out{suffix})")
    existed = p.exists()
    try:
        if p.is_dir():
            raise IsADirectoryError(21, "is a folder")
        p.parent.mkdir(parents=True, exist_ok=True)
        with open(p, "a"):
            pass
    except OSError as e:
        raise JtError(f"{option}={path}: cannot write there ({e.strerror or e}); give another path") from None
    if not existed:
        p.unlink()
    return p


def writable_folder(path: Any, option: str) -> Path:
    """``path`` as a ``Path`` when files can be written in it (created if missing, as writing
    would); else one ``JtError`` line naming ``option``."""
    p = Path(path).expanduser()
    try:
        if p.exists() and not p.is_dir():
            raise NotADirectoryError(20, "is a file, not a folder")
        p.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=p):
            pass
    except OSError as e:
        raise JtError(f"{option}={path}: cannot write there ({e.strerror or e}); give another folder") from None
    return p


def task_of(found: Any) -> Optional[str]:
    """The task of the run that wrote an artifact, or None when nothing says: ``found`` is a
    ``toolkit.store.resolve.Resolved`` (its run's ``jt.task`` tag) or a path; else the
    ``config.yaml`` beside the file or in the folder above (a run's work folder holds one)."""
    run = getattr(found, "run", None)
    tag = run.data.tags.get("jt.task") if run is not None else None
    if tag:
        return str(tag)
    path = Path(getattr(found, "path", found))
    for folder in path.parents[:2]:
        if (folder / "config.yaml").is_file():
            try:
                from omegaconf import OmegaConf

                name = OmegaConf.select(OmegaConf.load(folder / "config.yaml"), "task.name")
            except Exception:  # noqa: BLE001 - an unreadable config says nothing about the task
                return None
            return None if name is None else str(name)
    return None


def require_task(found: Any, ref: str, task: str, prog: str) -> None:
    """One ``JtError`` line when the run that wrote ``found`` is known to be of another task than
    ``task`` (``task_of``); nothing when it is ``task`` or unknown."""
    other = task_of(found)
    if other is not None and other != task:
        raise JtError(f"{ref}: a task={other} run; {prog} reads task={task} runs")


def studies() -> dict[str, dict[str, str]]:
    """``{task: {tool: "module:function"}}`` of every installed task that ships tools (a broken
    task plugin is left out)."""
    from toolkit import plugins

    out: dict[str, dict[str, str]] = {}
    for name in plugins.names("task"):
        try:
            tools = dict(getattr(plugins.load("task", name), "studies", {}) or {})
        except JtError:
            continue
        if tools:
            out[name] = tools
    return out


def summary(target: str) -> str:
    """The first line of a tool's module docstring (what ``jt study TASK`` lists)."""
    module = importlib.import_module(target.partition(":")[0])
    return ((module.__doc__ or "").strip().splitlines() or [""])[0]


def find(task: str, tool: str) -> Callable[[Optional[Sequence[str]]], Any]:
    """The ``main(argv)`` of ``task``'s tool ``tool``; one ``JtError`` line naming the choices."""
    every = studies()
    if task not in every:
        raise JtError(f"no study tools for task '{task}'; tasks with tools: {', '.join(sorted(every)) or '(none)'}")
    if tool not in every[task]:
        raise JtError(f"unknown tool '{tool}' of task={task}; choose one of: {', '.join(sorted(every[task]))}")
    module, _, function = every[task][tool].partition(":")
    return getattr(importlib.import_module(module), function or "main")


def listing(task: Optional[str] = None) -> list[str]:
    """Lines listing the tools (of ``task``, or of every task): ``jt study TASK TOOL  summary``."""
    every = studies()
    if task is not None and task not in every:
        raise JtError(f"no study tools for task '{task}'; tasks with tools: {', '.join(sorted(every)) or '(none)'}")
    rows = [(f"jt study {t} {name}", summary(target)) for t in sorted(every) if task in (None, t)
            for name, target in sorted(every[t].items())]
    width = max((len(a) for a, _ in rows), default=0)
    return [f"{a:<{width}}  {b}" for a, b in rows]
