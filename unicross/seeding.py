"""Per-trial seeds derived from the seed a user types, in one place.

Every protocol seeds each trial from (``--seed``, object, axis, trial) so that results do not
depend on sharding or on the trials run before; the value wraps into [0, 2**32), the range
ManiSkill and NumPy accept, so any ``--seed`` works (the plain sum overflowed above ~4294).
For seeds where the sum fits, the value is the sum itself: published results keep their trials.
"""
from __future__ import annotations

SEED_SPACE = 2 ** 32
EVAL_STRIDES = (1_000_003, 10_007, 1009)  # seed, object, axis (evaluation, chain, random policy, audit)
GRASP_STRIDES = (100_003, 1009, 0)        # seed, object (grasp synthesis attempts)


def trial_seed(seed: int, obj: int = 0, trial: int = 0, axis: int = 0, strides=EVAL_STRIDES) -> int:
    """``(seed * s0 + obj * s1 + axis * s2 + trial) mod 2**32`` for ``strides`` (s0, s1, s2)."""
    s_seed, s_obj, s_axis = strides
    return (int(seed) * s_seed + int(obj) * s_obj + int(axis) * s_axis + int(trial)) % SEED_SPACE
