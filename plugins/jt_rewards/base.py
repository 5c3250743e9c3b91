"""Shared plumbing of the reward terms: config parsing and record look-ups."""

from __future__ import annotations

import math
from typing import Any

from toolkit.interfaces.reward import RewardTerm
from toolkit.config import config_of


class RecordTerm(RewardTerm):
    """Base of jt's reward terms: parses ``cfg`` into ``self.params`` and reads record keys.

    Args:
        cfg: the term's parameters (``None``, a dict, a ``Config`` or an OmegaConf node).
    """

    def __init__(self, cfg: Any = None) -> None:
        super().__init__(cfg)
        self.params = config_of(type(self).Config, cfg, f"reward term {self.term_name}")

    @property
    def term_name(self) -> str:
        """The registry name if loaded through ``toolkit.plugins``, else the class name."""
        return type(self).name or type(self).__name__

    def get(self, record: dict[str, Any], key: str) -> Any:
        """``record[key]``, or a ``KeyError`` naming this term and the key it needs."""
        try:
            value = record[key]
        except KeyError:
            raise KeyError(f"reward term {self.term_name} needs record key '{key}' "
                           f"(record has: {', '.join(sorted(map(str, record))) or 'nothing'})") from None
        if value is None:
            raise KeyError(f"reward term {self.term_name}: record key '{key}' is None")
        return value

    def scalar(self, record: dict[str, Any], key: str) -> float:
        """``record[key]`` as a finite float (``ValueError`` otherwise)."""
        value = float(self.get(record, key))
        if not math.isfinite(value):
            raise ValueError(f"reward term {self.term_name}: record key '{key}' is {value}")
        return value
