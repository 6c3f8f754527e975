"""Reward audit: what PPO would be paid for reference behaviours of one mode.

Each reference behaviour is rolled out in the training task (the env settings of
``configs/ppo.yaml``: its ``task_config`` and ``reward_config`` overrides, randomisation on) over
the same objects and seeds. Every reward term is summed as PPO sees it: discounted by the GAE's
``gamma`` and multiplied by ``reward_scale``. Behaviours are ranked by that total; a reward is
sound for a mode when its successful reference ranks first.

Grasp behaviours (scripted on the task's own state, through the normal action interface):

  scripted       descend, close, lift (the scripted grasp synthesiser's policy)
  descend_close  descend and close, then hold still (the task's lift phase raises the wrist)
  hover          descend, never close
  hold_down      hover, then hold the wrist down against the task's lift (the wrist's residual cancels
                 its rise): the object is never lifted, so it never counts as dropped
  close_only     close the fingers where the hand starts (above the object)
  zero           no action
  random         uniform random actions

Relocate: ``follow`` (the successful reference: the zero action, so the wrist follows the task's
interpolated target and the fingers hold the grasp), ``follow_tight`` (the same with the fingers
tightened by 0.1 rad, as the naive baseline holds them), ``naive`` (the paper's naive baseline:
wrist driven straight to the goal, fingers tightened), ``stay`` (the wrist holds its start pose)
and ``random``.

Rotate and translate: ``oracle``, ``zero``, ``open``, ``close``, ``random``. The oracle is a kinematic reference:
the hand holds still (zero action) and, after each control step's physics, the object is placed
in the hand advanced by the mode's own speed (``omega_max`` about the hand-frame axis through
the object's centre, or ``v_max`` along it) with zero velocity. The reward then measures the
motion the mode asks for, exactly, with the contacts the physics produced: what the reward
would pay a policy that does the skill. ``open`` and ``close`` are physical references: the
finger targets move steadily along the hand's opening (closing) direction, 0.02 rad per control
step at most per joint, the wrist holding still. Opening the fingers slides a grasped object out
along the fingers (translate z+: 8/8 successes palm up and from random wrist orientations on
train objects), so translate z+ must pay it more than holding still (:func:`physical_reference`),
and more for every step on the way there (:func:`ascent`: the same sweep at a fraction of its rate).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Dict, List, Optional, Tuple

import gymnasium as gym
import torch

from unicross import formulation as F
from unicross.seeding import trial_seed
from unicross.config import load_config
from unicross.geometry import quat_apply, quat_inv

from unicross.rewards import term_names


# ----------------------------------------------------------------------------- reference behaviours
def _grasp_script(lift: bool, close: bool, descend: bool):
    from unicross.scripted_grasp import ScriptedGrasp

    def make(u):
        script = ScriptedGrasp(u, lift_height=0.15 if lift else 0.0)

        def act():
            t = script.t
            a = script()
            if not descend and t < script.t_close:
                a[:, :3] = 0.0
            if not close and script.t_close <= t < script.t_settle:
                a[:, 6:] = 0.0
            return a
        return act
    return make


def _hold_down(u):
    """Hover (descend, never close); from the lift phase on, the wrist's translation residual cancels
    the task's lift (``lift_speed`` along the world's up for each step after ``lift_after``): a grasp
    policy can learn this where every failed lift is penalised until the episode ends."""
    hover = _grasp_script(lift=False, close=False, descend=True)(u)
    g = u.cfg["grasp"]
    step = 0

    def act():
        nonlocal step
        a = hover()
        if g["lift_after"] is not None and step >= g["lift_after"]:
            up_root = quat_apply(quat_inv(u.root_q), torch.tensor([0.0, 0.0, 1.0], device=u.device).expand(u.num_envs, 3))
            a[:, :3] = -(up_root * g["lift_speed"] * u.control_dt) / u.action_scale[:3]
        step += 1
        return a.clamp(-1.0, 1.0)
    return act


def _zero(u):
    return lambda: torch.zeros(u.num_envs, u.hand_spec.dof, device=u.device)


def _random_factory(seed: int):
    def make(u):
        g = torch.Generator().manual_seed(seed)
        return lambda: (torch.rand(u.num_envs, u.hand_spec.dof, generator=g) * 2 - 1).to(u.device)
    return make


def _stay(u):
    """Wrist actions that cancel the target's motion: the hand stays where it started."""
    start = F.wrist_reference(u.targets).clone()

    def act():
        a = torch.zeros(u.num_envs, u.hand_spec.dof, device=u.device)
        a[:, :6] = (start - F.wrist_reference(u.targets)) / u.action_scale[:6]
        return a.clamp(-1.0, 1.0)
    return act


def _follow_relocate(u):
    """The wrist follows its Tracked reference (zero residual) while the fingers hold the grasp
    slightly tightened (as the paper's naive baseline does)."""
    from unicross.evaluation import tightened_fingers_action
    return lambda: tightened_fingers_action(u)


def _naive_relocate(u):
    from unicross.evaluation import scripted_relocate_policy
    return lambda: scripted_relocate_policy(None, u)


def finger_sweep_action(hand_spec, rate: float, joints: Optional[Tuple[str, int]] = None) -> torch.Tensor:
    """The constant normalised action [dof] that moves the finger targets ``rate`` rad per control
    step along the closing direction (negative: opening), the fastest joint by ``|rate|``, with a
    zero wrist residual. ``joints = (finger, k)`` moves only that finger's ``k`` most distal joints
    (at the same per-joint rates), the others hold."""
    from unicross.scripted_grasp import closing_direction
    scale = torch.as_tensor(hand_spec.action_scales(), dtype=torch.float32)
    a = torch.zeros(hand_spec.dof)
    a[6:] = (rate * closing_direction(hand_spec) / scale[6:]).clamp(-1.0, 1.0)
    if joints is not None:
        finger, k = joints
        if finger not in hand_spec.fingers:
            raise ValueError(f"hand {hand_spec.name!r} has no finger {finger!r}; its fingers: {list(hand_spec.fingers)}")
        moving = set(hand_spec.fingers[finger][-k:])
        a[6:] *= torch.tensor([j in moving for j in hand_spec.finger_joints])
    return a


def _finger_sweep(rate: float, joints: Optional[Tuple[str, int]] = None):
    """:func:`finger_sweep_action` at every step."""
    def make(u):
        a = finger_sweep_action(u.hand_spec, rate, joints).to(u.device)
        return lambda: a.expand(u.num_envs, -1).clone()
    return make


def _oracle(u):
    """Kinematic in-hand motion (see the module docstring); installs a per-instance hook that
    :func:`audit` removes after the episode."""
    from mani_skill.utils.structs.pose import Pose
    from unicross.geometry import pose_mul, quat_from_axis_angle, quat_mul, quat_positive
    axis = F.MODE_AXES.to(u.device)[u.mode]
    rotate = F.mode_skill(F.MODES[int(u.mode[0])]) == "rotate"  # the oracle turns or slides
    step_angle = u.cfg["motion"]["omega_max"] * u.control_dt
    step_dist = u.cfg["motion"]["v_max"] * u.control_dt
    held = dict(x=u.cur_rel.x_oh.clone(), q=u.cur_rel.q_oh.clone())

    def after_control_step():
        if rotate:
            dq = quat_from_axis_angle(axis, torch.full((u.num_envs,), step_angle, device=u.device))
            held["q"] = quat_positive(quat_mul(dq, held["q"]))
        else:
            held["x"] = held["x"] + axis * step_dist
        pos, quat = u.sensor.poses()
        p, q = pose_mul(pos[:, 0], quat[:, 0], held["x"], held["q"])
        u.obj.set_pose(Pose.create_from_pq(p, q))
        zero = torch.zeros(u.num_envs, 3, device=u.device)
        u.obj.set_linear_velocity(zero)
        u.obj.set_angular_velocity(zero)

    u._after_control_step = after_control_step
    return _zero(u)


# (skill, axis) -> (behaviour, finger rate, joints: None = every finger joint, or (finger, k): its k
# most distal joints; see finger_sweep_action). Translate z+: opening slides the object out along the
# fingers. Translate z-: curling the index finger's two distal joints pushes it toward the wrist
# (closing every finger moves it only 1.7-2.3 cm; docs/runs/translate_zm_reference/)
PHYSICAL_REFERENCES = {("translate", "z+"): ("open", -0.02, None),
                       ("translate", "z-"): ("pull", 0.05, ("index", 2))}
ASCENT_FRACTIONS = (0.0, 0.125, 0.25, 0.375, 0.5, 0.75, 1.0)


def physical_reference(skill: str, axis: Optional[str]) -> Optional[str]:
    """The behaviour that does the mode through the physics alone (no kinematic help), where one is
    known: it must out-earn holding still for PPO to have a reason to find it."""
    ref = PHYSICAL_REFERENCES.get((skill, axis))
    return ref[0] if ref else None


def _reference(skill: str, axis: Optional[str]):
    """(behaviour name, finger rate, joints) of the physical reference of (skill, axis); refuses a mode
    without one."""
    if (skill, axis) not in PHYSICAL_REFERENCES:
        raise ValueError(f"no physical reference for {skill} {axis}; known: {sorted(PHYSICAL_REFERENCES)}")
    return PHYSICAL_REFERENCES[(skill, axis)]


def ascent_behaviours(skill: str, axis: Optional[str], fractions=ASCENT_FRACTIONS) -> Dict[str, Callable]:
    """The physical reference scaled from nothing (the zero action) to its full rate, as behaviours
    named ``<reference>@<fraction>``. PPO starts near the zero action and follows the gradient of
    the return: the reward gives it a path to the reference only when the return rises along the
    way, not just at the end (:func:`ascent`)."""
    name, rate, joints = _reference(skill, axis)
    return {f"{name}@{f:g}": _finger_sweep(rate * f, joints) for f in fractions}


def reference_action(skill: str, axis: Optional[str], hand_spec, fraction: float = 1.0) -> torch.Tensor:
    """The constant normalised action [dof] of the physical reference of (``skill``, ``axis``) at
    ``fraction`` of its rate: what ``model.init_reference`` starts a policy's mean at."""
    _, rate, joints = _reference(skill, axis)
    return finger_sweep_action(hand_spec, rate * fraction, joints)


def ascent(skill: str, axis: Optional[str], fractions=ASCENT_FRACTIONS, **audit_kw) -> List["AuditRow"]:
    """:func:`audit` of :func:`ascent_behaviours`, in the order of the path (not ranked)."""
    rows = audit(skill, axis, behaviour_set=ascent_behaviours(skill, axis, fractions), **audit_kw)
    return sorted(rows, key=lambda r: float(r.behaviour.split("@")[1]))


def first_dip(rows: List["AuditRow"]) -> Optional[str]:
    """The first behaviour on an ascent path that earns less than the one before it (None: the
    return rises all the way)."""
    return next((b.behaviour for a, b in zip(rows, rows[1:]) if b.total < a.total), None)


def _gait(spec: str):
    """The scripted finger gait ``spec`` (:mod:`unicross.gaits`), run until its mode is done, then holding."""
    def make(u):
        from unicross.gaits import make_gait_policy
        policy = make_gait_policy(spec)
        return lambda: policy(None, u)
    return make


def behaviours(skill: str, seed: int = 0, axis: Optional[str] = None, hand: str = "allegro") -> Dict[str, Callable]:
    """name -> factory(u) -> act() for the reference behaviours of ``skill``; the first is the
    successful reference. With ``axis``, a mode with a shipped scripted gait (:mod:`unicross.gaits`)
    also lists it as ``gait`` (and run without its privileged stop, ``stop=0``, as ``gait_nostop``),
    and one with a physical reference not listed already (translate z-: ``pull``) lists that."""
    common = dict(zero=_zero, random=_random_factory(seed))
    if skill == "grasp":
        return dict(scripted=_grasp_script(lift=True, close=True, descend=True),
                    descend_close=_grasp_script(lift=False, close=True, descend=True),
                    hover=_grasp_script(lift=False, close=False, descend=True), hold_down=_hold_down,
                    close_only=_grasp_script(lift=False, close=True, descend=False), **common)
    if skill == "relocate":
        return dict(follow=_zero, follow_tight=_follow_relocate, naive=_naive_relocate, stay=_stay,
                    random=common["random"])
    if skill in ("rotate", "translate"):
        from unicross.gaits import shipped_gaits
        gait = shipped_gaits(hand).get(f"{skill}_{axis}") if axis else None
        gaits = dict(gait=_gait(gait), gait_nostop=_gait(f"{gait},stop=0")) if gait else {}  # with / without its stop
        beh = dict(oracle=_oracle, **gaits, zero=common["zero"],
                   open=_finger_sweep(-0.02), close=_finger_sweep(0.02), random=common["random"])
        ref = PHYSICAL_REFERENCES.get((skill, axis))
        if ref:
            beh.setdefault(ref[0], _finger_sweep(ref[1], ref[2]))
        return beh
    raise ValueError(f"unknown skill {skill!r}; valid: grasp, relocate, rotate, translate")


# ----------------------------------------------------------------------------- rollouts
@dataclass
class AuditRow:
    behaviour: str
    episodes: int
    success: float
    total: float                # mean discounted, scaled return
    terms: Dict[str, float]     # mean discounted, scaled return per term
    undiscounted: float         # mean raw (unscaled, undiscounted) return
    min_total: float            # worst episode (discounted, scaled)
    returns: List[float] = field(default_factory=list)    # every episode's total (discounted, scaled)
    successes: List[float] = field(default_factory=list)  # every episode's success at its end (0 or 1)


def audit(skill: str = "grasp", axis: Optional[str] = None, objects: Optional[str] = None, limit: int = 2,
          seeds: int = 3, hand: str = "allegro", ppo_overrides: Optional[dict] = None,
          only: Optional[List[str]] = None, progress: bool = True,
          behaviour_set: Optional[Dict[str, Callable]] = None) -> List[AuditRow]:
    """Rolls every reference behaviour of ``skill`` (or those of ``behaviour_set``: name ->
    factory(u) -> act()) out on the first ``limit`` objects per group of ``objects`` (default: the
    skill's training set) for ``seeds`` seeds each, in the PPO training env; returns the rows
    ranked by discounted scaled return (best first)."""
    import unicross  # noqa: F401  (registers the tasks)
    from tqdm import tqdm
    from unicross.objects import get_object_set
    from unicross.registry import skill as skill_entry
    from unicross.rl.ppo import env_kwargs_for
    cfg = load_config("ppo", ppo_overrides)
    gamma, scale = cfg["gae"]["gamma"], cfg["gae"]["reward_scale"]
    kw = env_kwargs_for(skill, axis, hand, cfg["env"])
    kw.pop("object_limit", None)
    kw.pop("reconfiguration_freq", None)
    objs = get_object_set(objects or skill_entry(skill).train_objects, limit=limit)
    beh = behaviour_set if behaviour_set is not None else behaviours(skill, axis=axis, hand=hand)
    if only:
        bad = [b for b in only if b not in beh]
        if bad:
            raise ValueError(f"unknown behaviour(s) {bad}; valid for {skill}: {list(beh)}")
        beh = {k: v for k, v in beh.items() if k in only}
    terms = term_names()
    acc = {b: dict(total=[], raw=[], succeeded=[], terms={t: [] for t in terms}) for b in beh}
    bar = tqdm(total=len(objs) * seeds * len(beh), desc=f"audit {skill}", disable=not progress)
    for oi, obj in enumerate(objs):
        env = gym.make(skill_entry(skill).env_id, obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none",
                       num_envs=1, **{**kw, "objects": [obj]})
        u = env.unwrapped
        length = int(u.episode_length[u.mode[0]])
        for name, make in beh.items():
            for k in range(seeds):
                u.reset(seed=trial_seed(0, oi, k))
                act = make(u)
                disc = 1.0
                ret = {t: 0.0 for t in terms}
                raw, success = 0.0, False
                for _ in range(length):
                    _, r, term, trunc, info = u.step(act())
                    for t in terms:
                        ret[t] += disc * scale * float(info[f"reward_{t}"][0])
                    raw += float(r[0])
                    disc *= gamma
                    success = bool(info["success"][0])
                    if bool(term[0]) or bool(trunc[0]):
                        break
                u.__dict__.pop("_after_control_step", None)  # the oracle's hook, if any
                for t in terms:
                    acc[name]["terms"][t].append(ret[t])
                acc[name]["total"].append(sum(ret.values()))
                acc[name]["raw"].append(raw)
                acc[name]["succeeded"].append(float(success))
                bar.update(1)
        env.close()
    bar.close()
    mean = lambda xs: sum(xs) / max(len(xs), 1)
    rows = [AuditRow(b, len(a["total"]), mean(a["succeeded"]), mean(a["total"]), {t: mean(a["terms"][t]) for t in terms},
                     mean(a["raw"]), min(a["total"]), a["total"], a["succeeded"]) for b, a in acc.items()]
    return sorted(rows, key=lambda r: -r.total)


def format_rows(rows: List[AuditRow]) -> str:
    terms = list(rows[0].terms) if rows else list(term_names())
    head = "| rank | behaviour | n | success | return (disc., scaled) | worst | raw return | " + \
           " | ".join(terms) + " |"
    lines = [head, "|" + "---|" * (7 + len(terms))]
    for i, r in enumerate(rows, 1):
        lines.append(f"| {i} | {r.behaviour} | {r.episodes} | {100 * r.success:.0f}% | {r.total:.3f} | "
                     f"{r.min_total:.3f} | {r.undiscounted:.1f} | " + " | ".join(f"{r.terms[t]:.3f}" for t in terms) + " |")
    return "\n".join(lines)
