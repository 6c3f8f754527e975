"""The UniCross task ids. Skills differ only by data: their modes and default object sets."""
from __future__ import annotations

from unicross.tasks.registration import register_task

from unicross import formulation as F
from unicross.tasks.base import UniCrossEnv

EPISODE_STEPS = dict(grasp=64, relocate=64, rotate=400, translate=64)  # configs/task.yaml episode_length


@register_task("UniCross-Grasp-v1", max_episode_steps=EPISODE_STEPS["grasp"])
class GraspEnv(UniCrossEnv):
    """Grasp an object resting on the table from a top-down start (see :class:`UniCrossEnv`)."""

    DEFAULT_OBJECTS = "train"
    DEFAULT_MODES = ("grasp",)

    def __init__(self, *args, **kwargs):
        super().__init__(*args, modes=self.DEFAULT_MODES, **kwargs)


@register_task("UniCross-Relocate-v1", max_episode_steps=EPISODE_STEPS["relocate"])
class RelocateEnv(GraspEnv):
    """Move a grasped object to a final pose with the object fixed in the hand."""

    DEFAULT_MODES = ("relocate",)


@register_task("UniCross-Rotate-v1", max_episode_steps=EPISODE_STEPS["rotate"])
class RotateEnv(UniCrossEnv):
    """Rotate a grasped wrappable object in hand about ``axis`` of the hand frame."""

    DEFAULT_OBJECTS = "train-wrappable"

    def __init__(self, *args, axis: str = "z+", **kwargs):
        F.mode_index("rotate", axis)  # validates
        super().__init__(*args, modes=(f"rotate_{axis}",), **kwargs)


@register_task("UniCross-Translate-v1", max_episode_steps=EPISODE_STEPS["translate"])
class TranslateEnv(UniCrossEnv):
    """Translate a grasped elongated object in hand along ``direction`` (hand-frame z)."""

    DEFAULT_OBJECTS = "train-elongated"

    def __init__(self, *args, direction: str = "z+", **kwargs):
        F.mode_index("translate", direction)  # validates
        super().__init__(*args, modes=(f"translate_{direction}",), **kwargs)


@register_task("UniCross-MultiSkill-v1", max_episode_steps=max(EPISODE_STEPS.values()))
class MultiSkillEnv(UniCrossEnv):
    """All ten modes at once: each parallel env holds one valid (object, mode) pair, spread
    uniformly; ``env.unwrapped.mode`` is the per-env mode tensor. Episodes are truncated per env
    at their mode's length."""

    DEFAULT_OBJECTS = "train"
