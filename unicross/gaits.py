"""Open-loop periodic finger gaits, and the scripted in-hand policy that runs one until its mode is done.

A gait is 6 numbers in [-1, 1] per finger and the period (25 for Allegro's four fingers); finger f's
joints (abduction, proximal flexion, distal flexion joints moving together) follow
``q0 + bias + amplitude * sin(2 pi t / T + phase)`` around the start command q0, with the distal joints
shifted by a loop phase (a closed path in joint space), T in 6..36 control steps; the wrist holds still.
Which joints of a finger play which part is the hand's :func:`gait_layout` (a four-joint finger:
abduction, proximal, then the two distal joints, as Allegro's; other fingers name theirs in the hand's
``gait_joints``), and flexion follows the hand's closing direction, so a positive bias tightens. ``benchmarks/gait_search.py`` samples gaits and refines them with a
cross-entropy search; its logs (JSON lines with ``p``, ``meta`` and, for a search, ``score``) are
what :func:`best_gait` reads.

:func:`make_gait_policy` runs a gait until the object's accumulated motion about (rotate) or along
(translate) the env's own axis exceeds the mode's success threshold, then holds the fingers where
they are (the protocol counts a success only if the object is never dropped afterwards). The stop
reads the task's privileged state (the object's velocity in the hand frame), as the scripted grasp
does: a scripted reference, not a learned policy. A gait is searched for one hand (its log's ``meta.hand``,
Allegro where a log names none) and runs on that hand only.
"""
from __future__ import annotations

import functools
import gzip
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Tuple

import torch

from unicross import formulation as F
from unicross.observations import contact as observed_contact

NPAR = 6 * 4 + 1  # the length of an Allegro gait (four fingers); other hands: gait_layout(spec).npar
ROTATE_MODES = torch.tensor([F.mode_skill(m) == "rotate" for m in F.MODES])  # [modes]: rotation (else translation)


@dataclass(frozen=True)
class GaitLayout:
    """The finger joints a gait moves, per finger of the hand (indices into its finger joints): the
    abduction joint, the proximal flexion joint and the distal flexion joints, with the sign that
    flexes each along the hand's closing direction."""
    hand: str
    n_joints: int
    fingers: Tuple[Tuple[int, int, Tuple[int, ...], float, Tuple[float, ...]], ...]  # (abd, prox, distal, sign_prox, signs_distal)

    @property
    def npar(self) -> int:
        """Parameters of a gait for this hand: 6 per finger and the period."""
        return 6 * len(self.fingers) + 1


def gait_layout(hand_spec) -> GaitLayout:
    """The :class:`GaitLayout` of a hand: per finger its ``gait_joints`` (abduction, proximal, distal...)
    where the hand names them, else its joints in order (a four-joint finger as Allegro's: abduction,
    proximal, two distal); flexion signs from the hand's closing direction (+1 where it has none)."""
    index = {j: i for i, j in enumerate(hand_spec.finger_joints)}
    closing = hand_spec.closing_deltas()
    named = hand_spec.gait_joints or {}
    fingers = []
    for finger, joints in hand_spec.fingers.items():
        js = named.get(finger, joints)
        if len(js) < 3:
            raise ValueError(f"hand {hand_spec.name!r}: a gait needs an abduction, a proximal and a distal joint "
                             f"per finger; finger {finger!r} gives {list(js)} (name them in the hand's gait_joints)")
        ids = [index[j] for j in js]
        sign = [-1.0 if closing[i] < 0 else 1.0 for i in ids]
        fingers.append((ids[0], ids[1], tuple(ids[2:]), sign[1], tuple(sign[2:])))
    return GaitLayout(hand_spec.name, len(hand_spec.finger_joints), tuple(fingers))


# Allegro's layout without reading its description: its fingers are four joints each, flexing positive
ALLEGRO_LAYOUT = GaitLayout("allegro", 16, tuple((4 * f, 4 * f + 1, (4 * f + 2, 4 * f + 3), 1.0, (1.0, 1.0))
                                                 for f in range(4)))


def _check_length(p, layout: GaitLayout) -> None:
    if len(p) != layout.npar:
        raise ValueError(f"a gait of {len(p)} numbers is not one for hand {layout.hand!r} ({len(layout.fingers)} "
                         f"fingers: {layout.npar} numbers)")


def gait_period(p) -> float:
    """The period of gait ``p`` in control steps (6..36): its last number."""
    return 6 + 30 * (float(p[-1]) + 1) / 2


def gait_offsets(p, t, dtype=torch.float32, layout: GaitLayout = ALLEGRO_LAYOUT) -> torch.Tensor:
    """The finger targets of gait ``p`` ([layout.npar] in [-1, 1]) minus q0, [..., layout.n_joints], at the
    (fractional) control steps ``t`` [...], computed in ``dtype`` and returned in float32."""
    _check_length(p, layout)
    period = gait_period(p)
    t = torch.as_tensor(t, dtype=dtype)
    off = torch.zeros(t.shape + (layout.n_joints,), dtype=dtype, device=t.device)
    for f, (j_abd, j_prox, j_dis, s_prox, s_dis) in enumerate(layout.fingers):
        a_abd, a_mcp, a_dis, ph, loop, bias = (float(v) for v in p[6 * f: 6 * f + 6])
        th = 2 * math.pi * t / period + math.pi * ph
        off[..., j_abd] = 0.3 * a_abd * torch.sin(th)
        off[..., j_prox] = s_prox * (0.5 * a_mcp * torch.sin(th) + 0.2 * bias)
        d = 0.5 * a_dis * torch.sin(th + math.pi * loop) + 0.2 * bias
        for j, s in zip(j_dis, s_dis):
            off[..., j] = s * d
    return off.float()


def reverse_gait(p) -> torch.Tensor:
    """The gait ``p`` run backwards in time: its offsets at step t are ``p``'s at -t (same period,
    amplitudes and bias; phase 1 - phase, loop phase -loop, wrapped into [-1, 1]). A finger loop
    traversed the other way round turns a held object the other way, as far as the motion is
    kinematic (slow, friction holding), so a gait for one direction of an axis is a candidate
    for the opposite direction."""
    q = torch.as_tensor(p, dtype=torch.float64).clone()
    q[3:-1:6] = (1.0 - q[3:-1:6] + 1.0) % 2.0 - 1.0  # each finger's phase
    q[4:-1:6] = (-q[4:-1:6] + 1.0) % 2.0 - 1.0  # each finger's loop phase
    return q.to(p.dtype if torch.is_tensor(p) else torch.float32)


def gait_targets(p, t: int, q0: torch.Tensor, layout: GaitLayout = ALLEGRO_LAYOUT) -> torch.Tensor:
    """Finger targets [..., n_joints] of gait ``p`` at control step ``t`` around ``q0`` [..., n_joints] (the
    offsets in float64, as the searches that found the shipped gaits computed them)."""
    return q0 + gait_offsets(p, float(t), torch.float64, layout).to(q0.device)


def phase_cycle(p, grid: int = 8, layout: GaitLayout = ALLEGRO_LAYOUT):
    """One period of gait ``p`` sampled ``grid`` times per control step: (times [K], offsets [K, n_joints]),
    what phase tracking (:func:`make_gait_policy`, ``tracking=phase``) finds the hand on."""
    period = gait_period(p)
    taus = torch.arange(int(math.ceil(period * grid))) / grid
    taus = taus[taus < period]
    return taus, gait_offsets(p, taus, layout=layout)


def phase_offsets(p, taus: torch.Tensor, cycle: torch.Tensor, rel: torch.Tensor, ahead,
                  layout: GaitLayout = ALLEGRO_LAYOUT) -> torch.Tensor:
    """Phase tracking's target offsets [N, n_joints]: ``ahead`` control steps (a number or [N]) past the point of
    the cycle (:func:`phase_cycle`) nearest the command's offsets ``rel`` [N, n_joints] from the gait's centre."""
    k = ((cycle[None] - rel[:, None]) ** 2).sum(-1).argmin(1)  # [N]
    return gait_offsets(p, taus[k] + ahead, layout=layout)


def gait_hand(row: dict) -> str:
    """The hand a gait was searched for: a shipped gait's ``hand``, else its log's ``meta.hand``
    (Allegro for the logs written before searches named one)."""
    return row.get("hand") or row.get("meta", {}).get("hand") or "allegro"


@functools.lru_cache(maxsize=None)
def layout_of(hand: str) -> GaitLayout:
    """The :class:`GaitLayout` of a hand by name (its description read once per process)."""
    if hand == "allegro":
        return ALLEGRO_LAYOUT
    from unicross.robots.hand import load_hand
    return gait_layout(load_hand(hand))


SHIPPED_DIR = Path(__file__).resolve().parent / "checkpoints"


GAIT_OPTIONS = {"tracking": str, "lookahead": float, "grid": int, "reverse": int, "guard": int, "guard_max": float,
                "stop": int, "drift": float}


def split_gait_spec(spec: str) -> Tuple[str, dict]:
    """(gait, options) of ``GAIT[,key=value...]``, the options of :func:`make_gait_policy`
    (``tracking``, ``lookahead``, ``grid``, ``reverse``, ``guard``, ``guard_max``, ``stop``, ``drift``), e.g. ``allegro/rotate_y-,tracking=phase,lookahead=1.5``
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
    """(gait [npar] with the log's amplitude applied to its amplitudes and bias, the row) of the best
    row of a gait log: the highest ``success`` of its selection rows (``--select``), else the
    highest search ``score``."""
    rows = read_log(path)
    key = "success" if any("success" in r for r in rows) else "score"
    rows = [r for r in rows if key in r]
    if not rows:
        raise ValueError(f"{path}: not a gait search log (no row with a 'score' or 'success')")
    row = max(rows, key=lambda r: r[key])
    p = torch.tensor(row["p"], dtype=torch.float32)
    p[:-1] *= float(row.get("meta", {}).get("amplitude", 1.0))
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
                     guard: int = 0, guard_max: float = 0.15, stop: int = 1, drift: float = 0.0):
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

    ``drift=D`` (metres, 0: off): the same reaction, also while the object is more than D from its target
    position in the hand (the rotate formulation fixes it at the start position; both are in the observation's
    goal) and the grasp has not yet tightened by ``guard_max``, so a grasp the gait is loosening tightens before
    the object has slid out. Measured once on the y- gait without the stop (2026-12-03, training objects, n = 120;
    `docs/record/rotation_gaits.md`): no gain.

    ``stop=0``: the gait never stops (no privileged read of the object's motion): it keeps cycling for
    the whole episode, as the paper's policies keep turning. Its action is then a function of the
    command and q0 alone (with ``tracking=phase``), with no unobservable switch to standing still,
    which is what a network that sees only the observation can copy (``benchmarks/gait_clone.py``).
    A gait searched with ``gait_search.py --no-stop`` runs this way unless the spec says ``stop=1``.
    """
    spec, opts = split_gait_spec(spec)
    tracking, lookahead, grid = opts.get("tracking", tracking), opts.get("lookahead", lookahead), opts.get("grid", grid)
    reverse = opts.get("reverse", reverse)
    guard, guard_max = opts.get("guard", guard), opts.get("guard_max", guard_max)
    stop, drift = opts.get("stop", stop), opts.get("drift", drift)
    if stop not in (0, 1):
        raise ValueError(f"gait stop must be 0 or 1, got {stop}")
    if guard < 0 or guard_max < 0 or drift < 0:
        raise ValueError(f"gait guard, guard_max and drift must be >= 0, got {guard}, {guard_max} and {drift}")
    guarded = guard > 0 or drift > 0
    if tracking not in TRACKING:
        raise ValueError(f"gait tracking must be one of {TRACKING}, got {tracking!r}")
    if grid < 1:
        raise ValueError(f"gait grid must be >= 1, got {grid}")
    if reverse not in (0, 1):
        raise ValueError(f"gait reverse must be 0 or 1, got {reverse}")
    p, row = best_gait(resolve_gait(spec))
    searched = row.get("meta", {})  # a gait searched with phase tracking runs with it unless the spec says otherwise
    if "tracking" not in opts and searched.get("tracking", "clock") != "clock":
        tracking = searched["tracking"]
        lookahead = opts.get("lookahead", searched.get("lookahead", lookahead))
    if "stop" not in opts and searched.get("no_stop"):  # a gait searched without the stop runs without it
        stop = 0
    if reverse:  # a gait for the opposite direction of the same axis
        p = reverse_gait(p)
        mode = gait_mode(row)
        row = dict(row, mode=mode[:-1] + {"+": "-", "-": "+"}[mode[-1]], reversed_from=mode, p=p.tolist(),
                   meta=dict(row.get("meta", {}), amplitude=1.0))  # p has the log's amplitude applied already
    hand = gait_hand(row)
    layout = layout_of(hand)
    _check_length(p, layout)
    taus, cycle = phase_cycle(p, grid, layout)
    state = {}

    def policy(obs, u):
        if u.hand_spec.name != hand:
            raise ValueError(f"gait policy: a gait for hand {hand!r} cannot run hand {u.hand_spec.name!r}")
        t = int(u.elapsed_steps[0])
        if t == 0 or state.get("env") is not u:
            is_rot = ROTATE_MODES.to(u.device)[u.mode.long()]
            sc = u.cfg["success"]
            state.update(env=u, q0=u.command[:, 6:].clone(), is_rot=is_rot,
                         threshold=torch.where(is_rot, sc["rotate_angle"], sc["translate_dist"]),
                         motion=torch.zeros(u.num_envs, device=u.device),
                         done=torch.zeros(u.num_envs, dtype=torch.bool, device=u.device))
            if guarded:  # the guard's own clock, its tightening so far, and the direction it tightens
                from unicross.scripted_grasp import closing_direction
                state.update(clock=torch.zeros(u.num_envs, device=u.device),
                             tight=torch.zeros(u.num_envs, 1, device=u.device),
                             closing=closing_direction(u.hand_spec).to(u.device)[None])
        else:  # the motion of the step just taken, about / along the env's axis
            vel = torch.where(state["is_rot"][:, None], u.obj_angvel_h, u.obj_vel_h)
            state["motion"] += (vel * u.axis).sum(-1) * u.control_dt
        if stop:
            state["done"] |= state["motion"] > state["threshold"]
        a = torch.zeros(u.num_envs, u.hand_spec.dof, device=u.device)
        centre = state["q0"]  # the gait's centre: the start command, tightened by the guard
        if guarded:
            slipping = (observed_contact(u) > 0).sum(-1) < guard  # the observation's contact flags
            if drift > 0:  # the object's distance from its target position in the hand (the goal's fixed slot);
                # a drift persists, so it pauses the gait only while the grasp can still tighten
                drifting = torch.linalg.norm(u.cur_rel.x_oh - u.targets.x_oh, dim=-1) > drift
                slipping = slipping | (drifting & (state["tight"][:, 0] < guard_max))
            state["tight"] = torch.where(slipping[:, None], (state["tight"] + GUARD_RATE).clamp(max=guard_max),
                                         state["tight"])
            centre = centre + state["tight"] * state["closing"]
        if tracking == "clock":
            if guarded:  # the gait's own clock, which stands still while the guard tightens
                state["clock"] += (~slipping).float()
                target = centre + gait_offsets(p, state["clock"].double(), layout=layout).to(u.device)
            else:
                target = gait_targets(p, t + 1, state["q0"], layout)
        else:
            ahead = torch.where(slipping, 0.0, lookahead) if guarded else lookahead
            target = centre + phase_offsets(p, taus.to(u.device), cycle.to(u.device), u.command[:, 6:] - centre,
                                            ahead, layout)
        step = ((target - u.command[:, 6:]) / u.action_scale[6:]).clamp(-1, 1)
        a[:, 6:] = torch.where(state["done"][:, None], torch.zeros_like(step), step)
        return a
    policy.gait_row = row
    return policy
