"""Shared plumbing of the reward terms: config parsing and record look-ups."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from toolkit.errors import JtError
from toolkit.interfaces.reward import RewardTerm


def config_of(config_cls: type, cfg: Any, what: str = "reward") -> Any:
    """A typed ``Config`` instance from ``None``, an instance, a dataclass, a dict or a group node.

    Values are type-checked and converted through OmegaConf's structured configs (``"0.7"`` is
    rejected for a float, ``1`` becomes ``1.0``). A ``name`` key is dropped unless ``config_cls``
    declares it.

    Raises:
        JtError: an unknown key (the message lists the valid ones) or a value of the wrong type.
    """
    if cfg is None:
        return config_cls()
    if isinstance(cfg, config_cls):
        return cfg
    from omegaconf import OmegaConf

    if dataclasses.is_dataclass(cfg):
        params = dataclasses.asdict(cfg)
    elif isinstance(cfg, dict):
        params = dict(cfg)
    else:
        params = OmegaConf.to_container(cfg, resolve=True)
    known = {f.name for f in dataclasses.fields(config_cls)}
    if "name" not in known:
        params.pop("name", None)
    unknown = sorted(set(params) - known)
    if unknown:
        valid = ", ".join(sorted(known - {"name"}))
        raise JtError(f"{what}: unknown key(s) {', '.join(unknown)} (valid keys: {valid})")
    try:
        node = OmegaConf.merge(OmegaConf.structured(config_cls), params)
        return OmegaConf.to_object(node)
    except Exception as e:  # noqa: BLE001 - OmegaConf raises several validation types
        msg = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        key = getattr(e, "full_key", None)
        raise JtError(f"{what}: {key + ': ' if key else ''}{msg}") from e


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
