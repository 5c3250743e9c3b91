"""Silence C-level output around noisy native calls (PyBullet's URDF importer warnings)."""

from __future__ import annotations

import contextlib
import os
import sys
from typing import Iterator


@contextlib.contextmanager
def native_stderr_silenced() -> Iterator[None]:
    """Redirect file descriptors 1 and 2 to /dev/null for the duration (Python's streams flushed).

    PyBullet prints one ``b3Warning ... no axis element for Joint`` per spherical joint of the
    DeepMimic URDFs on every load, from C (on stdout), past Python's streams. Set
    ``JT_VERBOSE_NATIVE=1`` to see them.
    """
    if os.environ.get("JT_VERBOSE_NATIVE"):
        yield
        return
    try:
        sys.stdout.flush()
        sys.stderr.flush()
        saved = (os.dup(1), os.dup(2))
    except (OSError, ValueError):  # no real descriptors (captured in-process): nothing to silence
        yield
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, devnull):
            os.close(fd)


def preload_quietly() -> None:
    """Import every installed simulator's noisy native modules (``Simulator.native_modules``, e.g.
    PyBullet's ``pybullet build time: ...`` banner on stdout) with C-level output silenced, so that
    no banner reaches a terminal: the CLI's working commands and every worker process of the local
    executor call this first; later imports find the modules loaded. A broken simulator plugin is
    left to the command that uses it. ``JT_VERBOSE_NATIVE=1`` shows the banners."""
    import importlib
    import importlib.util

    from toolkit import plugins
    from toolkit.errors import JtError

    for sim in plugins.names("sim"):
        try:
            names = tuple(getattr(plugins.load("sim", sim), "native_modules", ()))
        except JtError:
            continue
        for name in names:
            if name in sys.modules or importlib.util.find_spec(name) is None:
                continue
            with native_stderr_silenced():
                importlib.import_module(name)
