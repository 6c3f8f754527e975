"""Trajectory files and CPU rendering (pyrender on EGL/llvmpipe)."""
import builtins

import numpy as np
import pytest
import torch

from conftest import make
from unicross.trajectory import Trajectory, TrajectoryRecorder


@pytest.fixture(scope="module")
def traj_file(tmp_path_factory):
    env = make("UniCross-Grasp-v1", randomize=False, config=dict(grasp=dict(lift_after=None)))
    u = env.unwrapped
    u.reset(seed=0)
    rec = TrajectoryRecorder(u, task_id="UniCross-Grasp-v1")
    rec.record()
    a = torch.zeros(1, 22)
    a[0, 0] = -1.0  # move the wrist along -x of the root frame (up, away from the palm normal)
    for _ in range(6):
        u.step(a)
        rec.record()
    path = rec.save(tmp_path_factory.mktemp("traj") / "t.npz")
    env.close()
    return path


def test_trajectory_round_trip(traj_file):
    t = Trajectory.load(traj_file)
    assert len(t) == 7 and t.qpos.shape == (7, 22) and t.contact_points.shape == (7, 21, 3)
    assert t.meta["hand"] == "allegro" and t.meta["object"]["shape"] in ("box", "cylinder")
    assert np.linalg.norm(t.wrist_pose[-1, :3] - t.wrist_pose[0, :3]) > 0.03  # the hand moved


def test_render_frames_on_cpu(traj_file):
    from unicross.render import render_frames
    t = Trajectory.load(traj_file)
    f0, f1 = render_frames(t, "front", 160, 120, frames=[0, len(t) - 1], label=False)
    assert f0.shape == (120, 160, 3) and f0.std() > 5.0  # not an empty frame
    diff = np.abs(f0.astype(int) - f1.astype(int)).sum(-1) > 30
    assert 0.005 < diff.mean() < 0.9  # the hand region changed, the rest did not


def test_render_cli_outputs(traj_file, tmp_path):
    from unicross.cli import main
    assert main(["render", str(traj_file), "--out", str(tmp_path / "a.gif"), "--size", "96x72"]) == 0
    assert main(["render", str(traj_file), "--out", str(tmp_path / "a.png"), "--camera", "follow"]) == 0
    assert (tmp_path / "a.gif").stat().st_size > 1000 and (tmp_path / "a.png").stat().st_size > 1000
    assert main(["render", str(traj_file), "--out", str(tmp_path / "a.png"), "--camera", "nadir"]) == 2


def test_missing_display_libraries_give_one_clear_message(monkeypatch):
    import sys
    from unicross import render as R
    monkeypatch.delitem(sys.modules, "pyrender", raising=False)
    real_import = builtins.__import__

    def fake_import(name, *a, **k):
        if name == "pyrender":
            raise OSError("libEGL.so.1: cannot open shared object file")
        return real_import(name, *a, **k)
    monkeypatch.setattr(builtins, "__import__", fake_import)
    with pytest.raises(R.RenderUnavailable, match="libegl1"):
        R._import_pyrender()
