"""UniCross: unified cross-skill dexterous manipulation as ManiSkill3 tasks.

``import unicross`` registers the task ids ``UniCross-{Grasp,Relocate,Rotate,Translate,MultiSkill,Chain}-v1``
with gymnasium, and one id per rotate axis / translate direction with the axis fixed
(``UniCross-RotateXPos-v1``, ``UniCross-TranslateZNeg-v1``, ...) for clients that cannot pass kwargs.
The registration is lazy: the first ``gym.make`` of a UniCross id imports the tasks (ManiSkill,
SAPIEN, torch) and registers them with ManiSkill too, so ``import unicross`` and the CLI's help
stay fast. ``unicross.tasks`` imports them at once.
"""
from functools import partial

__version__ = "0.1.0"

from unicross.registry import SKILLS as _SKILLS, axis_env_id as _axis_env_id  # noqa: E402

TASK_IDS = ("UniCross-Grasp-v1", "UniCross-Relocate-v1", "UniCross-Rotate-v1", "UniCross-Translate-v1",
            "UniCross-MultiSkill-v1", "UniCross-Chain-v1")
AXIS_TASK_IDS = tuple(_axis_env_id(s, a) for s in _SKILLS.values() for a in s.axes)


def _make(env_id: str, **kwargs):
    from unicross.tasks import chain, skills  # noqa: F401  (imports and registers the task classes)
    from mani_skill.utils.registration import make
    return make(env_id, **kwargs)


def _make_vec(env_id: str, **kwargs):
    from unicross.tasks import chain, skills  # noqa: F401
    from mani_skill.utils.registration import make_vec
    return make_vec(env_id, **kwargs)


def _register() -> None:
    import gymnasium as gym
    for uid in TASK_IDS + AXIS_TASK_IDS:
        if uid not in gym.registry:
            gym.register(uid, entry_point=partial(_make, uid), vector_entry_point=partial(_make_vec, uid),
                         max_episode_steps=None, disable_env_checker=True, kwargs={})


_register()
