"""The grasp-state dataset from a trained grasp expert (the paper's relocate/rotate/translate starts).

The expert runs ``UniCross-Grasp-v1`` (with its lift phase) on each object; a grasp is kept when
the episode succeeds (lifted, never dropped) and the object is settled in the hand at the end
(hand-frame speed below ``settle_speed``). Rows are written in the format of
:mod:`unicross.grasps`, the one the tasks read and the scripted synthesiser writes.
"""
from __future__ import annotations

from typing import Sequence

import gymnasium as gym
from tqdm import tqdm

from unicross.seeding import GRASP_STRIDES, trial_seed
from unicross.grasps import empty_rows, from_rows
from unicross.objects import ObjectSpec
from unicross.rl.policy_io import act, load_policy
from unicross.scripted_grasp import grasp_state


def settled_in_hand(u, settle_speed: float = 0.05):
    """[N] bool: the object moves in the hand frame slower than ``settle_speed`` (m/s) and ten times
    that in rad/s over the last control step (the test a kept grasp passes)."""
    return (u.obj_vel_h.norm(dim=-1) < settle_speed) & (u.obj_angvel_h.norm(dim=-1) < 10 * settle_speed)


def expert_grasps(ckpt_path, objects: Sequence[ObjectSpec], per_object: int, seed: int = 0,
                  max_tries: int | None = None, settle_speed: float = 0.05, progress: bool = True):
    import unicross  # noqa: F401
    policy, ck = load_policy(ckpt_path)
    if ck.get("skill") != "grasp":
        raise ValueError(f"{ckpt_path} is a {ck.get('skill')!r} expert, not a grasp expert")
    hand = ck["hand"]
    max_tries = max_tries or 4 * per_object
    rows = empty_rows()
    tried, kept = {}, {}
    bar = tqdm(total=len(objects) * per_object, desc="expert grasps", disable=not progress)
    for oi, obj in enumerate(objects):
        env = gym.make("UniCross-Grasp-v1", obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none",
                       hand=hand, objects=[obj], randomize=False)
        u = env.unwrapped
        length = int(u.episode_length[0])
        tried[obj.name] = kept[obj.name] = 0
        while kept[obj.name] < per_object and tried[obj.name] < max_tries:
            obs, _ = u.reset(seed=trial_seed(seed, oi, tried[obj.name], strides=GRASP_STRIDES))
            info = None
            for _ in range(length):
                obs, _, term, _, info = u.step(act(policy, obs))
                if bool(term.all()):
                    break
            tried[obj.name] += 1
            ok = info["success"] & ~info["ever_dropped"] & settled_in_hand(u, settle_speed)
            if bool(ok[0]):
                for k, v in grasp_state(u, 0, oi).items():
                    rows[k].append(v)
                kept[obj.name] += 1
                bar.update(1)
        env.close()
    bar.close()
    return from_rows(hand, [o.name for o in objects], rows, tried, kept, source=f"expert:{ckpt_path}")


def chained_grasps(policy_spec: str, hand: str, objects: Sequence[ObjectSpec], sequence: str = "grasp,relocate",
                   per_object: int = 1, seed: int = 0, max_tries: int | None = None, settle_speed: float = 0.05,
                   progress: bool = True):
    """Grasp states where a chain leaves the hand: ``policy_spec`` (e.g. ``experts:allegro``, or a
    student) runs ``UniCross-Chain-v1`` over ``sequence`` on each object that can do every phase; a
    state is kept when every phase succeeded, the object was never dropped and it is settled in the
    hand at the end. Its rows carry ``keep_wrist``, so an in-hand start drawn from them keeps the
    wrist where the chain left it: merged into a grasp-state dataset, they give an in-hand mode's
    training (e.g. a distillation stage) the starts the long horizon gives it."""
    import torch
    import unicross  # noqa: F401
    from unicross.evaluation import resolve_policy
    from unicross.tasks.chain import objects_for_chain, parse_sequence
    modes = parse_sequence(sequence)
    objects = objects_for_chain(objects, modes)
    policy, _ = resolve_policy(policy_spec, hand, seed)  # checked against the hand before any simulation
    max_tries = max_tries or 4 * per_object
    rows = empty_rows()
    tried, kept = {}, {}
    bar = tqdm(total=len(objects) * per_object, desc="chained grasps", disable=not progress)
    for oi, obj in enumerate(objects):
        env = gym.make("UniCross-Chain-v1", obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none",
                       hand=hand, objects=[obj], randomize=False, sequence=modes)
        u = env.unwrapped
        tried[obj.name] = kept[obj.name] = 0
        while kept[obj.name] < per_object and tried[obj.name] < max_tries:
            obs, _ = u.reset(seed=trial_seed(seed, oi, tried[obj.name], strides=GRASP_STRIDES))
            dropped = False
            for _ in range(u.phase_ends[-1]):
                obs, _, term, _, _ = u.step(policy(obs, u))
                if bool(term.all()):  # the chain ends early only on a drop
                    dropped = True
                    break
            tried[obj.name] += 1
            if not dropped and bool(u.phase_success[0].all()) and bool(settled_in_hand(u, settle_speed)[0]):
                row = dict(grasp_state(u, 0, oi), keep_wrist=torch.tensor(True))
                for k, v in row.items():
                    rows[k].append(v)
                kept[obj.name] += 1
                bar.update(1)
        env.close()
    bar.close()
    return from_rows(hand, [o.name for o in objects], rows, tried, kept,
                     source=f"chain:{','.join(modes)}:{policy_spec}")
