"""UniCross: unified cross-skill dexterous manipulation as ManiSkill3 tasks.

``import unicross`` registers the task ids ``UniCross-{Grasp,Relocate,Rotate,Translate,MultiSkill,Chain}-v1``
with gymnasium/ManiSkill, and one id per rotate axis / translate direction with the axis fixed
(``UniCross-RotateXPos-v1``, ``UniCross-TranslateZNeg-v1``, ...) for clients that cannot pass kwargs.
"""
__version__ = "0.1.0"

from unicross.tasks import chain as _chain  # noqa: F401  (registers the environments)
from unicross.tasks import skills as _skills  # noqa: F401

TASK_IDS = ("UniCross-Grasp-v1", "UniCross-Relocate-v1", "UniCross-Rotate-v1", "UniCross-Translate-v1",
            "UniCross-MultiSkill-v1", "UniCross-Chain-v1")
AXIS_TASK_IDS = _skills.AXIS_TASK_IDS  # the same tasks with the axis in the id: UniCross-RotateXPos-v1, ...
