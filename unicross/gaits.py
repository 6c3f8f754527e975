"""Open-loop periodic finger gaits, and the scripted in-hand policy that runs one until its mode is done.

A gait is 25 numbers in [-1, 1] (6 per finger and the period); finger f's joints (abduction, MCP,
PIP = DIP) follow ``q0 + bias + amplitude * sin(2 pi t / T + phase)`` around the start command q0,
with the distal joints shifted by a loop phase (a closed path in joint space), T in 6..36 control
steps; the wrist holds still. ``benchmarks/gait_search.py`` samples gaits and refines them with a
cross-entropy search; its logs (JSON lines with ``p``, ``meta`` and, for a search, ``score``) are
what :func:`best_gait` reads.

:func:`make_gait_policy` runs a gait until the object's accumulated motion about (rotate) or along
(translate) the env's own axis exceeds the mode's success threshold, then holds the fingers where
they are (the protocol counts a success only if the object is never dropped afterwards). The stop
reads the task's privileged state (the object's velocity in the hand frame), as the scripted grasp
does: a scripted reference, not a learned policy. Four fingers of four joints each (Allegro).
"""
from __future__ import annotations

import gzip
import json
import math
from pathlib import Path
from typing import Tuple

import torch

from unicross import formulation as F
from unicross.observations import contact as observed_contact

NPAR = 6 * 4 + 1
ROTATE_MODES = torch.tensor([F.mode_skill(m) == "rotate" for m in F.MODES])  # [modes]: rotation (else translation)


def gait_period(p) -> float:
    """The period of gait ``p`` in control steps (6..36)."""
    return 6 + 30 * (float(p[24]) + 1) / 2


def gait_offsets(p, t, dtype=torch.float32) -> torch.Tensor:
    """The finger targets of gait ``p`` ([25] in [-1, 1]) minus q0, [..., 16], at the (fractional)
    control steps ``t`` [...], computed in ``dtype`` and returned in float32."""
    period = gait_period(p)
    t = torch.as_tensor(t, dtype=dtype)
    off = torch.zeros(t.shape + (16,), dtype=dtype, device=t.device)
    for f in range(4):
        a_abd, a_mcp, a_dis, ph, loop, bias = (float(v) for v in p[6 * f: 6 * f + 6])
        th = 2 * math.pi * t / period + math.pi * ph
        j = 4 * f
        off[..., j] = 0.3 * a_abd * torch.sin(th)
        off[..., j + 1] = 0.5 * a_mcp * torch.sin(th) + 0.2 * bias
        d = 0.5 * a_dis * torch.sin(th + math.pi * loop) + 0.2 * bias
        off[..., j + 2] = d
        off[..., j + 3] = d
    return off.float()


def reverse_gait(p) -> torch.Tensor:
    """The gait ``p`` run backwards in time: its offsets at step t are ``p``'s at -t (same period,
    amplitudes and bias; phase 1 - phase, loop phase -loop, wrapped into [-1, 1]). A finger loop
    traversed the other way round turns a held object the other way, as far as the motion is
    kinematic (slow, friction holding), so a gait for one direction of an axis is a candidate
    for the opposite direction."""
    q = torch.as_tensor(p, dtype=torch.float64).clone()
    q[3:24:6] = (1.0 - q[3:24:6] + 1.0) % 2.0 - 1.0  # each finger's phase
    q[4:24:6] = (-q[4:24:6] + 1.0) % 2.0 - 1.0  # each finger's loop phase
    return q.to(p.dtype if torch.is_tensor(p) else torch.float32)


def gait_targets(p, t: int, q0: torch.Tensor) -> torch.Tensor:
    """Finger targets [..., 16] of gait ``p`` at control step ``t`` around ``q0`` [..., 16] (the
    offsets in float64, as the searches that found the shipped gaits computed them)."""
    return q0 + gait_offsets(p, float(t), torch.float64).to(q0.device)


SHIPPED_DIR = Path(__file__).resolve().parent / "checkpoints"


GAIT_OPTIONS = {"tracking": str, "lookahead": float, "grid": int, "reverse": int, "guard": int, "guard_max": float}


def split_gait_spec(spec: str) -> Tuple[str, dict]:
    """(gait, options) of ``GAIT[,key=value...]``, the options of :func:`make_gait_policy`
    (``tracking``, ``lookahead``, ``grid``, ``reverse``, ``guard``, ``guard_max``), e.g. ``allegro/rotate_y-,tracking=phase,lookahead=1.5``
    or ``allegro/rotate_y-,reverse=1`` (the y- gait run backwards, :func:`reverse_gait`)."""
    base, *rest = spec.split(",")
    opts = {}
    for kv in rest:
        k, _, v = kv.partition("=")
        if k not in GAIT_OPTIONS or not v:
            raise ValueError(f"gait {spec!r}: options are key=value with key in {sorted(GAIT_OPTIONS)}, got {kv!r}")
        try:
            opts[k] = GAIT_OPTIONS[k](v)
        except ValueError:
            raise ValueError(f"gait {spec!r}: {k} must be a {GAIT_OPTIONS[k].__name__}, got {v!r}") from None
    return base, opts


def resolve_gait(spec: str) -> str:
    """A gait log path, or the shorthand ``<hand>/<mode>`` of a shipped gait
    (``unicross/checkpoints/<hand>/gaits/<mode>.json``, e.g. ``allegro/rotate_y-``); options after a
    comma (:func:`split_gait_spec`) are ignored here."""
    spec = split_gait_spec(spec)[0]
    if Path(spec).exists() or spec.endswith((".json", ".jsonl", ".gz")):
        if not Path(spec).exists():
            raise FileNotFoundError(f"gait log not found: {spec}")
        return spec
    hand, _, mode = spec.partition("/")
    shipped = SHIPPED_DIR / hand / "gaits" / f"{mode}.json"
    if not shipped.exists():
        have = sorted(f"{p.parent.parent.name}/{p.stem}" for p in SHIPPED_DIR.glob("*/gaits/*.json"))
        raise FileNotFoundError(f"gait not found: {spec} (shipped gaits: {have})")
    return str(shipped)


def shipped_gaits(hand: str) -> dict:
    """Mode -> ``<hand>/<mode>`` of every gait shipped for ``hand``."""
    return {p.stem: f"{hand}/{p.stem}" for p in sorted((SHIPPED_DIR / hand / "gaits").glob("*.json"))}


def read_log(path: str) -> list:
    """The rows of a gait log (``.jsonl`` or ``.jsonl.gz``), or the one row of a shipped gait (``.json``)."""
    if path.endswith(".json"):
        with open(path) as f:
            return [json.load(f)]
    with (gzip.open(path, "rt") if path.endswith(".gz") else open(path)) as f:
        return [json.loads(line) for line in f if line.strip()]


def best_gait(path: str) -> Tuple[torch.Tensor, dict]:
    """(gait [25] with the log's amplitude applied to its amplitudes and bias, the row) of the best
    row of a gait log: the highest ``success`` of its selection rows (``--select``), else the
    highest search ``score``."""
    rows = read_log(path)
    key = "success" if any("success" in r for r in rows) else "score"
    rows = [r for r in rows if key in r]
    if not rows:
        raise ValueError(f"{path}: not a gait search log (no row with a 'score' or 'success')")
    row = max(rows, key=lambda r: r[key])
    p = torch.tensor(row["p"], dtype=torch.float32)
    p[:24] *= float(row.get("meta", {}).get("amplitude", 1.0))
    return p, row


def gait_mode(row: dict) -> str:
    """The mode a gait was searched for (e.g. ``rotate_y-``): a shipped gait's ``mode``, else its
    search's ``--skill`` and ``--refine`` axis."""
    if "mode" in row:
        return row["mode"]
    meta = row.get("meta", {})
    if not meta.get("refine"):
        raise ValueError("a gait log without --refine names no mode")
    return f"{meta.get('skill', 'rotate')}_{meta['refine']}"


TRACKING = ("clock", "phase")


GUARD_RATE = 0.02  # rad a control step along the closing direction while a guard tightens the grasp


def make_gait_policy(spec: str, tracking: str = "clock", lookahead: float = 1.0, grid: int = 8, reverse: int = 0,
                     guard: int = 0, guard_max: float = 0.15):
    """The scripted in-hand policy of the best gait in ``spec`` (a log, or a shipped gait's
    ``<hand>/<mode>``; see the module docstring). Options written into ``spec`` after commas
    (``allegro/rotate_y-,tracking=phase,lookahead=1.5``; :func:`split_gait_spec`) override the
    arguments, so ``unicross eval --policy gait:...`` and ``collector.teacher`` reach them.

    ``tracking``: how the gait's target is chosen at each step.

    - ``clock`` (the gait as searched): the target of the control step, whatever the fingers did;
      a hand that lags behind it (the per-step move is clamped) is pulled toward a target that
      runs ahead on the clock, which the observation does not show.
    - ``phase``: the target ``lookahead`` steps ahead of the point of the gait's cycle nearest the
      current joint command (the cycle sampled ``grid`` times per control step): the gait as an
      autonomous limit cycle, whose action depends on the command and the start command q0 only,
      not on a clock. Labels of this kind are a function of what a policy can observe (up to q0,
      fixed per episode), so a network can fit them on states it has not seen.

    ``reverse=1``: the gait run backwards in time (:func:`reverse_gait`); the stop still follows
    the env's own axis, so ``allegro/rotate_y-,reverse=1`` on a y+ env stops at a y+ success.

    ``guard=K`` (0: off): a reaction to slipping, from the observation's contact flags. While fewer than
    K contact links touch the object, the gait pauses (its clock, or with ``tracking=phase`` its
    lookahead, stands still) and the fingers close along the hand's closing direction by
    ``GUARD_RATE`` a step, up to ``guard_max`` rad in all; the gait then goes on around the tightened
    grasp (the tightening stays).
    """
    spec, opts = split_gait_spec(spec)
    tracking, lookahead, grid = opts.get("tracking", tracking), opts.get("lookahead", lookahead), opts.get("grid", grid)
    reverse = opts.get("reverse", reverse)
    guard, guard_max = opts.get("guard", guard), opts.get("guard_max", guard_max)
    if guard < 0 or guard_max < 0:
        raise ValueError(f"gait guard and guard_max must be >= 0, got {guard} and {guard_max}")
    if tracking not in TRACKING:
        raise ValueError(f"gait tracking must be one of {TRACKING}, got {tracking!r}")
    if grid < 1:
        raise ValueError(f"gait grid must be >= 1, got {grid}")
    if reverse not in (0, 1):
        raise ValueError(f"gait reverse must be 0 or 1, got {reverse}")
    p, row = best_gait(resolve_gait(spec))
    if reverse:  # a gait for the opposite direction of the same axis
        p = reverse_gait(p)
        mode = gait_mode(row)
        row = dict(row, mode=mode[:-1] + {"+": "-", "-": "+"}[mode[-1]], reversed_from=mode, p=p.tolist(),
                   meta=dict(row.get("meta", {}), amplitude=1.0))  # p has the log's amplitude applied already
    period = gait_period(p)
    taus = torch.arange(int(math.ceil(period * grid))) / grid
    cycle = gait_offsets(p, taus[taus < period])  # [K, 16] offsets over one period
    state = {}

    def policy(obs, u):
        if u.hand_spec.dof - 6 != 16:
            raise ValueError(f"gait policy: written for four fingers of four joints (Allegro), "
                             f"hand {u.hand_spec.name!r} has {u.hand_spec.dof - 6} finger joints")
        t = int(u.elapsed_steps[0])
        if t == 0 or state.get("env") is not u:
            is_rot = ROTATE_MODES.to(u.device)[u.mode.long()]
            sc = u.cfg["success"]
            state.update(env=u, q0=u.command[:, 6:].clone(), is_rot=is_rot,
                         threshold=torch.where(is_rot, sc["rotate_angle"], sc["translate_dist"]),
                         motion=torch.zeros(u.num_envs, device=u.device),
                         done=torch.zeros(u.num_envs, dtype=torch.bool, device=u.device))
            if guard > 0:  # the guard's own clock, its tightening so far, and the direction it tightens
                from unicross.scripted_grasp import closing_direction
                state.update(clock=torch.zeros(u.num_envs, device=u.device),
                             tight=torch.zeros(u.num_envs, 1, device=u.device),
                             closing=closing_direction(u.hand_spec).to(u.device)[None])
        else:  # the motion of the step just taken, about / along the env's axis
            vel = torch.where(state["is_rot"][:, None], u.obj_angvel_h, u.obj_vel_h)
            state["motion"] += (vel * u.axis).sum(-1) * u.control_dt
        state["done"] |= state["motion"] > state["threshold"]
        a = torch.zeros(u.num_envs, u.hand_spec.dof, device=u.device)
        centre = state["q0"]  # the gait's centre: the start command, tightened by the guard
        if guard > 0:
            slipping = (observed_contact(u) > 0).sum(-1) < guard  # the observation's contact flags
            state["tight"] = torch.where(slipping[:, None], (state["tight"] + GUARD_RATE).clamp(max=guard_max),
                                         state["tight"])
            centre = centre + state["tight"] * state["closing"]
        if tracking == "clock":
            if guard > 0:  # the gait's own clock, which stands still while the guard tightens
                state["clock"] += (~slipping).float()
                target = centre + gait_offsets(p, state["clock"].double()).to(u.device)
            else:
                target = gait_targets(p, t + 1, state["q0"])
        else:
            rel = u.command[:, 6:] - centre  # [N, 16]
            k = ((cycle.to(u.device)[None] - rel[:, None]) ** 2).sum(-1).argmin(1)  # [N]
            ahead = torch.where(slipping, 0.0, lookahead) if guard > 0 else lookahead
            target = centre + gait_offsets(p, taus.to(u.device)[k] + ahead)
        step = ((target - u.command[:, 6:]) / u.action_scale[6:]).clamp(-1, 1)
        a[:, 6:] = torch.where(state["done"][:, None], torch.zeros_like(step), step)
        return a
    policy.gait_row = row
    return policy
