"""Observation terms, registered by name; ``configs/task.yaml`` (``observation``) lists the terms of
each group in order.

The policy network reads three groups (paper §3.1.3): ``hand`` (s^h: joint readings and the last
command), ``object`` (s^o: per-link contact flags, forces and distance vectors) and ``goal`` (g:
mode one-hot, axis, current and target relational poses). A term is a function ``fn(env) -> [N, k]``
of the task after ``evaluate()``: most read ``env._obs_parts``, the step math's observation parts
with the paper's ablations already applied (``StepMath._observation_parts``). The ``hand`` and
``goal`` groups reach the env's observation concatenated, ``object`` as a dict of its named terms.

Adding a term is one decorated function here and its name in a group of ``configs/task.yaml``;
the observation sizes follow (checkpoints store them and refuse a different layout).
"""
from __future__ import annotations

from typing import Callable, Dict, List

import torch

GROUPS = ("hand", "object", "goal")
OBSERVATION_TERMS: Dict[str, Callable] = {}


def observation_term(name: str):
    """Registers ``fn(env) -> [N, k]`` as the observation term ``name``."""
    def deco(fn):
        if name in OBSERVATION_TERMS:
            raise ValueError(f"observation term {name!r} is registered twice")
        OBSERVATION_TERMS[name] = fn
        return fn
    return deco


def resolve(layout: dict) -> Dict[str, List[Callable]]:
    """The term functions of each group of an ``observation`` config section (clear errors for an
    unknown group or term, or a group left empty)."""
    if set(layout) != set(GROUPS):
        raise ValueError(f"observation groups must be exactly {list(GROUPS)}, got {list(layout)}")
    out = {}
    for group in GROUPS:
        names = list(layout[group] or [])
        unknown = [n for n in names if n not in OBSERVATION_TERMS]
        if unknown:
            raise ValueError(f"unknown observation term(s) {unknown} in group {group!r}; "
                             f"registered: {sorted(OBSERVATION_TERMS)}")
        if not names:
            raise ValueError(f"observation group {group!r} has no term")
        out[group] = [(n, OBSERVATION_TERMS[n]) for n in names]
    return out


def observe(env, terms: Dict[str, List[Callable]]) -> dict:
    """The observation of ``env`` from resolved ``terms``: hand and goal concatenated, object by name."""
    return dict(hand=torch.cat([fn(env) for _, fn in terms["hand"]], dim=-1),
                object={n: fn(env) for n, fn in terms["object"]},
                goal=torch.cat([fn(env) for _, fn in terms["goal"]], dim=-1))


def observe_flat(env, terms: Dict[str, List[Callable]]) -> torch.Tensor:
    """The ``state`` observation [N, D]: what ManiSkill's flattening of ``{"agent": {}, "extra":
    observe(env, terms)}`` gives (hand terms, object terms, goal terms, in order), in one ``cat``
    that runs inside the compiled step (``StepMath._step_math_eager``)."""
    n = env.num_envs
    return torch.cat([fn(env).reshape(n, -1) for group in GROUPS for _, fn in terms[group]], dim=-1)


def obs_layout(obs: dict) -> list:
    """The widths of ``observe``'s output in ``observe_flat``'s order: ``[(group, width)]`` for the
    hand and goal groups, ``[(group, [(term, width)])]`` for the object group."""
    return [(g, [(n, x.shape[-1]) for n, x in obs[g].items()] if isinstance(obs[g], dict) else obs[g].shape[-1])
            for g in GROUPS]


def unflatten(flat: torch.Tensor, layout: list) -> dict:
    """``observe``'s dict from ``observe_flat``'s tensor (views into it)."""
    widths = [w for _, ws in layout for w in ([w for _, w in ws] if isinstance(ws, list) else [ws])]
    parts = iter(torch.split(flat, widths, dim=-1))
    return {g: {n: next(parts) for n, _ in ws} if isinstance(ws, list) else next(parts) for g, ws in layout}


@observation_term("joint_pos")
def joint_pos(env) -> torch.Tensor:
    """Actuated joint positions (virtual wrist + fingers) with the episode's reading noise."""
    return env._obs_parts["qpos"] + env.obs_noise


@observation_term("command")
def command(env) -> torch.Tensor:
    """The joint command of the last action (the PD targets)."""
    return env.command


@observation_term("contact")
def contact(env) -> torch.Tensor:
    """Per contact link: 1 when its contact force with the object exceeds the threshold."""
    return env._obs_parts["contact"]


@observation_term("force")
def force(env) -> torch.Tensor:
    """Per contact link: the norm of its contact force with the object, clipped (N)."""
    return env._obs_parts["force"]


@observation_term("distance")
def distance(env) -> torch.Tensor:
    """Per contact link: the vector to the object's closest surface point, hand frame (m)."""
    return env._obs_parts["distance"]


@observation_term("goal")
def goal(env) -> torch.Tensor:
    """The mode one-hot, the task axis and the current and target relational poses."""
    return env._obs_parts["goal"]
