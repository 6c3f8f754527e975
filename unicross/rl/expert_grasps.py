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
