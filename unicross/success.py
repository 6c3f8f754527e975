"""Success tests, registered by name; each skill names its test in its registry entry
(:attr:`unicross.registry.Skill.success`).

A test is a function ``fn(m, sc) -> bool [N]`` of the step's success measurements ``m`` (batched
tensors: ``contact`` [N, L] link contact flags, ``lifted``, ``pos_err``/``rot_err`` to the final
pose, ``rot_acc``/``trans_acc`` accumulated motion) and the ``success`` section of
``configs/task.yaml`` (``sc``). The task evaluates every skill's test and each env takes its own
skill's, never after a drop. A new test is one decorated function here and its name in a
:class:`~unicross.registry.Skill` entry.
"""
from __future__ import annotations

from typing import Callable, Dict

import torch

SUCCESS_TESTS: Dict[str, Callable[[dict, dict], torch.Tensor]] = {}


def success_test(name: str):
    """Registers ``fn(m, sc) -> bool [N]`` as the success test ``name``."""
    def deco(fn):
        if name in SUCCESS_TESTS:
            raise ValueError(f"success test {name!r} is registered twice")
        SUCCESS_TESTS[name] = fn
        return fn
    return deco


def get(name: str) -> Callable[[dict, dict], torch.Tensor]:
    if name not in SUCCESS_TESTS:
        raise ValueError(f"no success test {name!r}; registered: {sorted(SUCCESS_TESTS)}")
    return SUCCESS_TESTS[name]


@success_test("lifted_with_contacts")
def lifted_with_contacts(m: dict, sc: dict) -> torch.Tensor:
    """Grasp: the object lifted above its start height (``grasp.lift_success``) with >= 2 links in contact."""
    return m["lifted"] & (m["contact"].sum(-1) >= 2)


@success_test("at_final_pose")
def at_final_pose(m: dict, sc: dict) -> torch.Tensor:
    """Relocate: within ``relocate_pos`` (m) and ``relocate_rot`` (rad) of the final object pose."""
    return (m["pos_err"] < sc["relocate_pos"]) & (m["rot_err"] < sc["relocate_rot"])


@success_test("rotated_past_threshold")
def rotated_past_threshold(m: dict, sc: dict) -> torch.Tensor:
    """Rotate: accumulated rotation about the axis above ``rotate_angle`` (rad)."""
    return m["rot_acc"] > sc["rotate_angle"]


@success_test("translated_past_threshold")
def translated_past_threshold(m: dict, sc: dict) -> torch.Tensor:
    """Translate: accumulated translation along the direction above ``translate_dist`` (m)."""
    return m["trans_acc"] > sc["translate_dist"]
