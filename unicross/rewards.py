"""Reward terms of the paper (§3.1.4) as named functions; weights come from ``configs/reward.yaml``.

``r = r_goal + r_track + r_reg`` with
  r_goal  = contact + motion (+ success: ours, a per-step bonus while the mode's success holds;
            + progress: ours, the decrease of the object's error to its final pose (relocate);
            both 0 in the paper, see configs/reward.yaml)
  r_track = Σ w · error over the six relational poses (position errors saturate at ``track.max_pos_error``)
  r_reg   = pose + wrist_velocity + energy + drop

``TERMS`` names every term once; the task sums exactly these and logs each as ``reward_<name>``.

:class:`RewardTerms` turns the config into per-mode coefficient tensors, so one batched call
serves every env whatever its mode. Each term is returned separately for logging.
"""
from __future__ import annotations

from typing import Dict

import torch

from unicross.formulation import MODES, Relational, mode_skill
from unicross.geometry import quat_angle

TERMS = ("contact", "motion", "success", "progress", "track", "pose", "wrist_velocity", "energy", "drop")
TRACK_WEIGHTS = dict(x_or="w_opr", q_or="w_oqr", x_oh="w_oph", q_oh="w_oqh", x_hr="w_hpr", q_hr="w_hqr")


def contact_reward(distance: torch.Tensor, contact: torch.Tensor, force: torch.Tensor,
                   w_dis: torch.Tensor, w_con: torch.Tensor, w_f: torch.Tensor,
                   max_distance: float = float("inf")) -> torch.Tensor:
    """(1/N) Σ_links (-w_dis·min(d_i, max_distance) + w_con·c_i + w_f·f_i); distance/contact/force
    are [B, L]. The saturation bounds the term when an object is lost (it can fall past the table)."""
    per_link = -w_dis[:, None] * distance.clamp(max=max_distance) + w_con[:, None] * contact + w_f[:, None] * force
    return per_link.mean(dim=-1)


def motion_reward(speed_along_axis: torch.Tensor, cap: torch.Tensor, w_p: torch.Tensor) -> torch.Tensor:
    """w_p · min(v_o^h · d^h, v_max)."""
    return w_p * torch.minimum(speed_along_axis, cap)


def tracking_reward(cur: Relational, tgt: Relational, w_pos: torch.Tensor, w_rot: torch.Tensor,
                    max_pos: float = float("inf")) -> torch.Tensor:
    """Σ w_pos·min(||x - x̂||, max_pos)² + w_rot·A(q, q̂) over the three relational poses (o in h,
    o in r, h in r); ``w_pos``/``w_rot`` are [3] weights in that order. The position saturation
    bounds the term when an object is lost (a dropped object can roll away for ever); angles are
    bounded by π already."""
    xc, qc = cur.poses()
    xt, qt = tgt.poses()
    pos = torch.linalg.norm(xc - xt, dim=-1).clamp(max=max_pos) ** 2
    return (pos * w_pos).sum(-1) + (quat_angle(qc, qt) * w_rot).sum(-1)


def success_reward(success: torch.Tensor, w_success: torch.Tensor) -> torch.Tensor:
    """w_success · [the mode's success holds at this step]."""
    return w_success * success.float()


def progress_reward(err_prev: torch.Tensor, err: torch.Tensor, w_pos: torch.Tensor, w_rot: torch.Tensor,
                    max_pos: float = float("inf")) -> torch.Tensor:
    """w_pos·(e_{t-1} − e_t) + w_rot·(θ_{t-1} − θ_t): how much closer the object came to its final
    pose over the step (``err`` [B, 2]: position error, saturated at ``max_pos``, and angle). A
    potential-based shaping term (Ng et al., 1999, with γ≈1): over an episode it sums to the
    reduction of the error from start to end, whatever the path."""
    pos_prev, pos = err_prev[:, 0].clamp(max=max_pos), err[:, 0].clamp(max=max_pos)
    return w_pos * (pos_prev - pos) + w_rot * (err_prev[:, 1] - err[:, 1])


def pose_reward(finger_q: torch.Tensor, finger_q0: torch.Tensor, w_pose: float) -> torch.Tensor:
    """w_pose · Σ (q_i - q_i,0)² over finger joints."""
    return w_pose * ((finger_q - finger_q0) ** 2).sum(-1)


def wrist_velocity_reward(lin_vel: torch.Tensor, ang_vel: torch.Tensor, w_vel: float, w_ang: float) -> torch.Tensor:
    return w_vel * (lin_vel ** 2).sum(-1) + w_ang * (ang_vel ** 2).sum(-1)


def energy_reward(torque: torch.Tensor, w_tau: float) -> torch.Tensor:
    return w_tau * (torque ** 2).sum(-1)


def drop_reward(dropped: torch.Tensor, w_drop: float) -> torch.Tensor:
    return w_drop * dropped.float()


class RewardTerms:
    """Per-mode coefficients from the reward config; ``__call__`` returns every term."""

    def __init__(self, cfg: dict, device, no_track_reward: bool = False):
        def per_mode(getter):
            return torch.tensor([getter(mode_skill(m)) for m in MODES], dtype=torch.float32, device=device)
        self.w_dis = per_mode(lambda s: cfg["contact"][s]["w_dis"])
        self.w_con = per_mode(lambda s: cfg["contact"][s]["w_con"])
        self.w_f = per_mode(lambda s: cfg["contact"][s]["w_f"])
        self.w_p = per_mode(lambda s: cfg["motion"][s])
        self.max_distance = float(cfg["contact_max_distance"])
        self.w_success = per_mode(lambda s: cfg["success"][s])
        self.w_prog_pos = per_mode(lambda s: cfg["progress"][s]["w_pos"])
        self.w_prog_rot = per_mode(lambda s: cfg["progress"][s]["w_rot"])
        t = cfg["track"]
        self.max_pos = float(t["max_pos_error"])
        self.track_pos = torch.tensor([t[TRACK_WEIGHTS[s]] for s in ("x_oh", "x_or", "x_hr")], device=device)
        self.track_rot = torch.tensor([t[TRACK_WEIGHTS[s]] for s in ("q_oh", "q_or", "q_hr")], device=device)
        self.reg = dict(cfg["reg"])
        self.no_track_reward = no_track_reward

    def __call__(self, mode, m: dict) -> Dict[str, torch.Tensor]:
        """``m`` holds the step's measurements (see UniCrossEnv.evaluate)."""
        terms = dict(
            contact=contact_reward(m["link_distance"], m["contact"].float(), m["force_clipped"],
                                   self.w_dis[mode], self.w_con[mode], self.w_f[mode], self.max_distance),
            motion=motion_reward(m["speed_along_axis"], m["speed_cap"], self.w_p[mode]),
            success=success_reward(m["success"], self.w_success[mode]),
            progress=progress_reward(m["goal_err_prev"], m["goal_err"], self.w_prog_pos[mode],
                                     self.w_prog_rot[mode], self.max_pos),
            track=tracking_reward(m["relational"], m["reward_targets"], self.track_pos, self.track_rot,
                                  self.max_pos),
            pose=pose_reward(m["finger_qpos"], m["finger_qpos0"], self.reg["w_pose"]),
            wrist_velocity=wrist_velocity_reward(m["hand_lin_vel"], m["hand_ang_vel"],
                                                 self.reg["w_vel"], self.reg["w_ang"]),
            energy=energy_reward(m["finger_torque"], self.reg["w_tau"]),
            drop=drop_reward(m["drop"], self.reg["w_drop"]),
        )
        if self.no_track_reward:
            terms["track"] = torch.zeros_like(terms["track"])
        return terms
