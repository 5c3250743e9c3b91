"""Simulators (``jt.simulators``): a character in a scene, stepped at the simulation rate.

An environment never names its simulator (MimicKit's engine interface): everything it needs goes
through this interface — state I/O, the substep loop with the episode's termination rules checked
inside it, batched link/CoM reads, contacts, static scene geometry (boxes), ray
queries and rendering. ``Watch`` declares what ends a control step early and what to record at
each checked substep, so Python runs once per control step, not once per 600 Hz substep.
"""

from __future__ import annotations

import abc
import dataclasses
from typing import TYPE_CHECKING, Any, Callable, ClassVar, Optional, Sequence

from toolkit.interfaces.plugin import Plugin

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np

BASE = -1  #: link index of the character's base (root) in contacts and link queries


@dataclasses.dataclass(frozen=True)
class ContactRule:
    """Ends the control step when the character touches a scene body.

    Attributes:
        body: the scene body (``Simulator.ground`` or a handle ``add_box`` returned).
        outcome: ``"fail"`` or ``"success"``: what the episode's end is.
        reason: the reason reported (``"touched the bar"``).
        links: only these character links count (``BASE`` = -1 for the root); None: every link.
        except_links: these links never count (e.g. the feet on the ground).
        clear_of: a scene body that every part of the character must be farther than ``margin``
            from for the rule to fire (a landing counts only clear of the bar), or None.
        margin: metres, with ``clear_of``.
    """

    body: int
    outcome: str = "fail"
    reason: str = ""
    links: Optional[tuple[int, ...]] = None
    except_links: tuple[int, ...] = ()
    clear_of: Optional[int] = None
    margin: float = 0.0


@dataclasses.dataclass(frozen=True)
class Watch:
    """What a control step checks and records at each checked substep.

    Attributes:
        rules: contact rules, in order; the first that fires ends the step (and the episode).
        touches: scene bodies whose touching links are reported the first time (per control step)
            any link touches them (``StepResult.touched``), e.g. the landing mat.
        record: quantities logged at every checked substep (``StepResult.samples``): ``"time"``
            ``(k,)``, ``"com"`` ``(k, 3)``, ``"root"`` ``(k, 7)`` (position, quaternion x, y, z, w).
        time_limit: simulation time (s since ``reset``) at which the step ends with
            ``time_limit_outcome``; None: no limit.
        time_limit_outcome: ``"fail"`` or ``"truncate"``.
        time_limit_reason: the reason reported.
        check_every: substeps between checks (the last substep of a step is always checked).
    """

    rules: tuple[ContactRule, ...] = ()
    touches: tuple[int, ...] = ()
    record: tuple[str, ...] = ()
    time_limit: Optional[float] = None
    time_limit_outcome: str = "fail"
    time_limit_reason: str = "time limit"
    check_every: int = 1


class Simulator(Plugin, abc.ABC):
    """A physics world holding one controlled character and its scene.

    Control happens at ``control_hz``; each control step runs ``sim_hz / control_hz`` simulation
    substeps, each computing SPD torques with the configured backend. A NaN or exploding state
    ends the episode as a failure with a reason; it never raises.

    Attributes:
        n_substeps: substeps per control step (``sim_hz / control_hz``).
        time: simulation time since the last ``reset`` (s).
        ground: scene handle of the ground, or -1 without one.
        n_links: the character's links besides the base.
        masses: link masses ``(n_links + 1,)``, base first (kg).
        model: the character's ``toolkit.dynamics.Model`` (``n_q``, ``n_v``, ``depth`` ...).
        steps_itself: True when the configured SPD backend acts inside the engine's own step
            (``SPDBackend.steps_itself``): the step records carry no torques (``tau`` is NaN) and
            tasks that time or read the torques skip that. False by default.
        planar_world: optional classmethod ``planar_world(urdf_path, sim_hz, friction, ...)``
            opening a planar (2-D) world for ``task=standing_jump``; None (default): this
            simulator has none, and that task says so.
        forward_kinematics: optional classmethod ``forward_kinematics(skeleton, root_pos,
            root_rot, joints) -> toolkit.motion.kinematics.Kinematics``: link poses of mocap
            poses ``(n, ...)`` of a ``toolkit.motion.Skeleton``'s character, no world needed.
            ``toolkit.motion`` (features, datasets) and the tasks' references use the first
            registered simulator that has it (``toolkit.motion.kinematics.engine``). None: none.
        kinematic_body: optional classmethod ``kinematic_body(skeleton)``: a kinematic copy of
            the character, never stepped (``masses``, ``pose(q)``, ``lowest_point(q, link)``,
            ``links_and_com(q)``, ``close()``; see ``toolkit.motion.kinematics.kinematic_body``).
        render_poses: optional classmethod ``render_poses(skeleton, dofs) -> list`` of RGB frames
            ``(height, width, 3)`` uint8 of still poses in the dof layout ``(n, n_dof)`` (the
            priors' filmstrips, ``toolkit.priors.render``).
        native_modules: names of native modules the simulator imports that print from C when
            first imported (a build banner): ``toolkit.quiet.preload_quietly`` imports them with
            C-level output silenced before a command or a worker starts. Empty by default.

    Required: ``sim_hz``, ``control_hz``, ``reset``, ``step``, ``state`` and the queries and scene methods below that a task
    uses (the defaults raise ``NotImplementedError``); ``close`` releases the engine.

    Args:
        cfg: the whole run config (``cfg.sim``, ``cfg.character``, ``cfg.spd``).
    """

    n_substeps: int = 1
    time: float = 0.0
    ground: int = -1
    n_links: int = 0
    steps_itself: bool = False
    planar_world: ClassVar[Optional[Callable[..., Any]]] = None
    forward_kinematics: ClassVar[Optional[Callable[..., Any]]] = None
    kinematic_body: ClassVar[Optional[Callable[..., Any]]] = None
    render_poses: ClassVar[Optional[Callable[..., Any]]] = None
    native_modules: ClassVar[tuple[str, ...]] = ()
    group_schemas: ClassVar[dict[str, type]] = {}

    def __init__(self, cfg: Any) -> None:
        self.cfg = cfg

    # ------------------------------------------------------------------ rates
    @property
    @abc.abstractmethod
    def sim_hz(self) -> float:
        """Substep rate (Hz): the rate SPD and contacts run at (600 in the papers)."""

    @property
    @abc.abstractmethod
    def control_hz(self) -> float:
        """Default control rate (Hz); ``step`` runs ``sim_hz / control_hz`` substeps unless told
        otherwise (a task with its own rate passes ``n_substeps``)."""

    @property
    def friction(self) -> float:
        """Lateral friction of the ground (what scene geometry a task adds should use to match it)."""
        raise NotImplementedError

    # ------------------------------------------------------------------ state and stepping
    @abc.abstractmethod
    def reset(self, q: "np.ndarray", qd: "np.ndarray") -> None:
        """Put the character in state ``(q (n_q,), qd (n_dof,))``; time = 0."""

    @abc.abstractmethod
    def step(self, q_target: "np.ndarray", qd_target: "Optional[np.ndarray]" = None,
             n_substeps: Optional[int] = None, watch: Optional[Watch] = None) -> dict[str, Any]:
        """One control step towards ``q_target``: ``n_substeps`` (default ``self.n_substeps``)
        SPD-controlled substeps, ``watch`` checked inside the loop.

        Returns:
            The step record: ``time``, ``q``, ``qd``, ``tau``, ``failed``, ``reason`` (a NaN or
            exploded state), ``substeps`` (simulated), ``outcome`` (``""`` while running, else a
            rule's / the time limit's, ``"fail"`` for a failed simulation), ``touched``
            ``{body: links}``, ``samples`` ``{name: (k, ...)}``, and, when configured, ``contacts``
            / ``n_contacts``.
        """

    @abc.abstractmethod
    def state(self) -> tuple["np.ndarray", "np.ndarray"]:
        """Current ``(q, qd)`` (copies)."""

    # ------------------------------------------------------------------ queries
    @property
    def masses(self) -> "np.ndarray":
        """Link masses ``(n_links + 1,)``, base first (kg)."""
        raise NotImplementedError

    def link_states(self) -> tuple["np.ndarray", "np.ndarray"]:
        """Centre-of-mass positions ``(n_links + 1, 3)`` and orientations ``(n_links + 1, 4)`` of
        every link, base first, world frame, in one batched read."""
        raise NotImplementedError

    def link_velocities(self) -> tuple["np.ndarray", "np.ndarray"]:
        """World linear and angular velocities ``(n_links + 1, 3)`` of every link's centre of mass,
        base first, now (optional: an observation that asks for them, e.g. ``task=spacetime
        task.velocities=links``, needs it)."""
        raise NotImplementedError

    def link_index(self, name: str) -> int:
        """The index of a character link by name, for ``link_pose``, ``aabb`` and contacts.

        Args:
            name: a link name of the character's model file, else a joint name (its child link);
                ``"base"`` / ``"root"`` name the base.

        Returns:
            The link index; ``BASE`` (-1) for the base.

        Raises:
            toolkit.errors.JtError: the character has no such link or joint (also a
                ``KeyError``); the message lists the links.
        """
        raise NotImplementedError

    def link_pose(self, link: int) -> tuple["np.ndarray", "np.ndarray"]:
        """World pose of a link's own frame (its joint origin, not its centre of mass), by forward
        kinematics of the current state (after ``reset`` too, before any step).

        Args:
            link: a link index (``link_index``); ``BASE`` for the base frame.

        Returns:
            ``(position (3,), orientation (4,))``, the orientation a quaternion x, y, z, w.
        """
        raise NotImplementedError

    def link_poses(self, links: "Sequence[int]") -> tuple["np.ndarray", "np.ndarray"]:
        """``link_pose`` of several links at once: positions ``(n, 3)`` and orientations ``(n, 4)``
        (a simulator may answer them with one query; this default calls ``link_pose`` for each)."""
        import numpy as np

        poses = [self.link_pose(int(k)) for k in links]
        return (np.array([p for p, _ in poses]).reshape(-1, 3), np.array([o for _, o in poses]).reshape(-1, 4))

    def com(self) -> "np.ndarray":
        """The character's centre of mass ``(3,)``."""
        pos, _ = self.link_states()
        m = self.masses
        return m @ pos / m.sum()

    def aabb(self, link: int) -> tuple["np.ndarray", "np.ndarray"]:
        """World axis-aligned bounding box ``(low (3,), high (3,))`` of a link (``BASE``: the base)."""
        raise NotImplementedError

    def contacts(self, body: Optional[int] = None) -> list[tuple[int, int]]:
        """``(scene body, character link)`` of every contact point now (of ``body`` only if given)."""
        raise NotImplementedError

    def near(self, body: int, margin: float) -> bool:
        """True when any part of the character is within ``margin`` metres of scene ``body``."""
        raise NotImplementedError

    def ray(self, starts: "np.ndarray", ends: "np.ndarray") -> "np.ndarray":
        """Hit points ``(n, 3)`` of rays ``starts -> ends`` ``(n, 3)`` against the scene (not the
        character); NaN rows where a ray hits nothing."""
        raise NotImplementedError

    # ------------------------------------------------------------------ scene
    def add_box(self, half_extents: Sequence[float], position: Sequence[float],
                orientation: Sequence[float] = (0.0, 0.0, 0.0, 1.0),
                rgba: Sequence[float] = (0.6, 0.6, 0.6, 1.0), friction: float = 0.9) -> int:
        """A static box (half extents in its own frame, orientation x, y, z, w); its handle."""
        raise NotImplementedError

    def add_boxes(self, half_extents: "np.ndarray", positions: "np.ndarray", orientations: "np.ndarray",
                  rgba: Any = (0.6, 0.6, 0.6, 1.0), friction: float = 0.9) -> tuple[int, ...]:
        """Static boxes: half extents ``(n, 3)``, centres ``(n, 3)`` and orientations ``(n, 4)``
        (x, y, z, w), world frame, colours ``rgba`` ``(4,)`` or ``(n, 4)``, as few scene bodies as
        the simulator allows; their handles (what ``contacts`` names them by)."""
        raise NotImplementedError

    def remove(self, body: int) -> None:
        """Remove a scene body added by ``add_box`` / ``add_boxes``."""
        raise NotImplementedError

    # ------------------------------------------------------------------ output
    def render(self, width: int = 320, height: int = 240, camera: Any = None,
               target: Optional[Sequence[float]] = None, mask: bool = False) -> Any:
        """RGB frame ``(height, width, 3)`` uint8, headless, looking at ``target`` (default: the
        root) with ``camera`` (a ``toolkit.render.Camera``; default: the character's view); with
        ``mask``, ``(frame, character)``: also where the character is, ``(height, width)`` bool
        (a picture's check that it shows the character)."""
        raise NotImplementedError

    def close(self) -> None:
        """Release the physics world."""
