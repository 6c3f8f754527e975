"""The hand-object relational formulation (paper §3.1-3.2, DESIGN §2), in one place.

Frames
    world; root r (the hand frame's world pose at episode start, fixed for the episode);
    hand h (the current hand frame, origin at the palm point).
Relational poses (``SLOTS``)
    x_oh, q_oh  object in the hand frame      x_or, q_or  object in the root frame
    x_hr, q_hr  hand in the root frame
Targets
    each slot's target is Tracked (updated every step by a named rule), Fixed (value at the
    episode start) or Free (the current value, i.e. unconstrained). ``SKILL_TARGETS`` (from
    :mod:`unicross.registry`) is the paper's Table 1 as data; the ten modes are instantiations of the four skills.
Goal features
    g = [one-hot mode (10), d^h (3), current poses (21), target poses (21)] = 55-D.
Action
    q_act = clamp(q_ref + alpha * a, q_min, q_max), q_ref = previous command for the fingers and
    the current *target* wrist pose (x̂_h^r, Euler XYZ of q̂_h^r) for the six virtual joints.

Everything is batched over environments: a ``mode`` tensor selects per-env rules.
"""
from __future__ import annotations

import dataclasses
from typing import Dict, List, Tuple

import torch
import torch.utils._pytree

from unicross import registry as R
from unicross.geometry import (
    pose_inv, pose_mul, quat_apply, quat_from_axis_angle, quat_inv, quat_mul, quat_positive,
    quat_to_axis_angle, quat_to_euler_xyz, relative_pose, slerp_toward,
)

SKILLS = R.SKILL_NAMES
MODES: Tuple[str, ...] = R.MODES
NUM_MODES = R.NUM_MODES  # 10
SLOTS = ("x_oh", "q_oh", "x_or", "q_or", "x_hr", "q_hr")
SLOT_DIMS = {"x_oh": 3, "q_oh": 4, "x_or": 3, "q_or": 4, "x_hr": 3, "q_hr": 4}
GOAL_DIM = NUM_MODES + 3 + 2 * sum(SLOT_DIMS.values())  # 55

TRACKED, FIXED, FREE = "Tracked", "Fixed", "Free"
# Paper Table 1 (from the registry). Values are rule names: "fixed", "free" or a tracked rule (see _RULES).
SKILL_TARGETS: Dict[str, Dict[str, str]] = {s.name: s.targets for s in R.SKILLS.values()}


def target_kind(rule: str) -> str:
    return FIXED if rule == "fixed" else FREE if rule == "free" else TRACKED


def target_table() -> Dict[str, Dict[str, List[str]]]:
    """Skill -> {Tracked: [...], Fixed: [...], Free: [...]} (the paper's Table 1)."""
    return {s: {k: [slot for slot in SLOTS if target_kind(r[slot]) == k] for k in (TRACKED, FIXED, FREE)}
            for s, r in SKILL_TARGETS.items()}


def mode_skill(mode: str) -> str:
    return R.skill_of_mode(mode).name


def mode_index(skill: str, axis: str | None = None) -> int:
    """Index into MODES of a skill (with its axis for rotate / direction for translate)."""
    return MODES.index(R.skill(skill).mode(axis))


def skill_id(name: str) -> int:
    """Index of a skill in SKILLS (the values of ``MODE_SKILL_ID``)."""
    return SKILLS.index(R.skill(name).name)


def mode_flag(attr: str, value=True) -> torch.Tensor:
    """Per mode [NUM_MODES] bool: whether its skill's registry field ``attr`` equals ``value``."""
    return torch.tensor([getattr(R.skill_of_mode(m), attr) == value for m in MODES])


MODE_AXES = torch.tensor([R.axis_vector(R.mode_axis(m)) for m in MODES])
MODE_SKILL_ID = torch.tensor([SKILLS.index(mode_skill(m)) for m in MODES])


_OFFSETS = {}
_o = 0
for _s in SLOTS:
    _OFFSETS[_s] = (_o, _o + SLOT_DIMS[_s])
    _o += SLOT_DIMS[_s]


class Relational:
    """The six relational poses, stored as one [N, 21] tensor (slot order ``SLOTS``: for each of
    object-in-hand, object-in-root, hand-in-root a position then a quaternion). Slots are views,
    so whole-state operations (select, copy, observe) are single tensor ops."""

    __slots__ = ("data",)

    def __init__(self, data: torch.Tensor | None = None, **slots):
        if data is None:
            data = torch.cat([slots[s] for s in SLOTS], dim=-1)
        self.data = data

    @staticmethod
    def from_poses(x: torch.Tensor, q: torch.Tensor) -> "Relational":
        """From stacked poses x [N, 3, 3], q [N, 3, 4] in the order (o in h, o in r, h in r)."""
        return Relational(torch.cat([x, q], dim=-1).reshape(x.shape[0], 21))

    def poses(self):
        """Stacked positions [N, 3, 3] and quaternions [N, 3, 4] (o in h, o in r, h in r)."""
        v = self.data.view(-1, 3, 7)
        return v[..., :3], v[..., 3:]

    def flat(self) -> torch.Tensor:
        return self.data

    @staticmethod
    def unflat(v: torch.Tensor) -> "Relational":
        return Relational(v)

    def clone(self) -> "Relational":
        return Relational(self.data.clone())

    def assign(self, other: "Relational", idx) -> None:
        """self[idx] = other (in place, for partial resets)."""
        self.data[idx] = other.data

    def where(self, mask: torch.Tensor, other: "Relational") -> "Relational":
        return Relational(torch.where(mask[:, None], self.data, other.data))


# a pytree node (one leaf: ``data``), so that traced and compiled step math takes and returns it
torch.utils._pytree.register_pytree_node(Relational, lambda r: ([r.data], None), lambda leaves, _: Relational(leaves[0]),
                                         serialized_type_name="unicross.formulation.Relational")


def _slot_property(slot):
    a, b = _OFFSETS[slot]

    def get(self):
        return self.data[:, a:b]

    def set(self, value):
        self.data[:, a:b] = value
    return property(get, set)


for _s in SLOTS:
    setattr(Relational, _s, _slot_property(_s))


def relational_poses(root_p, root_q, hand_p, hand_q, obj_p, obj_q) -> Relational:
    """World poses -> the six relational poses (quaternions with w >= 0), in one batched call."""
    frame_p = torch.stack([hand_p, root_p, root_p], dim=1)
    frame_q = torch.stack([hand_q, root_q, root_q], dim=1)
    x, q = relative_pose(frame_p, frame_q, torch.stack([obj_p, obj_p, hand_p], dim=1),
                         torch.stack([obj_q, obj_q, hand_q], dim=1))
    return Relational.from_poses(x, q)


@dataclasses.dataclass
class MotionParams:
    dt: float               # control period (s)
    v_max: float            # translate speed (m/s)
    omega_max: float        # rotate speed (rad/s)
    relocate_v: float       # relocate interpolation speed (m/s)
    relocate_omega: float   # relocate interpolation angular speed (rad/s)


def _rule_index(slot: str) -> Tuple[List[str], torch.Tensor]:
    rules = sorted({SKILL_TARGETS[s][slot] for s in SKILLS})
    per_skill = torch.tensor([rules.index(SKILL_TARGETS[s][slot]) for s in SKILLS])
    return rules, per_skill


_SLOT_RULES = {slot: _rule_index(slot) for slot in SLOTS}


def task_axis(mode: torch.Tensor, cur: Relational, final_x_or: torch.Tensor) -> torch.Tensor:
    """d^h, unit vector in the hand frame: grasp object centre -> hand origin; relocate current
    object position -> final position; rotate/translate the mode's fixed axis."""
    skill = MODE_SKILL_ID.to(mode.device)[mode]
    fixed = MODE_AXES.to(mode.device)[mode]
    grasp_d = -cur.x_oh
    reloc_d = quat_apply(quat_inv(cur.q_hr), final_x_or - cur.x_or)
    d = torch.where((skill == 0)[:, None], grasp_d, torch.where((skill == 1)[:, None], reloc_d, fixed))
    n = torch.linalg.norm(d, dim=-1, keepdim=True)
    return torch.where(n > 1e-6, d / n.clamp_min(1e-6), torch.zeros_like(d))


class _Rules:
    """The tracked rules of the target table; each is a function of the step's context."""

    @staticmethod
    def palm(c):
        return torch.zeros_like(c.cur.x_oh)

    @staticmethod
    def translate_along_axis(c):
        return c.cur.x_oh + c.p.v_max * c.p.dt * c.axis

    @staticmethod
    def rotate_about_axis(c):
        rot = quat_from_axis_angle(c.axis, torch.full_like(c.axis[:, 0], c.p.omega_max * c.p.dt))
        return quat_positive(quat_mul(rot, c.cur.q_oh))

    @staticmethod
    def interpolate(c, slot):
        if slot == "x_or":
            step = c.final_x_or - c.cur.x_or
            n = torch.linalg.norm(step, dim=-1, keepdim=True)
            return c.cur.x_or + step * torch.clamp(c.p.relocate_v * c.p.dt / n.clamp_min(1e-9), max=1.0)
        return slerp_toward(c.cur.q_or, c.final_q_or, c.p.relocate_omega * c.p.dt)

    @staticmethod
    def object_from_hand(c, slot):
        """Root-frame object target from the current wrist and the hand-frame object target."""
        if slot == "x_or":
            return c.cur.x_hr + quat_apply(c.cur.q_hr, c.out["x_oh"])
        return quat_positive(quat_mul(c.cur.q_hr, c.out["q_oh"]))

    @staticmethod
    def hand_from_object(c, slot):
        """Hand target that realises the object target with the current object-in-hand pose."""
        if "hand" not in c.cache:
            inv_p, inv_q = pose_inv(c.cur.x_oh, c.cur.q_oh)
            c.cache["hand"] = pose_mul(c.out["x_or"], c.out["q_or"], inv_p, inv_q)
        hx, hq = c.cache["hand"]
        return hx if slot == "x_hr" else quat_positive(hq)


@dataclasses.dataclass
class _Ctx:
    cur: Relational
    init: Relational
    final_x_or: torch.Tensor
    final_q_or: torch.Tensor
    axis: torch.Tensor
    p: MotionParams
    out: dict
    cache: dict


def _candidate(rule: str, slot: str, c: _Ctx) -> torch.Tensor:
    if rule == "fixed":
        return getattr(c.init, slot)
    if rule == "free":
        return getattr(c.cur, slot)
    fn = getattr(_Rules, rule)
    return fn(c, slot) if rule in ("interpolate", "object_from_hand", "hand_from_object") else fn(c)


def update_targets(mode: torch.Tensor, cur: Relational, init: Relational, final_x_or: torch.Tensor,
                   final_q_or: torch.Tensor, axis: torch.Tensor, p: MotionParams,
                   skill: str | None = None) -> Relational:
    """Targets for the next step from the current relational state (paper §3.2).

    Slots are filled in dependency order (hand-frame object targets, root-frame object targets,
    hand targets). With ``skill`` given (all envs share it) only that skill's rules run;
    otherwise every rule of a slot runs and each env selects its skill's rule.
    """
    c = _Ctx(cur, init, final_x_or, final_q_or, axis, p, {}, {})
    env_skill = None if skill is not None else MODE_SKILL_ID.to(mode.device)[mode]
    for slot in SLOTS:
        if skill is not None:
            c.out[slot] = _candidate(SKILL_TARGETS[skill][slot], slot, c)
            continue
        rules, per_skill = _SLOT_RULES[slot]
        rid = per_skill.to(mode.device)[env_skill]
        out = _candidate(rules[0], slot, c)
        for i, r in enumerate(rules[1:], start=1):
            out = torch.where((rid == i)[:, None], _candidate(r, slot, c), out)
        c.out[slot] = out
    return Relational(**c.out)


FREE_BY_MODE = torch.tensor([[SKILL_TARGETS[mode_skill(m)][s] == "free" for s in SLOTS for _ in range(SLOT_DIMS[s])]
                             for m in MODES])  # [modes, 21]


def with_free_as_current(mode: torch.Tensor, tgt: Relational, cur: Relational) -> Relational:
    """Targets where Free slots take the current value (their tracking error is zero)."""
    return Relational(torch.where(FREE_BY_MODE.to(mode.device)[mode], cur.data, tgt.data))


def goal_features(mode: torch.Tensor, axis: torch.Tensor, cur: Relational, tgt: Relational,
                  zero_target: bool = False) -> torch.Tensor:
    """g = [one-hot mode, d^h, g_current, g_target] (55-D)."""
    onehot = torch.nn.functional.one_hot(mode, NUM_MODES).to(axis.dtype)
    target = tgt.flat()
    if zero_target:
        target = torch.zeros_like(target)
    return torch.cat([onehot, axis, cur.flat(), target], dim=-1)


def wrist_reference(tgt: Relational) -> torch.Tensor:
    """Virtual-joint values that realise the target hand pose: (x̂_h^r, Euler XYZ of q̂_h^r)."""
    return torch.cat([tgt.x_hr, quat_to_euler_xyz(tgt.q_hr)], dim=-1)


def map_action(action: torch.Tensor, prev_command: torch.Tensor, wrist_ref: torch.Tensor,
               scale: torch.Tensor, lower: torch.Tensor, upper: torch.Tensor,
               wrist_from_target: bool = True) -> torch.Tensor:
    """q_act = clamp(q_ref + alpha * a, q_min, q_max); the first 6 joints are the virtual wrist."""
    ref = prev_command.clone()
    if wrist_from_target:
        ref[:, :6] = wrist_ref
    return torch.clamp(ref + scale * action, lower, upper)


def finite_velocity(x_prev, q_prev, x_cur, q_cur, dt: float) -> Tuple[torch.Tensor, torch.Tensor]:
    """Linear and angular velocity of poses between two control steps, both expressed in each
    pose's parent frame (e.g. the object's hand-frame velocity from x_oh, q_oh). Any leading shape."""
    v = (x_cur - x_prev) / dt
    w = quat_to_axis_angle(quat_mul(q_cur, quat_inv(q_prev))) / dt
    return v, w
