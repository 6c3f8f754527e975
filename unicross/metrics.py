"""Metric arithmetic of the paper's protocols (§4.2), as pure functions over trajectories.

Trajectories are batched tensors ``[B, T, ...]`` (B trials, T steps). Every protocol in
:mod:`unicross.evaluation` records trajectories and calls these, so the arithmetic is tested on
synthetic data independently of the simulator.
"""
from __future__ import annotations

import math
from typing import Tuple

import torch

from unicross.geometry import quat_angle, quat_inv, quat_mul, quat_to_axis_angle


def rotation_series(q_oh: torch.Tensor, axis: torch.Tensor) -> torch.Tensor:
    """Signed rotation (rad) about ``axis`` (hand frame) accumulated up to each step of a
    trajectory of hand-frame orientations ``q_oh`` [B, T, 4]; axis [B, 3] or [3]. Returns [B, T]
    starting at 0.

    Sums the per-step incremental rotations projected on the axis, so it keeps counting past
    ±pi (a full turn gives 2*pi, not 0)."""
    dq = quat_mul(q_oh[:, 1:], quat_inv(q_oh[:, :-1]))
    axis = axis.expand(q_oh.shape[0], 3) if axis.ndim == 1 else axis
    inc = (quat_to_axis_angle(dq) * axis[:, None]).sum(-1)  # [B, T-1], each increment in (-pi, pi]
    return torch.cat([torch.zeros_like(inc[:, :1]), torch.cumsum(inc, dim=1)], dim=1)


def accumulated_rotation(q_oh: torch.Tensor, axis: torch.Tensor) -> torch.Tensor:
    """Total signed rotation (rad) about ``axis`` over the trajectory: [B]."""
    return rotation_series(q_oh, axis)[:, -1]


def translation_series(x_oh: torch.Tensor, axis: torch.Tensor) -> torch.Tensor:
    """Signed displacement (m) along ``axis`` of the hand-frame object position [B, T, 3] from
    its first value, at each step: [B, T]."""
    axis = axis.expand(x_oh.shape[0], 3) if axis.ndim == 1 else axis
    return ((x_oh - x_oh[:, :1]) * axis[:, None]).sum(-1)


def exceeded(series: torch.Tensor, threshold: float) -> torch.Tensor:
    """Whether the accumulated motion went beyond ``threshold`` at any step: [B, T] -> [B]."""
    return series.max(dim=-1).values > threshold


def pose_errors(p: torch.Tensor, q: torch.Tensor, p_goal: torch.Tensor, q_goal: torch.Tensor,
                window: int) -> Tuple[torch.Tensor, torch.Tensor]:
    """Mean position (m) and angle (rad) errors to the goal over the last ``window`` steps.
    p [B, T, 3], q [B, T, 4], goals [B, 3] / [B, 4]."""
    w = min(window, p.shape[1])
    pe = torch.linalg.norm(p[:, -w:] - p_goal[:, None], dim=-1).mean(-1)
    ae = quat_angle(q[:, -w:], q_goal[:, None].expand(-1, w, 4)).mean(-1)
    return pe, ae


def ever(flags: torch.Tensor) -> torch.Tensor:
    """Any True over time: [B, T] -> [B]."""
    return flags.any(dim=-1)


def wilson_interval(successes: int, n: int, z: float = 1.96) -> Tuple[float, float]:
    """95% Wilson score interval of a success rate."""
    if n == 0:
        return (float("nan"), float("nan"))
    p = successes / n
    den = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return (max(0.0, centre - half), min(1.0, centre + half))


def success_summary(success: torch.Tensor) -> dict:
    """SR (%) with its count and Wilson 95% interval."""
    n, k = int(success.numel()), int(success.sum())
    lo, hi = wilson_interval(k, n)
    return dict(sr=100.0 * k / n if n else float("nan"), n=n, successes=k, ci95=[100 * lo, 100 * hi])


def mean_over(values: torch.Tensor, mask: torch.Tensor) -> float:
    """Mean of ``values`` where ``mask`` (e.g. non-dropped trials); NaN if none."""
    m = mask.bool()
    return float(values[m].mean()) if bool(m.any()) else float("nan")
