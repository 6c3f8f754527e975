"""Reward terms of the paper (§3.1.4) as named functions; weights come from ``configs/reward.yaml``.

``r = r_goal + r_track + r_reg`` with
  r_goal  = contact + motion (+ success: ours, a per-step bonus while the mode's success holds;
            + progress: ours, the decrease of the object's error to its final pose (relocate);
            + settle: ours, the object's speed in the hand while the success holds;
            all 0 in the paper, see configs/reward.yaml)
  r_track = Σ w · error over the six relational poses (position errors saturate at ``track.max_pos_error``)
  r_reg   = pose + wrist_velocity + energy + drop

Each term is one function registered with :func:`reward_term` (its name and how it reads its
coefficients from the config); the task sums exactly the registered terms and writes each to
``info["reward_<name>"]``, and the RL env keys and training logs list them from the registry. A new
term is one decorated function plus its coefficients in ``configs/reward.yaml``.

Per-skill coefficients become per-mode tensors (:func:`per_mode`), so one batched call serves
every env whatever its mode.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Dict, Optional, Tuple

import torch

from unicross.formulation import MODES, mode_skill
from unicross.geometry import quat_angle

TRACK_WEIGHTS = dict(x_or="w_opr", q_or="w_oqr", x_oh="w_oph", q_oh="w_oqh", x_hr="w_hpr", q_hr="w_hqr")


@dataclass(frozen=True)
class RewardTerm:
    """One reward term: ``fn(m, c, mode) -> [B]`` over the step's measurements ``m`` (see
    ``UniCrossEnv._step_math_eager``), its coefficients ``c`` and the per-env mode; ``coefficients(cfg,
    device)`` reads ``c`` from the reward config once per env."""

    name: str
    fn: Callable[[dict, dict, torch.Tensor], torch.Tensor]
    coefficients: Callable[[dict, object], dict]


REGISTRY: Dict[str, RewardTerm] = {}


def reward_term(name: str, coefficients: Callable[[dict, object], dict]):
    """Registers the decorated ``fn(m, c, mode)`` as the reward term ``name``: the task sums it,
    writes it to ``info["reward_<name>"]``, and the RL env keys and training logs carry it."""
    def deco(fn):
        if name in REGISTRY:
            raise ValueError(f"reward term {name!r} is registered twice")
        REGISTRY[name] = RewardTerm(name, fn, coefficients)
        return fn
    return deco


def term_names() -> Tuple[str, ...]:
    """The registered reward terms, in registration order."""
    return tuple(REGISTRY)


def per_mode(by_skill: dict, device, key: Optional[str] = None) -> torch.Tensor:
    """[NUM_MODES] tensor of a per-skill coefficient (``by_skill[skill]`` or ``by_skill[skill][key]``)."""
    return torch.tensor([float(by_skill[mode_skill(m)] if key is None else by_skill[mode_skill(m)][key])
                         for m in MODES], dtype=torch.float32, device=device)


@reward_term("contact", lambda cfg, dev: dict(**{k: per_mode(cfg["contact"], dev, k) for k in ("w_dis", "w_con", "w_f")},
                                              max_distance=float(cfg["contact_max_distance"])))
def contact_reward(m: dict, c: dict, mode: torch.Tensor) -> torch.Tensor:
    """(1/N) Σ_links (-w_dis·min(d_i, max_distance) + w_con·c_i + w_f·f_i) over the [B, L] link
    distances, contact flags and clipped forces. The saturation bounds the term when an object is
    lost (it can fall past the table)."""
    per_link = (-c["w_dis"][mode, None] * m["link_distance"].clamp(max=c["max_distance"])
                + c["w_con"][mode, None] * m["contact"].float() + c["w_f"][mode, None] * m["force_clipped"])
    return per_link.mean(dim=-1)


@reward_term("motion", lambda cfg, dev: dict(w_p=per_mode(cfg["motion"], dev), floor=float(cfg["motion_floor"])))
def motion_reward(m: dict, c: dict, mode: torch.Tensor) -> torch.Tensor:
    """w_p · clamp(v_o^h · d^h, -floor · v_max, v_max) while the object is held (``held``: not
    dropped before this step; ``floor``: ``motion_floor``, inf in the paper). The paper ends an
    episode at a drop, so it never pays motion after one; our training episodes go on past drops
    (``terminate_on_drop: false``), and a lost object falling at 1-3 m/s along the axis made this
    unbounded-below term -10 to -30 per step (translate), noise far larger than anything a held
    object earns. The floor bounds the steps of a fall before the drop is detected."""
    v = torch.minimum(m["speed_along_axis"], m["speed_cap"])
    if math.isfinite(c["floor"]):  # (inf * a zero cap would be NaN)
        v = torch.maximum(v, -c["floor"] * m["speed_cap"])
    return c["w_p"][mode] * v * m["held"].float()


@reward_term("success", lambda cfg, dev: dict(w=per_mode(cfg["success"], dev),
                                              revoke=per_mode(cfg["success_revoke_on_drop"], dev),
                                              max_pos=per_mode(cfg["success_max_pos_error"], dev)))
def success_reward(m: dict, c: dict, mode: torch.Tensor) -> torch.Tensor:
    """w_success · [the mode's success holds at this step], and with ``success_revoke_on_drop``
    minus everything this term has paid in the episode (``success_paid``, before this step) at the
    step the object is dropped: success counts only if the object is never dropped, so an episode
    that passes the threshold and then drops it nets no bonus. With ``success_max_pos_error`` (inf by
    default) the bonus is paid only while the object is within that distance of its final root-frame
    position (``goal_err[:, 0]``), so an object turned by rolling away on an open hand earns none."""
    first_drop = (m["drop"] & m["held"]).float()
    near = m["goal_err"][:, 0] <= c["max_pos"][mode]
    return (c["w"][mode] * (m["success"] & near).float()
            - c["revoke"][mode] * m["success_paid"] * first_drop)


@reward_term("settle", lambda cfg, dev: dict(w=per_mode(cfg["settle"]["weight"], dev),
                                             speed=float(cfg["settle"]["speed"]),
                                             angular_speed=float(cfg["settle"]["angular_speed"]),
                                             cap=float(cfg["settle"]["cap"])))
def settle_reward(m: dict, c: dict, mode: torch.Tensor) -> torch.Tensor:
    """-w · min(max(||v_o^h|| / speed, ||ω_o^h|| / angular_speed), cap) while the mode's success
    holds: the object's speed in the hand frame, in units of the grasp-state dataset's settle test
    (a grasp is kept when both ratios are below 1), so a success with the object still slipping or
    rolling in the hand earns less than a firm one (ours; paper: none)."""
    s = torch.maximum(m["obj_speed_hand"] / c["speed"], m["obj_angspeed_hand"] / c["angular_speed"])
    return -c["w"][mode] * s.clamp(max=c["cap"]) * m["success"].float()


@reward_term("progress", lambda cfg, dev: dict(w_pos=per_mode(cfg["progress"], dev, "w_pos"),
                                               w_rot=per_mode(cfg["progress"], dev, "w_rot"),
                                               max_pos=float(cfg["track"]["max_pos_error"])))
def progress_reward(m: dict, c: dict, mode: torch.Tensor) -> torch.Tensor:
    """w_pos·(e_{t-1} − e_t) + w_rot·(θ_{t-1} − θ_t): how much closer the object came to its final
    pose over the step (``goal_err``/``goal_err_prev`` [B, 2]: position error, saturated at
    ``max_pos``, and angle). A potential-based shaping term (Ng et al., 1999, with γ≈1): over an
    episode it sums to the reduction of the error from start to end, whatever the path."""
    prev, err = m["goal_err_prev"], m["goal_err"]
    pos_prev, pos = prev[:, 0].clamp(max=c["max_pos"]), err[:, 0].clamp(max=c["max_pos"])
    return c["w_pos"][mode] * (pos_prev - pos) + c["w_rot"][mode] * (prev[:, 1] - err[:, 1])


def _track_coefficients(cfg: dict, dev) -> dict:
    t = cfg["track"]
    return dict(pos=torch.tensor([t[TRACK_WEIGHTS[s]] for s in ("x_oh", "x_or", "x_hr")], device=dev),
                rot=torch.tensor([t[TRACK_WEIGHTS[s]] for s in ("q_oh", "q_or", "q_hr")], device=dev),
                max_pos=float(t["max_pos_error"]), off=bool(cfg.get("no_track_reward", False)))


@reward_term("track", _track_coefficients)
def tracking_reward(m: dict, c: dict, mode: torch.Tensor) -> torch.Tensor:
    """Σ w_pos·min(||x - x̂||, max_pos)² + w_rot·A(q, q̂) over the three relational poses (o in h,
    o in r, h in r). The position saturation bounds the term when an object is lost (a dropped
    object can roll away for ever); angles are bounded by π already. 0 under the
    ``no_track_reward`` ablation."""
    xc, qc = m["relational"].poses()
    xt, qt = m["reward_targets"].poses()
    pos = torch.linalg.norm(xc - xt, dim=-1).clamp(max=c["max_pos"]) ** 2
    r = (pos * c["pos"]).sum(-1) + (quat_angle(qc, qt) * c["rot"]).sum(-1)
    return torch.zeros_like(r) if c["off"] else r


@reward_term("pose", lambda cfg, dev: dict(w=float(cfg["reg"]["w_pose"])))
def pose_reward(m: dict, c: dict, mode: torch.Tensor) -> torch.Tensor:
    """w_pose · Σ (q_i - q_i,0)² over finger joints."""
    return c["w"] * ((m["finger_qpos"] - m["finger_qpos0"]) ** 2).sum(-1)


@reward_term("wrist_velocity", lambda cfg, dev: dict(w_vel=float(cfg["reg"]["w_vel"]), w_ang=float(cfg["reg"]["w_ang"])))
def wrist_velocity_reward(m: dict, c: dict, mode: torch.Tensor) -> torch.Tensor:
    """w_vel·||ẋ_h||² + w_ang·||ω_h||²."""
    return c["w_vel"] * (m["hand_lin_vel"] ** 2).sum(-1) + c["w_ang"] * (m["hand_ang_vel"] ** 2).sum(-1)


@reward_term("energy", lambda cfg, dev: dict(w=float(cfg["reg"]["w_tau"])))
def energy_reward(m: dict, c: dict, mode: torch.Tensor) -> torch.Tensor:
    """w_tau · ||τ||² over the finger joints."""
    return c["w"] * (m["finger_torque"] ** 2).sum(-1)


@reward_term("drop", lambda cfg, dev: dict(w=float(cfg["reg"]["w_drop"])))
def drop_reward(m: dict, c: dict, mode: torch.Tensor) -> torch.Tensor:
    """w_drop · [dropped at this step]."""
    return c["w"] * m["drop"].float()


class RewardTerms:
    """Every registered term with its coefficients read from the reward config; ``__call__``
    returns each term separately (for logging) and :meth:`total` their sum."""

    def __init__(self, cfg: dict, device, no_track_reward: bool = False):
        cfg = dict(cfg, no_track_reward=no_track_reward)
        self.terms = [(t, t.coefficients(cfg, device)) for t in REGISTRY.values()]

    def __call__(self, mode: torch.Tensor, m: dict) -> Dict[str, torch.Tensor]:
        """``m`` holds the step's measurements (see UniCrossEnv.evaluate)."""
        return {t.name: t.fn(m, c, mode) for t, c in self.terms}

    @property
    def names(self) -> Tuple[str, ...]:
        return tuple(t.name for t, _ in self.terms)

    def coefficients(self, name: str) -> dict:
        """The coefficients of term ``name`` (the dict its function reads at every step)."""
        for t, c in self.terms:
            if t.name == name:
                return c
        raise KeyError(f"no reward term {name!r}; terms: {list(self.names)}")
