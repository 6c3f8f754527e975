"""The UniCross task ids. Skills differ only by data (:mod:`unicross.registry`): their modes and
default object sets."""
from __future__ import annotations

from unicross.tasks.registration import register_task

from functools import partialmethod

from unicross.config import load_config
from unicross.registry import SKILLS, axis_env_id
from unicross.tasks.base import UniCrossEnv

EPISODE_STEPS = load_config("task")["episode_length"]  # the TimeLimit of each id; the task truncates by its config


@register_task(SKILLS["grasp"].env_id, max_episode_steps=EPISODE_STEPS["grasp"])
class GraspEnv(UniCrossEnv):
    """Grasp an object resting on the table from a top-down start (see :class:`UniCrossEnv`)."""

    DEFAULT_OBJECTS = SKILLS["grasp"].train_objects
    DEFAULT_MODES = SKILLS["grasp"].modes

    def __init__(self, *args, **kwargs):
        super().__init__(*args, modes=self.DEFAULT_MODES, **kwargs)


@register_task(SKILLS["relocate"].env_id, max_episode_steps=EPISODE_STEPS["relocate"])
class RelocateEnv(GraspEnv):
    """Move a grasped object to a final pose with the object fixed in the hand."""

    DEFAULT_MODES = SKILLS["relocate"].modes


@register_task(SKILLS["rotate"].env_id, max_episode_steps=EPISODE_STEPS["rotate"])
class RotateEnv(UniCrossEnv):
    """Rotate a grasped wrappable object in hand about ``axis`` of the hand frame."""

    DEFAULT_OBJECTS = SKILLS["rotate"].train_objects

    def __init__(self, *args, axis: str = "z+", **kwargs):
        super().__init__(*args, modes=(SKILLS["rotate"].mode(axis),), **kwargs)


@register_task(SKILLS["translate"].env_id, max_episode_steps=EPISODE_STEPS["translate"])
class TranslateEnv(UniCrossEnv):
    """Translate a grasped elongated object in hand along ``direction`` (hand-frame z)."""

    DEFAULT_OBJECTS = SKILLS["translate"].train_objects

    def __init__(self, *args, direction: str = "z+", **kwargs):
        super().__init__(*args, modes=(SKILLS["translate"].mode(direction),), **kwargs)


@register_task("UniCross-MultiSkill-v1", max_episode_steps=max(EPISODE_STEPS.values()))
class MultiSkillEnv(UniCrossEnv):
    """All ten modes at once: each parallel env holds one valid (object, mode) pair, spread
    uniformly; ``env.unwrapped.mode`` is the per-env mode tensor. Episodes are truncated per env
    at their mode's length."""

    DEFAULT_OBJECTS = "train"


def _register_axis_ids() -> None:
    """One id per mode of every skill with axes (``axis_env_id``; listed as ``unicross.AXIS_TASK_IDS``),
    each a subclass of the skill's class with the axis fixed."""
    from mani_skill.utils.registration import REGISTERED_ENVS
    for s in SKILLS.values():
        base = REGISTERED_ENVS[s.env_id].cls
        for axis in s.axes:
            uid = axis_env_id(s, axis)
            cls = type(uid.replace("-", "_"), (base,), dict(
                __init__=partialmethod(base.__init__, **{s.axis_kwarg: axis}),
                __doc__=f"{base.__doc__.strip()} The {s.axis_kwarg} is fixed to {axis}."))
            register_task(uid, max_episode_steps=EPISODE_STEPS[s.name])(cls)


_register_axis_ids()
