"""Registration of the UniCross task ids with ManiSkill and gymnasium.

Unlike ManiSkill's ``register_env``, ``gym.make`` adds no time-limit wrapper: every UniCross
task truncates its episodes itself, per env, from its mode's episode length (``configs/
task.yaml``) or its chain phases, and a wrapper with one fixed length would overwrite that.
``max_episode_steps`` is still recorded in ManiSkill's registry for tools that read it.
"""
from __future__ import annotations

from functools import partial

import gymnasium as gym
from mani_skill.utils.registration import REGISTERED_ENVS, make, make_vec, register


def register_task(uid: str, max_episode_steps: int):
    def deco(cls):
        if uid not in REGISTERED_ENVS:
            register(uid, cls, max_episode_steps=max_episode_steps, default_kwargs={})
        if uid not in gym.registry:
            gym.register(uid, entry_point=partial(make, env_id=uid), vector_entry_point=partial(make_vec, env_id=uid),
                         max_episode_steps=None, disable_env_checker=True, kwargs={})
        return cls
    return deco
