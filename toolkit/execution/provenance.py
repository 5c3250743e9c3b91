"""What a run records about where it came from: jt version, git commit, command line."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path


def jt_version() -> str:
    """Installed jt version (``0+unknown`` when running from an uninstalled tree)."""
    from importlib import metadata

    try:
        return metadata.version("jt")
    except metadata.PackageNotFoundError:
        return "0+unknown"


def git_commit() -> str:
    """Commit of the jt source tree (``+dirty`` if it has uncommitted changes), or ``unknown``."""
    src = Path(__file__).resolve().parents[2]
    try:
        sha = subprocess.run(
            ["git", "-C", str(src), "rev-parse", "--verify", "-q", "HEAD"], capture_output=True, text=True, timeout=5
        ).stdout.strip()
        if not sha:
            return "unknown"
        dirty = subprocess.run(
            ["git", "-C", str(src), "status", "--porcelain", "--untracked-files=no"],
            capture_output=True, text=True, timeout=5,
        ).stdout.strip()
        return sha + ("+dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def command_line() -> str:
    """The command as typed (``jt run task=...``)."""
    return " ".join(["jt", *sys.argv[1:]])
