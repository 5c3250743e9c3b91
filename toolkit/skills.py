"""Trained skills that ship with jt (``jt play NAME``): find them, read and check their manifests,
and make one from a finished run.

A task declares the package holding its skills (``Task.skills``: ``"jt_tasks.jumping.skills"``);
the registry finds them, so the core names no task. A skill is one folder of that package::

    <package>/<name>/
        manifest.yaml   what the skill is and how its environment is rebuilt (below)
        policy.h5       a slim PPO checkpoint (``toolkit.rl.checkpoint.slim``: ~3 MB, not ~16)
        prior.h5        any file its overrides name: an override whose value is the name of a file
                        in the folder (``action.prior=prior.h5``) points at that file

``manifest.yaml``:

* ``name``, ``task``, ``description`` (one line);
* ``overrides``: the training command's overrides, which compose its environment (``jt run``'s
  syntax; ``store=`` left out, files of the folder by name);
* ``point``: the searched point its environment is built at (``{}``: the task's defaults);
* ``env_attrs``: environment attributes set before the replay (a curriculum's bar, control rate);
* ``seed``: the environment's seed;
* ``measure``: what the replay reaches (the task's ``PolicyTask.play_summary``), documented;
* ``provenance``: ``command``, ``run_id`` (in the store that trained it), ``commit``, ``samples``,
  ``train_wall_s``, ``date``, and ``metrics``: the run's own measure (its task's key metrics: the spacetime
  walk's survival from every start phase).

``toolkit.ship.ship(ref, name)`` (``jt play --ship RUN NAME``) writes such a folder from a run: the
slim policy, the prior, the manifest from the run's command, tags and metrics, and its measure from
one replay.
A skill whose policy no longer fits the environment its overrides build (another observation or
action size) is refused in one line that names the command retraining it (``check_fits``).

``jt run task.evaluate=NAME`` measures a shipped skill as a run (``toolkit.policy.trained``): the
skill's overrides compose under the command line's (``evaluate_overrides``: the command line wins,
a group it chooses otherwise drops the skill's keys of that group; ``toolkit.config.compose_skill``
composes a skill's own), and the run's environment must be the skill's
(``toolkit.policy.trained.check_skill_settings``).
"""

from __future__ import annotations

import dataclasses
import importlib.util
import re
import shlex
from pathlib import Path
from typing import Any, Optional

from toolkit.errors import JtError

MANIFEST = "manifest.yaml"
POLICY = "policy.h5"
_REQUIRED = ("name", "task", "description", "overrides")
NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


@dataclasses.dataclass
class Skill:
    """A shipped skill: its folder and its manifest's fields (see the module docstring)."""

    name: str
    task: str
    description: str
    folder: Path
    overrides: list[str]
    point: dict[str, float] = dataclasses.field(default_factory=dict)
    env_attrs: dict[str, Any] = dataclasses.field(default_factory=dict)
    seed: int = 0
    measure: dict[str, Any] = dataclasses.field(default_factory=dict)
    provenance: dict[str, Any] = dataclasses.field(default_factory=dict)

    @property
    def policy(self) -> Path:
        """The skill's slim checkpoint."""
        return self.folder / POLICY

    @property
    def command(self) -> str:
        """The command that trained it (``provenance.command``), else one built from its overrides."""
        return str(self.provenance.get("command") or "jt run " + " ".join(map(shlex.quote, self.overrides)))

    def resolved_overrides(self) -> list[str]:
        """The overrides with every value naming a file of the folder made that file's path, and
        ``task=`` first when the manifest left it out."""
        out = []
        for ov in self.overrides:
            key, eq, value = ov.partition("=")
            if eq and value and "/" not in value and (self.folder / value).is_file():
                ov = f"{key}={(self.folder / value).resolve()}"
            out.append(ov)
        if not any(o.startswith("task=") for o in out):
            out.insert(0, f"task={self.task}")
        return out


# ---------------------------------------------------------------------------- task.evaluate=NAME
_RUN_ID = re.compile(r"^[0-9a-f]{32}$")


def is_skill_ref(ref: str) -> bool:
    """Whether ``ref`` names a shipped skill rather than a run (an MLflow run id) or a path."""
    from toolkit.store.resolve import is_path

    ref = str(ref or "").strip()
    return bool(ref) and not _RUN_ID.match(ref) and not is_path(ref)


def _key(override: str) -> str:
    return override.split("=", 1)[0].lstrip("+~").strip()


def evaluate_overrides(overrides: Any) -> list[str]:
    """``overrides`` with a shipped skill's own overrides under them when ``task.evaluate=NAME``
    names one (``jt run task.evaluate=fosbury`` composes the Fosbury skill's environment): the
    command line's win, and a group it chooses otherwise (``search=bds``) drops the skill's keys
    of that group (``search.budget=1``). As given otherwise (an unknown name is the line of
    ``toolkit.policy.trained.trained_skill``, which names the shipped skills)."""
    overrides = list(overrides)
    refs = [o.split("=", 1)[1].strip().strip("'\"") for o in overrides if _key(o) == "task.evaluate" and "=" in o]
    if not refs or not is_skill_ref(refs[-1]):
        return overrides
    skill = next((s for s in scan()[0] if s.name == refs[-1]), None)
    if skill is None:
        return overrides
    given = {_key(o): o for o in overrides}
    theirs = {_key(o): o for o in skill.resolved_overrides()}
    other = tuple(f"{k}." for k, o in given.items() if "." not in k and theirs.get(k, o) != o)  # another choice
    own = [o for k, o in theirs.items() if k not in given and not k.startswith(other)]
    return own + overrides


def replaced_overrides(overrides: Any) -> str:
    """Which of ``overrides`` replace the settings of the skill that their ``task.evaluate=NAME``
    names (``experiment=smoke replaces the skill's experiment=laptop``), for a message; ``""``
    when none does."""
    overrides = list(overrides)
    refs = [o.split("=", 1)[1].strip().strip("'\"") for o in overrides if _key(o) == "task.evaluate" and "=" in o]
    skill = next((s for s in scan()[0] if refs and s.name == refs[-1]), None)
    if skill is None:
        return ""
    theirs = {_key(o): o for o in skill.resolved_overrides()}
    kept = set(evaluate_overrides(overrides)[: -len(overrides)])  # the skill's that stay
    out = []
    for o in overrides:
        k = _key(o)
        dropped = [t for kk, t in theirs.items() if (kk == k or kk.startswith(f"{k}.")) and t not in kept and t != o]
        if dropped and k not in ("task.evaluate", "store"):
            out.append(f"{o} replaces the skill's {' '.join(dropped)}")
    return "; ".join(out)


# ---------------------------------------------------------------------------- discovery
def packages() -> dict[str, list[str]]:
    """``{skills package: [tasks declaring it]}`` of every installed task (a broken one left out)."""
    from toolkit import plugins

    out: dict[str, list[str]] = {}
    for name in plugins.names("task"):
        try:
            pkg = str(getattr(plugins.load("task", name), "skills", "") or "")
        except JtError:
            continue
        if pkg:
            out.setdefault(pkg, []).append(name)
    return out


def package_folder(package: str) -> Optional[Path]:
    """The folder of a skills package (None when it is not importable)."""
    try:
        spec = importlib.util.find_spec(package)
    except (ImportError, ValueError):
        return None
    locations = list(getattr(spec, "submodule_search_locations", None) or []) if spec is not None else []
    return Path(locations[0]) if locations else None


def scan() -> tuple[list[Skill], list[str]]:
    """Every shipped skill, sorted by name, and one line per folder whose manifest is broken."""
    skills, broken = [], []
    for pkg in sorted(packages()):
        folder = package_folder(pkg)
        for d in sorted(folder.iterdir()) if folder is not None else []:
            if (d / MANIFEST).is_file():
                try:
                    skills.append(load_manifest(d))
                except JtError as e:
                    broken.append(str(e))
    return sorted(skills, key=lambda s: s.name), broken


def names() -> list[str]:
    """The shipped skills' names."""
    return [s.name for s in scan()[0]]


def find(name: str) -> Skill:
    """The shipped skill ``name``; one ``JtError`` line naming the shipped ones."""
    skills = scan()[0]
    for s in skills:
        if s.name == name:
            return s
    shipped = ", ".join(s.name for s in skills) or "(none)"
    raise JtError(f"unknown skill '{name}'; shipped skills: {shipped} (jt play lists them; a run id, a run's "
                  "folder or its ppo.h5 replays a trained run)")


def listing() -> list[str]:
    """Lines listing the shipped skills: name, task, documented measure, description."""
    skills, broken = scan()
    rows = [(s.name, f"task={s.task}", measure_text(s.measure), s.description) for s in skills]
    widths = [max((len(r[i]) for r in rows), default=0) for i in range(3)]
    lines = [f"{a:<{widths[0]}}  {b:<{widths[1]}}  {c:<{widths[2]}}  {d}".rstrip() for a, b, c, d in rows]
    return lines + [f"BROKEN: {b}" for b in broken]


def measure_text(measure: dict[str, Any]) -> str:
    """``key=value`` pairs of a measure (floats to 4 significant digits)."""
    def show(v: Any) -> str:
        return str(round(v, 4)) if isinstance(v, float) else str(v).lower() if isinstance(v, bool) else str(v)

    return " ".join(f"{k}={show(v)}" for k, v in measure.items())


def differences(got: dict[str, Any], documented: dict[str, Any], tol: float = 0.05) -> list[str]:
    """The documented measure's keys the replay's ``got`` differs in (numbers: by more than ``tol``
    absolute or 2 %), as ``key=got (documented X)``."""
    import math

    out = []
    for k, want in documented.items():
        have = got.get(k)
        numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (have, want))
        same = (math.isclose(float(have), float(want), rel_tol=0.02, abs_tol=tol) if numbers else have == want)
        if not same:
            out.append(f"{k}={have} (documented {want})")
    return out


# ---------------------------------------------------------------------------- manifests
def load_manifest(folder: Any) -> Skill:
    """The skill in ``folder`` (its ``manifest.yaml``, checked: one ``JtError`` line per problem)."""
    import yaml

    folder = Path(folder).expanduser()
    path = folder / MANIFEST
    where = f"skill {folder}"
    if not path.is_file():
        raise JtError(f"{where}: no {MANIFEST} there")
    try:
        data = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError) as e:
        raise JtError(f"{where}: {MANIFEST} is not readable YAML ({' '.join(str(e).split())[:160]})") from None
    if not isinstance(data, dict):
        raise JtError(f"{where}: {MANIFEST} is not a mapping")
    missing = [k for k in _REQUIRED if k not in data]
    if missing:
        raise JtError(f"{where}: {MANIFEST} lacks {', '.join(missing)}")
    if not isinstance(data["overrides"], list) or not all(isinstance(o, str) for o in data["overrides"]):
        raise JtError(f"{where}: {MANIFEST}: overrides must be a list of KEY=VALUE strings")
    for key in ("point", "env_attrs", "measure", "provenance"):
        if not isinstance(data.get(key) or {}, dict):
            raise JtError(f"{where}: {MANIFEST}: {key} must be a mapping")
    if not NAME.match(str(data["name"])):
        raise JtError(f"{where}: {MANIFEST}: name {data['name']!r} must be letters, digits, '_', '-', '.'")
    if not (folder / POLICY).is_file():
        raise JtError(f"{where}: no {POLICY} beside its {MANIFEST}")
    try:
        seed = int(data.get("seed", 0) or 0)
        point = {str(k): float(v) for k, v in (data.get("point") or {}).items()}
    except (TypeError, ValueError) as e:
        raise JtError(f"{where}: {MANIFEST}: seed must be an integer and point numbers ({e})") from None
    return Skill(name=str(data["name"]), task=str(data["task"]), description=str(data["description"]).strip(),
                 folder=folder.resolve(), overrides=list(data["overrides"]), point=point,
                 env_attrs=dict(data.get("env_attrs") or {}), seed=seed, measure=dict(data.get("measure") or {}),
                 provenance=dict(data.get("provenance") or {}))


def write_manifest(skill: Skill) -> Path:
    """Write ``skill``'s ``manifest.yaml`` in its folder."""
    import yaml

    data = _yaml_plain({"name": skill.name, "task": skill.task, "description": skill.description,
                        "overrides": list(skill.overrides), "point": dict(skill.point),
                        "env_attrs": dict(skill.env_attrs), "seed": int(skill.seed), "measure": dict(skill.measure),
                        "provenance": dict(skill.provenance)})
    head = (f"# A trained skill shipped with jt: `jt play {skill.name}` replays it (toolkit/skills.py says what\n"
            f"# each field is; `jt play --ship RUN {skill.name}` rewrites this folder from a run).\n")
    path = skill.folder / MANIFEST
    path.write_text(head + yaml.safe_dump(data, sort_keys=False, width=120, allow_unicode=True))
    return path


def _yaml_plain(value: Any) -> Any:
    """``value`` with numpy arrays and scalars made lists, floats, ints and bools (YAML writes those:
    a spacetime run's start-phase weights are an array)."""
    if isinstance(value, dict):
        return {str(k): _yaml_plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_yaml_plain(v) for v in value]
    tolist = getattr(value, "tolist", None)
    if callable(tolist):  # numpy arrays and scalars
        return _yaml_plain(tolist())
    return value


def check_fits(policy: Path, env: Any, skill: Optional[Skill] = None, what: str = "") -> None:
    """The policy takes ``env``'s observation and gives its action (sizes from the checkpoint);
    else one ``JtError`` line: for a skill, that it must be retrained and the command that does it."""
    from toolkit.rl.checkpoint import load_attrs

    attrs = load_attrs(policy)
    want = (int(attrs["obs_dim"]), int(attrs["act_dim"]))
    have = (int(env.observation_space.shape[0]), int(env.action_space.shape[0]))
    if want == have:
        return
    sizes = (f"its policy takes {want[0]} observations and gives {want[1]} actions, the environment "
             f"built here observes {have[0]} and acts with {have[1]}")
    if skill is not None:
        raise JtError(f"skill '{skill.name}' must be retrained for this jt ({sizes}); retrain it with: "
                      f"{skill.command}, then ship the run: jt play --ship RUN_ID {skill.name}")
    raise JtError(f"{what or policy}: {sizes} (a run of another task, or of other settings)")
