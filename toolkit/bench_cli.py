"""``jt bench ...`` subcommands (registered on import; heavy imports inside each command)."""

from __future__ import annotations
