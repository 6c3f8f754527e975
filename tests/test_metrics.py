"""Protocol metric arithmetic on synthetic trajectories."""
import math

import pytest
import torch

from unicross import metrics as M
from unicross.evaluation import markdown_table, summarize
from unicross.geometry import quat_from_axis_angle, quat_mul

pytestmark = pytest.mark.unit


def _spin(axis, step, n, start=None):
    axis = torch.tensor(axis, dtype=torch.float32)
    q = [start if start is not None else torch.tensor([1.0, 0.0, 0.0, 0.0])]
    inc = quat_from_axis_angle(axis[None], torch.tensor([step]))[0]
    for _ in range(n):
        q.append(quat_mul(inc[None], q[-1][None])[0])
    return torch.stack(q)[None]  # [1, T, 4]


def test_accumulated_rotation_counts_past_pi():
    q = _spin([0, 0, 1], 0.3, 30)  # 9 rad: wraps past pi twice
    assert M.accumulated_rotation(q, torch.tensor([0.0, 0.0, 1.0])).item() == pytest.approx(9.0, abs=1e-4)
    assert M.accumulated_rotation(q, torch.tensor([0.0, 0.0, -1.0])).item() == pytest.approx(-9.0, abs=1e-4)
    assert M.accumulated_rotation(q, torch.tensor([1.0, 0.0, 0.0])).item() == pytest.approx(0.0, abs=1e-5)
    # quaternion sign flips along the trajectory (q and -q) change nothing
    flipped = q.clone()
    flipped[:, ::3] *= -1
    assert M.accumulated_rotation(flipped, torch.tensor([0.0, 0.0, 1.0])).item() == pytest.approx(9.0, abs=1e-4)
    # back-and-forth motion cancels
    back = _spin([0, 0, 1], -0.3, 30, start=q[0, -1])
    both = torch.cat([q, back[:, 1:]], dim=1)
    s = M.rotation_series(both, torch.tensor([0.0, 0.0, 1.0]))
    assert s[0, -1].item() == pytest.approx(0.0, abs=1e-4) and s[0].max().item() == pytest.approx(9.0, abs=1e-4)
    assert bool(M.exceeded(s, math.pi / 2)[0]) and not bool(M.exceeded(s, 9.5)[0])


def test_translation_series_and_threshold():
    x = torch.zeros(2, 11, 3)
    x[0, :, 2] = torch.linspace(0, 0.06, 11)     # +6 cm along z
    x[1, :, 2] = torch.linspace(0, -0.06, 11)    # wrong way
    s = M.translation_series(x, torch.tensor([0.0, 0.0, 1.0]))
    assert s[:, -1].tolist() == pytest.approx([0.06, -0.06], abs=1e-6)
    assert M.exceeded(s, 0.05).tolist() == [True, False]


def test_pose_error_window():
    T = 75
    p = torch.zeros(1, T, 3)
    p[0, :, 0] = torch.linspace(0.5, 0.0, T)     # converges to the goal at the origin
    q = torch.tensor([1.0, 0, 0, 0]).expand(1, T, 4).clone()
    goal_q = quat_from_axis_angle(torch.tensor([[0.0, 1.0, 0.0]]), torch.tensor([0.1]))
    pe, ae = M.pose_errors(p, q, torch.zeros(1, 3), goal_q, window=25)
    assert pe.item() == pytest.approx(p[0, -25:, 0].mean().item(), abs=1e-6)
    assert ae.item() == pytest.approx(0.1, abs=1e-5)


def test_wilson_interval():
    lo, hi = M.wilson_interval(8, 10)
    assert (lo, hi) == pytest.approx((0.4902, 0.9433), abs=1e-3)
    assert M.wilson_interval(0, 5)[0] == 0.0 and M.wilson_interval(5, 5)[1] == 1.0


def test_summaries_handle_drops():
    trials = [dict(success=True, dropped=False, rotation_rad=2.0), dict(success=False, dropped=False, rotation_rad=1.0),
              dict(success=False, dropped=True, rotation_rad=50.0)]
    s = summarize("rotate", trials)
    assert s["n"] == 3 and s["successes"] == 1 and s["sr"] == pytest.approx(100 / 3)
    assert s["rot_rad"] == pytest.approx(1.5)  # the dropped trial is excluded from Rot.
    assert s["non_dropped"] == 2
    table = markdown_table({"x": {"rotate": s}})
    assert "33.3" in table and "1.50" in table and "n=3" in table
