"""Scripted grasp synthesiser: real, physically settled grasps before a grasp expert exists.

It drives ``UniCross-Grasp-v1`` through its normal action interface (normalised residual
actions), batched over envs:

  descend   the wrist moves along the palm normal until the hand-frame origin is just above the
            object's centre (or fingertips near the table);
  close     flexion joints move towards the closed pose (the PD drives then squeeze);
  lift      the wrist rises ``lift_height`` in the world;
  hold      the hand holds still for ``hold_seconds``.

A grasp is kept when the object never dropped, is lifted by at least ``0.5 * lift_height`` (the free wrist lags its commands) and
at least two links touch it at the end. The recorded state (finger joints and their targets,
wrist pose, object pose in the hand frame) is the grasp dataset format of :mod:`unicross.grasps`.
"""
from __future__ import annotations

from typing import List, Optional, Sequence, Tuple

import gymnasium as gym
import torch
from tqdm import tqdm

from unicross.seeding import GRASP_STRIDES, trial_seed
from unicross.geometry import quat_apply, quat_inv
from unicross.grasps import GraspSet, empty_rows, from_rows
from unicross.objects import ObjectSpec

PHASES = dict(descend=14, close=14, settle=6)


def closing_delta(hand_spec) -> torch.Tensor:
    """Per-finger-joint closing increment (the hand description's ``closing_delta``; by default
    every joint but the first of each finger is flexed by 0.7 rad)."""
    return torch.from_numpy(hand_spec.closing_deltas())


def closing_direction(hand_spec) -> torch.Tensor:
    """:func:`closing_delta` scaled so its largest joint increment is 1 (rad): multiply by a step
    in rad to move every finger joint along the hand's closing direction, the fastest by that step."""
    d = closing_delta(hand_spec)
    return d / d.abs().max().clamp(min=1e-6)


class ScriptedGrasp:
    """The scripted policy for the unwrapped grasp task ``u`` right after its reset; each call
    returns the next normalised action."""

    def __init__(self, u, lift_height: float = 0.15, hold_seconds: float = 2.0):
        self.env = u
        self.lift_steps = int(round(1.0 / u.control_dt))
        self.hold_steps = int(round(hold_seconds / u.control_dt))
        self.lift_height = lift_height
        self.t_close = PHASES["descend"]
        self.t_settle = self.t_close + PHASES["close"]
        self.t_lift = self.t_settle + PHASES["settle"]
        self.t_hold = self.t_lift + self.lift_steps
        self.total = self.t_hold + self.hold_steps
        dev = u.device
        self.delta = closing_delta(u.hand_spec).to(dev)
        self.q_open = u.command[:, 6:].clone()
        # where the hand-frame origin should end up: just above the object's centre (world z)
        self.z_goal = u.obj_z0 + 0.01
        self.t = 0

    def __call__(self) -> torch.Tensor:
        u, t = self.env, self.t
        n, dev = u.num_envs, u.device
        a = torch.zeros(n, u.hand_spec.dof, device=dev)
        scale = u.action_scale
        hand_z = u.root_p[:, 2] + quat_apply(u.root_q, u.cur_rel.x_hr)[:, 2]
        up_root = quat_apply(quat_inv(u.root_q), torch.tensor([0.0, 0.0, 1.0], device=dev).expand(n, 3))
        if t < self.t_close:
            dz = (self.z_goal - hand_z).clamp(min=-0.012, max=0.0)  # move down, at most 1.2 cm/step
            a[:, :3] = (up_root * dz[:, None]) / scale[:3]
        elif t < self.t_settle:
            frac = (t - self.t_close + 1) / (self.t_settle - self.t_close)
            q_des = torch.clamp(self.q_open + frac * self.delta, u.q_lower[6:], u.q_upper[6:])
            a[:, 6:] = (q_des - u.command[:, 6:]) / scale[6:]
        elif self.t_lift <= t < self.t_hold:
            a[:, :3] = (up_root * (self.lift_height / self.lift_steps)) / scale[:3]
        self.t += 1
        return a.clamp(-1.0, 1.0)


def synthesize(hand: str, objects: Sequence[ObjectSpec], per_object: int, seed: int = 0,
               sim_backend: str = "physx_cpu", num_envs: int = 1, max_tries: Optional[int] = None,
               progress: bool = True, randomize: bool = True):
    """Synthesise up to ``per_object`` grasps per object. Returns (GraspSet, stats dict).

    On the CPU backend one env is simulated at a time (SAPIEN CPU: one env per process); on the
    GPU ``num_envs`` envs run in parallel over the objects.
    """
    import unicross  # noqa: F401  (registers the tasks)
    max_tries = max_tries or 2 * per_object
    rows = empty_rows()
    names = [o.name for o in objects]
    tried = {n: 0 for n in names}
    kept = {n: 0 for n in names}
    bar = tqdm(total=len(objects) * per_object, desc="scripted grasps", disable=not progress)
    for oi, obj in enumerate(objects):
        env = gym.make("UniCross-Grasp-v1", num_envs=num_envs, obs_mode="none", sim_backend=sim_backend,
                       render_backend="none", hand=hand, objects=[obj], randomize=randomize,
                       config=dict(grasp=dict(lift_after=None)))
        u = env.unwrapped
        attempt = 0
        while kept[obj.name] < per_object and tried[obj.name] < max_tries:
            u.reset(seed=trial_seed(seed, oi, attempt, strides=GRASP_STRIDES))
            attempt += 1
            policy = ScriptedGrasp(u)
            info = None
            for _ in range(policy.total):
                _, _, _, _, info = u.step(policy())
            ok = (~info["ever_dropped"]) & (u.cur_rel.x_hr.norm(dim=-1) > 0) & (info["num_contacts"] >= 2) \
                & ((u.sensor.poses()[0][:, -1, 2] - u.obj_z0) > 0.5 * policy.lift_height)
            tried[obj.name] += num_envs
            for e in torch.nonzero(ok).flatten().tolist():
                if kept[obj.name] >= per_object:
                    break
                for k, v in grasp_state(u, e, oi).items():
                    rows[k].append(v)
                kept[obj.name] += 1
                bar.update(1)
        env.close()
    bar.close()
    return from_rows(hand, names, rows, tried, kept, source="scripted")


def grasp_state(u, e: int, object_id: int) -> dict:
    """The grasp-dataset row of env ``e`` of the unwrapped task ``u`` (copies, on the CPU)."""
    pos, quat = u.sensor.poses()
    full = u.agent.robot.get_qpos()
    q = full[:, u._qidx]
    return dict(finger_qpos=q[e, 6:].cpu().clone(), finger_target=u.command[e, 6:].cpu().clone(),
                mimic_qpos=full[e, u._midx].cpu().clone(),
                wrist_pose=torch.cat([pos[e, 0], quat[e, 0]]).cpu().clone(),
                object_pose_hand=torch.cat([u.cur_rel.x_oh[e], u.cur_rel.q_oh[e]]).cpu().clone(),
                object_id=torch.tensor(object_id))


def contact_link_fingers(u) -> List[str]:
    """The finger (a key of the hand's ``fingers``) each contact link of the task ``u`` belongs to, in
    the order of ``hand_spec.contact_links``: the first finger joint met walking up the kinematic tree
    from the link (a fingertip's fixed joint or a mimic joint leads on to its finger); ``"palm"`` for
    links above every finger joint."""
    owner = {j: f for f, joints in u.hand_spec.fingers.items() for j in joints}
    out = []
    for link in u.contact_links:
        finger, joint = "palm", link.joint
        while joint is not None:
            if joint.name in owner:
                finger = owner[joint.name]
                break
            joint = joint.parent_link.joint if joint.parent_link is not None else None
        out.append(finger)
    return out


def fingers_touching(u, fingers: Sequence[str], env: int = 0) -> Tuple[str, ...]:
    """The fingers (and ``"palm"``) of env ``env`` of the task ``u`` whose contact links press on the object
    (net contact force above the task's ``contact_force_threshold``), in contact-link order; ``fingers`` is
    :func:`contact_link_fingers` of ``u``."""
    touch = (u.link_force[env] > u.cfg["contact_force_threshold"]).tolist()
    touched = {f for t, f in zip(touch, fingers) if t}
    return tuple(f for f in dict.fromkeys(fingers) if f in touched)


def hold_test(hand: str, grasps: GraspSet, objects: Sequence[ObjectSpec], seconds: float = 2.0,
              seed: int = 0, randomize: bool = False) -> Tuple[List[bool], List[Tuple[str, ...]]]:
    """Restore each grasp in UniCross-Relocate-v1 with the final pose equal to the start (the wrist
    holds still), keep the fingers at their recorded targets for ``seconds`` and report, per grasp
    (lists aligned with the dataset's rows; rows of objects not in ``objects`` count as not held):
    whether the object stayed in the hand (never dropped), and the fingers (and ``"palm"``) touching
    it at the end (a link's net contact force above the task's ``contact_force_threshold``; empty
    when it dropped): which fingers a dataset's grasps hold with (:func:`finger_census`)."""
    import unicross  # noqa: F401
    held = [False] * len(grasps)
    touching: List[Tuple[str, ...]] = [()] * len(grasps)
    by_name = {o.name: o for o in objects}
    for oi, name in enumerate(grasps.object_names):
        mask = grasps.data["object_id"] == oi
        if name not in by_name or not bool(mask.any()):
            continue
        sub = GraspSet(hand, [name], grasps.data[mask], grasps.source)
        sub.data["object_id"] = torch.zeros_like(sub.data["object_id"])
        env = gym.make("UniCross-Relocate-v1", obs_mode="none", sim_backend="physx_cpu", render_backend="none",
                       hand=hand, objects=[by_name[name]], randomize=randomize, grasp_dataset=sub,
                       config=dict(relocate_target=dict(xy=0.0, z=[0.0, 0.0], rpy=0.0)))
        u = env.unwrapped
        fingers = contact_link_fingers(u)
        for k, row in enumerate(torch.nonzero(mask).flatten().tolist()):
            u.grasps = GraspSet(hand, [name], sub.data[k:k + 1], grasps.source)  # exactly this grasp
            u.reset(seed=seed + k)
            zero = torch.zeros(1, u.hand_spec.dof)
            info = None
            for _ in range(int(round(seconds / u.control_dt))):
                _, _, _, _, info = u.step(zero)
            held[row] = bool((~info["ever_dropped"]).item())
            if held[row]:
                touching[row] = fingers_touching(u, fingers)
        env.close()
    return held, touching


def finger_census(grasps: GraspSet, objects: Sequence[ObjectSpec], touching: Sequence[Tuple[str, ...]],
                  rows: Optional[Sequence[bool]] = None) -> dict:
    """Per object category, over the dataset's rows (those where ``rows`` is true): the number of
    grasps, how many each finger (and the palm) touches at the end of :func:`hold_test`, and the
    sets of touching fingers by frequency (``"index+ring": 79``)."""
    category = {o.name: o.category for o in objects}
    out: dict = {}
    for i, oid in enumerate(grasps.data["object_id"].tolist()):
        if rows is not None and not rows[i]:
            continue
        c = out.setdefault(category.get(grasps.object_names[oid], "other"), dict(grasps=0, touching={}, sets={}))
        c["grasps"] += 1
        for f in touching[i]:
            c["touching"][f] = c["touching"].get(f, 0) + 1
        key = "+".join(touching[i]) or "none"
        c["sets"][key] = c["sets"].get(key, 0) + 1
    for c in out.values():
        c["sets"] = dict(sorted(c["sets"].items(), key=lambda kv: -kv[1]))
    return out
