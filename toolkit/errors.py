"""Errors that are the user's to fix: the CLI prints them as one line and exits with status 2."""

from __future__ import annotations

from typing import Any, Callable


class JtError(Exception):
    """A user mistake (bad override, unknown plugin, missing file): one clear line, no traceback."""


class UnknownPlugin(JtError):
    """A config names a plugin that no installed package provides."""

    def __init__(self, kind: str, name: str, choices: list[str]) -> None:
        self.kind, self.name, self.choices = kind, name, choices
        listed = ", ".join(choices) if choices else "(none installed)"
        super().__init__(f"unknown {kind} '{name}'; choose one of: {listed}")


class BrokenPlugin(JtError):
    """A plugin is registered but its module fails to import."""

    def __init__(self, kind: str, name: str, reason: str) -> None:
        self.kind, self.name, self.reason = kind, name, reason
        super().__init__(f"{kind} plugin '{name}' is installed but broken: {reason}")


def one_line_errors(main: "Callable[..., Any]") -> "Callable[..., Any]":
    """Decorate a tool's ``main`` (``jt study``, ``python -m``): a ``JtError`` is printed as one line on stderr
    (``jt: ...``) and the tool exits with status 2, as the ``jt`` command does."""
    import functools

    @functools.wraps(main)
    def wrapped(*args: Any, **kwargs: Any) -> Any:
        import sys

        try:
            return main(*args, **kwargs)
        except JtError as e:
            print(f"jt: {e}", file=sys.stderr)
            raise SystemExit(2) from None

    return wrapped
