"""``jt study TASK TOOL ...``: the analysis tools a task ships, behind one door.

A task declares its tools by name (``Task.studies``: ``{"survival": "jt_tasks.spacetime.analysis.
survival_plot:main"}``), each a ``main(argv)`` that reads runs or files and writes figures or
tables: the registry finds them, so the core names no task. ``jt study`` lists every task's tools,
``jt study TASK`` one task's, ``jt study TASK TOOL --help`` a tool's arguments.

A tool builds its parser with ``parser(...)``: a mistake in its arguments is one ``JtError`` line
(``jt: <tool>: <what>``, exit 2), as everywhere in jt, instead of argparse's usage block.
"""

from __future__ import annotations

import argparse
import importlib
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
