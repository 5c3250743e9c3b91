"""The base every plugin class derives from."""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar


@dataclasses.dataclass
class NoConfig:
    """A plugin that takes no parameters."""


class Plugin:
    """Base of every plugin class.

    A plugin declares its parameters as a dataclass in ``Config`` (one field per YAML key, each
    with a docstring-style comment); ``toolkit.config`` validates the plugin's config group against
    it, so an unknown key or a wrong type is one clear error before anything runs. The first line
    of the class docstring is the summary ``jt plugins`` prints.

    Attributes:
        Config: dataclass of the plugin's parameters.
        name: the registry name, filled in by the registry when the class is loaded.
        group_schemas: other config groups this plugin reads, with the dataclass that types each
            (the ``bullet`` simulator types ``character``); checked at composition like ``Config``.
    """

    Config: ClassVar[type] = NoConfig
    name: ClassVar[str] = ""
    group_schemas: ClassVar[dict[str, type]] = {}

    @classmethod
    def check_run(cls, cfg: Any) -> None:
        """Checks across the groups of a composed run config that only this plugin can make
        (a task that needs a character, an action space that needs a prior): raise one
        ``JtError`` line. Runs at composition, before a run opens; the default checks nothing."""

    @classmethod
    def summary(cls) -> str:
        """First line of the class docstring."""
        doc = (cls.__doc__ or "").strip()
        return doc.splitlines()[0].strip() if doc else ""

    @staticmethod
    def params_of(cfg: Any) -> dict:
        """Plain dict of a group node without the bookkeeping key ``name``."""
        from omegaconf import OmegaConf

        if cfg is None:
            return {}
        d = OmegaConf.to_container(cfg, resolve=True) if not isinstance(cfg, dict) else dict(cfg)
        d.pop("name", None)
        return d


class GroupPlugin(Plugin):
    """A plugin configured by its own config group (reward terms, action spaces, curricula, SPD
    backends): ``cfg`` is that group, and ``params`` its validated ``Config`` instance.

    Attributes:
        params: ``Config`` validated from ``cfg`` (``toolkit.schema.config_of``) when the base
            ``__init__`` runs, so a plugin whose ``__init__`` calls ``super().__init__(cfg)`` has
            it (and its one-line error for a wrong key) without writing a line; an
            implementation may also assign it. The shipped contract suites read it.
    """

    cfg: Any = None
    #: how an error names the plugin (``{name}``: its registry name)
    what: ClassVar[str] = "{name}"

    def __init__(self, cfg: Any = None) -> None:
        self.cfg = cfg
        self.params  # noqa: B018 - validated now: a wrong key or type is one line at construction

    @property
    def params(self) -> Any:
        p = self.__dict__.get("_params")
        if p is None:
            from toolkit.schema import config_of

            name = type(self).name or type(self).__name__
            p = config_of(type(self).Config, self.cfg, type(self).what.format(name=name))
            self.__dict__["_params"] = p
        return p

    @params.setter
    def params(self, value: Any) -> None:
        self.__dict__["_params"] = value
