"""Finger sequences: scripted in-hand behaviours written as sums of one-finger sweeps.

A sequence is a ``+``-joined list of terms ``finger:k:rate:START:END``: the ``k`` most distal joints of
``finger`` move their targets ``rate`` rad per control step along the hand's closing direction
(negative opens; :func:`unicross.audit.finger_sweep_action`), while the term is active:

- ``finger:k:rate:t0:t1`` (integers): for control steps ``t0 <= t < t1`` of the episode (a clock,
  which the observation does not show);
- ``finger:k:rate:@other:theta``: from the first step at which the joint command of ``other``'s most
  distal joint has reached ``theta`` rad, to the episode's end (a state trigger: the command is part
  of the observation's s^h, so a network can represent the switch).

A term may name ``base`` for ``k``: ``finger:base:rate:...`` moves only the finger's first joint from the palm (the
Allegro fingers' spread joints, its thumb's rotation), which the closing direction leaves still, ``rate`` rad per
control step along that joint's own axis (negative: the other way).

Translate z- example (``docs/runs/translate_zm_reference/``): ``index:2:0.05:0:400+ring:2:0.05:@index:0.9``
curls the index finger's two distal joints (the shipped physical reference) and, once the index's
distal command has reached 0.9 rad, the ring finger's too. Per-env batched: each env has its own
clock and trigger.

A teacher may also pick its sequence by the object: ``width<W?THIN|THICK`` runs the sequence ``THIN``
on objects whose smaller width across their long axis (:func:`cross_width`, m) is under ``W`` and
``THICK`` on the others. The width is privileged (read from the env's object specs, not the
observation): such a sequence is a teacher for a clone, whose network has to infer the width
(``docs/runs/translate_zm_reference/thickness/``).
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import List, Optional, Tuple

import torch


@dataclass(frozen=True)
class Sweep:
    finger: str
    k: int
    rate: float
    t0: int = 0                    # clock window [t0, t1) (used when ``trigger`` is None)
    t1: int = 0
    trigger: Optional[str] = None  # finger whose most distal command starts the sweep
    theta: float = 0.0             # ... once it has reached theta rad
    base: bool = False             # the finger's first joint alone, along its own axis (``k`` is then 1)


_SWITCH = re.compile(r"width<([^?]*)\?([^|]*)\|([^|]*)")


def split_switch(spec: str) -> Optional[Tuple[float, str, str]]:
    """``(W, THIN, THICK)`` of a switched spec ``width<W?THIN|THICK``, or None for a plain sequence."""
    if not spec.startswith("width<"):
        return None
    m = _SWITCH.fullmatch(spec)
    if m is None:
        raise ValueError(f"switched sequence {spec[:40]!r}...: write width<W?THIN|THICK (W in m)")
    try:
        w = float(m.group(1))
    except ValueError:
        raise ValueError(f"switched sequence: the width {m.group(1)!r} must be a number (m)") from None
    if not w > 0:
        raise ValueError(f"switched sequence: the width {w} must be > 0 (m)")
    return w, m.group(2), m.group(3)


def cross_width(obj) -> float:
    """The smaller width (m) of ``obj`` (an :class:`unicross.objects.ObjectSpec`) across its long axis x:
    ``min(dims[1:])`` (a box's two widths, a cylinder's or prism's diameter); a sphere's diameter."""
    d = obj.dims
    if not d:
        raise ValueError(f"object {obj.name!r} has no dims: a switched sequence needs a primitive shape")
    return float(min(d[1:])) if len(d) > 1 else float(d[0])


def parse_sequence(spec: str) -> List[Sweep]:
    """The sweeps of ``spec`` (of both branches for a switched spec); a malformed spec raises
    ``ValueError`` saying which term and why."""
    switch = split_switch(spec)
    if switch is not None:
        return parse_sequence(switch[1]) + parse_sequence(switch[2])
    sweeps = []
    for term in spec.split("+"):
        parts = term.split(":")
        if len(parts) != 5:
            raise ValueError(f"sequence term {term!r}: write finger:k:rate:t0:t1 or finger:k:rate:@finger:theta")
        finger, k, rate, start, end = parts
        base = k == "base"
        try:
            k_, rate_ = 1 if base else int(k), float(rate)
            if start.startswith("@"):
                sweeps.append(Sweep(finger, k_, rate_, trigger=start[1:], theta=float(end), base=base))
            else:
                sweeps.append(Sweep(finger, k_, rate_, t0=int(start), t1=int(end), base=base))
        except ValueError:
            raise ValueError(f"sequence term {term!r}: k (or base) and the window must be integers, rate and theta "
                             f"numbers") from None
        if k_ < 1:
            raise ValueError(f"sequence term {term!r}: k (joints moved) must be >= 1")
    return sweeps


def check_sequence(spec: str, hand_spec) -> List[Sweep]:
    """:func:`parse_sequence`, with the fingers and joint counts checked against ``hand_spec``."""
    sweeps = parse_sequence(spec)
    for s in sweeps:
        for f in (s.finger, s.trigger):
            if f is not None and f not in hand_spec.fingers:
                raise ValueError(f"sequence {spec!r}: hand {hand_spec.name!r} has no finger {f!r}; "
                                 f"its fingers: {list(hand_spec.fingers)}")
        if s.k > len(hand_spec.fingers[s.finger]):
            raise ValueError(f"sequence {spec!r}: finger {s.finger!r} has {len(hand_spec.fingers[s.finger])} joints, "
                             f"not {s.k}")
    return sweeps


def _action_index(hand_spec, finger: str, i: int) -> int:
    """The action dimension of ``finger``'s joint ``i`` (0: its first from the palm, -1: its most distal), after
    the 6 wrist dimensions."""
    return 6 + hand_spec.finger_joints.index(hand_spec.fingers[finger][i])


def sweep_action(hand_spec, s: Sweep) -> torch.Tensor:
    """The normalised action [dof] of one sweep: :func:`unicross.audit.finger_sweep_action` for ``k`` distal joints;
    for ``base``, ``rate`` rad per step on the finger's first joint alone (clipped to the action's range)."""
    from unicross.audit import finger_sweep_action
    if not s.base:
        return finger_sweep_action(hand_spec, s.rate, (s.finger, s.k))
    a = torch.zeros(hand_spec.dof)
    j = _action_index(hand_spec, s.finger, 0)
    a[j] = max(-1.0, min(1.0, s.rate / float(hand_spec.action_scales()[j])))
    return a


def make_sequence_policy(spec: str):
    """A policy ``(obs, env) -> action [n, dof]`` that sums the sweeps of ``spec`` active at each env's
    control step (see the module docstring); triggers latch per env and clear at its step 0. A switched
    spec runs each env's branch by its object's :func:`cross_width`."""
    parse_sequence(spec)  # a malformed spec fails before any simulation
    switch = split_switch(spec)
    if switch is not None:
        return _switched_policy(*switch)
    cache = {}

    def policy(obs, u) -> torch.Tensor:
        if cache.get("env") is not u:
            sweeps = check_sequence(spec, u.hand_spec)
            terms = []
            for s in sweeps:
                a = sweep_action(u.hand_spec, s).to(u.device)
                j = _action_index(u.hand_spec, s.trigger, -1) if s.trigger else None
                terms.append((a, s, j))
            cache.update(env=u, terms=terms,
                         on=torch.zeros(u.num_envs, len(terms), dtype=torch.bool, device=u.device))
        t = u.elapsed_steps.to(u.device)[:, None]  # [n, 1]: the control step about to be taken
        on = cache["on"]
        on &= t != 0  # a new episode clears its triggers
        a = torch.zeros(u.num_envs, u.hand_spec.dof, device=u.device)
        for i, (sweep, s, j) in enumerate(cache["terms"]):
            if j is None:
                active = (t >= s.t0) & (t < s.t1)
            else:
                on[:, i] |= u.command[:, j] >= s.theta
                active = on[:, i:i + 1]
            a = a + sweep * active
        return a.clamp(-1.0, 1.0)
    return policy


def _switched_policy(width: float, thin: str, thick: str):
    thin_policy, thick_policy = make_sequence_policy(thin), make_sequence_policy(thick)
    cache = {}

    def policy(obs, u) -> torch.Tensor:
        objects = u.env_objects  # rebuilt with the scene: a new list, a new mask
        if cache.get("objects") is not objects:
            cache.update(objects=objects, thin=torch.tensor([cross_width(o) < width for o in objects],
                                                            device=u.device)[:, None])
        return torch.where(cache["thin"], thin_policy(obs, u), thick_policy(obs, u))
    return policy
