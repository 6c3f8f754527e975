"""The skills, in one place: start here to read or extend UniCross.

Every structural fact about a skill lives in its :class:`Skill` entry below: its ManiSkill env
id, its modes (axes or directions) and their hand-frame vectors, the object categories it works
on, its default training set, the paper's PPO horizon, its evaluation protocol (steps, table
column), the target rules of the paper's Table 1, its success test (``unicross/success.py``) and
which motion speed caps its ``r_motion``.
Everything else iterates :data:`SKILLS` (modes, the mode one-hot and the goal size follow from
it); tunable numbers (episode lengths, speeds, success thresholds, reward weights) live in
``configs/*.yaml``.

Adding a skill or an axis here changes :data:`NUM_MODES` and so the goal size of the
observation: checkpoints store their goal size and refuse to load into a different one.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Dict, Optional, Tuple

BOTH_CATEGORIES = ("wrappable", "elongated")


@dataclass(frozen=True)
class Skill:
    """One skill of the formulation (see the module docstring)."""

    name: str
    env_id: str                       # the ManiSkill task id (tasks/skills.py registers it)
    short_name: str                   # long-horizon table label (paper: Gr., Re., Rot., Trans.)
    targets: Dict[str, str]           # relational slot -> target rule (paper Table 1; see formulation._RULES)
    success: str                      # its success test (unicross/success.py)
    axes: Tuple[str, ...] = ()        # hand-frame axes of its modes ("x+", ...); () for a single axis-free mode
    axis_kwarg: Optional[str] = None  # the env constructor's argument that picks the axis
    categories: Tuple[str, ...] = BOTH_CATEGORIES  # object categories it trains and evaluates on
    train_objects: str = "train"      # its default training object set
    ppo_horizon: int = 64             # the paper's PPO horizon (steps per env per iteration)
    protocol_steps: int = 75          # control steps of its evaluation protocol (paper §4.2)
    speed: str = "v_max"              # configs/task.yaml motion key capping its r_motion (v_max, omega_max)
    success_once: bool = False        # success counts when reached at any step (accumulated motion), not at the end
    # how its episodes run (tasks/ reads these flags; none of it names a skill)
    starts_on_table: bool = False     # starts with the object on the table (else from a grasp state of the dataset)
    wrist_where_grasped: bool = False  # in-hand start with the wrist where the grasp was recorded (else in the air)
    lifts: bool = False               # a lift phase after grasp.lift_after: the wrist reference rises, and drops
                                      # (and the robustness disturbance) count only while lifting
    draws_goal_pose: bool = False     # draws a final object pose at its start (configs/task.yaml relocate_target)
    accumulates: Optional[str] = None  # motion accumulated along its axis: "rotation" or "translation"

    @property
    def modes(self) -> Tuple[str, ...]:
        """Its mode names: ``name`` alone, or ``name_axis`` per axis."""
        return tuple(f"{self.name}_{a}" for a in self.axes) if self.axes else (self.name,)

    def mode(self, axis: Optional[str] = None) -> str:
        """The mode name of ``axis``; a clear error for an axis the skill does not have."""
        if not self.axes:
            if axis is not None:
                raise ValueError(f"skill {self.name!r} takes no axis/direction (got {axis!r})")
            return self.name
        if axis not in self.axes:
            word = self.axis_kwarg or "axis"
            plural = "axes" if word == "axis" else word + "s"
            if axis is None:
                raise ValueError(f"{self.name} needs --{word} (valid {plural}: {list(self.axes)})")
            raise ValueError(f"invalid {self.name} {word} {axis!r}; valid {plural}: {list(self.axes)}")
        return f"{self.name}_{axis}"

    def env_kwargs(self, axis: Optional[str] = None) -> dict:
        """The env constructor arguments that select ``axis`` (validated)."""
        self.mode(axis)
        return {self.axis_kwarg: axis} if self.axis_kwarg else {}


_SKILL_LIST = (
    Skill("grasp", "UniCross-Grasp-v1", "Gr.",
          targets=dict(x_oh="palm", q_oh="free", x_or="fixed", q_or="fixed", x_hr="free", q_hr="free"),
          success="lifted_with_contacts", starts_on_table=True, lifts=True),
    Skill("relocate", "UniCross-Relocate-v1", "Re.",
          targets=dict(x_oh="fixed", q_oh="fixed", x_or="interpolate", q_or="interpolate",
                       x_hr="hand_from_object", q_hr="hand_from_object"),
          success="at_final_pose", wrist_where_grasped=True, draws_goal_pose=True),
    Skill("rotate", "UniCross-Rotate-v1", "Rot.",
          targets=dict(x_oh="fixed", q_oh="rotate_about_axis", x_or="fixed", q_or="object_from_hand",
                       x_hr="fixed", q_hr="fixed"), success="rotated_past_threshold",
          axes=("x+", "x-", "y+", "y-", "z+", "z-"), axis_kwarg="axis", categories=("wrappable",),
          train_objects="train-wrappable", ppo_horizon=8, protocol_steps=400, speed="omega_max",
          success_once=True, accumulates="rotation"),
    Skill("translate", "UniCross-Translate-v1", "Trans.",
          targets=dict(x_oh="translate_along_axis", q_oh="fixed", x_or="object_from_hand", q_or="fixed",
                       x_hr="fixed", q_hr="fixed"), success="translated_past_threshold",
          axes=("z+", "z-"), axis_kwarg="direction", categories=("elongated",),
          train_objects="train-elongated", ppo_horizon=8, protocol_steps=50, success_once=True,
          accumulates="translation"),
)

SKILLS: Dict[str, Skill] = {s.name: s for s in _SKILL_LIST}
SKILL_NAMES: Tuple[str, ...] = tuple(SKILLS)
MODES: Tuple[str, ...] = tuple(m for s in _SKILL_LIST for m in s.modes)
NUM_MODES = len(MODES)


def skill(name: str) -> Skill:
    """The registry entry of ``name``; a clear error listing the valid names."""
    if name not in SKILLS:
        raise ValueError(f"unknown skill {name!r}; valid skills: {list(SKILLS)}")
    return SKILLS[name]


def skill_of_mode(mode: str) -> Skill:
    """The skill a mode name belongs to."""
    return skill(mode.split("_")[0])


def axis_vector(axis: Optional[str]) -> Tuple[float, float, float]:
    """'x+' -> (1, 0, 0), 'z-' -> (0, 0, -1); None -> zeros (modes without an axis)."""
    v = [0.0, 0.0, 0.0]
    if axis is not None:
        v["xyz".index(axis[0])] = 1.0 if axis[1] == "+" else -1.0
    return tuple(v)


def axis_env_id(skill: Skill, axis: str) -> str:
    """The id with ``axis`` fixed, for clients that cannot pass env kwargs (ManiSkill's PPO baseline):
    ``UniCross-Rotate-v1`` + ``y-`` -> ``UniCross-RotateYNeg-v1`` (gymnasium ids allow no '+')."""
    name, _, version = skill.env_id.rpartition("-")
    return f"{name}{axis[0].upper()}{'Pos' if axis[1] == '+' else 'Neg'}-{version}"


def mode_axis(mode: str) -> Optional[str]:
    """The axis of a mode name (None for axis-free modes)."""
    _, _, axis = mode.partition("_")
    return axis or None


def trained_mode(skill_name: Optional[str], axis: Optional[str] = None) -> Optional[str]:
    """The mode a checkpoint was trained for from its ``skill``/``axis`` fields; a skill name outside
    the registry (e.g. a student's ``multi``) is returned as it is."""
    return skill(skill_name).mode(axis) if skill_name in SKILLS else skill_name
