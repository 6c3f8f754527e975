"""The runner side shared by PPO and DAgger: run directory, checkpoint, resume, RNG, wall clock, logs."""
import json
import random

import numpy as np
import pytest
import torch

from unicross import formulation as F
from unicross.rl.runner import CKPT_NAME, Runner

pytestmark = pytest.mark.unit


class Counter(Runner):
    """The smallest trainer: one number, incremented by a random draw per step."""

    STEP_KEY = "epoch"

    def __init__(self, run_dir, resume=False, overrides=None):
        super().__init__(run_dir, resume, overrides, "dagger", progress=False)
        self.value, self.steps = 0.0, 0
        if self.ckpt is not None:
            self.value, self.steps = self.ckpt["value"], self.ckpt["steps"]
            self.load_runner_state(self.ckpt)

    def state(self):
        return dict(**self.runner_state(), value=self.value, steps=self.steps, epoch=self.steps, obs_dims=dict(goal=F.GOAL_DIM),
                    modes=list(F.MODES))

    def step(self):
        self.value += float(torch.rand(1)) + float(np.random.rand()) + random.random()
        self.steps += 1
        row = dict(epoch=self.steps, frames=self.steps, value=self.value, wall_s=self._wall())
        self.log_json(row)
        self.append_csv("metrics.csv", row, list(row))
        self.log_scalars(row, self.steps)


def test_resume_continues_exactly_and_records_every_segment(tmp_path):
    straight = Counter(tmp_path / "a")
    straight.open_logs()
    for _ in range(6):
        straight.step()
    straight.close_logs()

    first = Counter(tmp_path / "b")
    for _ in range(3):
        first.step()
    first.save()
    with pytest.raises(FileExistsError, match="--resume"):
        Counter(tmp_path / "b")
    with pytest.raises(RuntimeError, match="in use by another process"):  # one process per run directory
        Counter(tmp_path / "b", resume=True)
    first.release()
    second = Counter(tmp_path / "b", resume=True, overrides={"optim": {"lr": 1.0e-4}})
    assert second.cfg["optim"]["lr"] == 1.0e-4 and second.cfg["seed"] == first.cfg["seed"]
    for _ in range(3):
        second.step()
    assert second.value == straight.value  # the RNG states came back with the checkpoint
    second.save()
    ck = torch.load(tmp_path / "b" / CKPT_NAME, weights_only=False)
    assert len(ck["commits"]) == 2 and ck["git_commit"] == ck["commits"][-1]
    assert ck["wall_s"] >= first.wall_s
    rows = [json.loads(line) for line in (tmp_path / "b" / "metrics.jsonl").read_text().splitlines()]
    assert [r["epoch"] for r in rows] == [1, 2, 3, 4, 5, 6]
    assert all(b["wall_s"] >= a["wall_s"] for a, b in zip(rows, rows[1:]))
    assert (tmp_path / "b" / "metrics.csv").read_text().count("\n") == 7  # header + 6 rows


def test_resume_needs_a_checkpoint(tmp_path):
    with pytest.raises(FileNotFoundError, match="no checkpoint"):
        Counter(tmp_path / "none", resume=True)


def test_a_resumed_run_may_name_another_mode_in_a_mode_map(tmp_path):
    """``{mode: w}`` fields are empty in configs/dagger.yaml: a run started with one mode named in them
    may be resumed naming another (merged), while a typo elsewhere still fails."""
    run = Counter(tmp_path / "r", overrides=dict(optim=dict(mode_weights={"rotate_x+": 5.0})))
    run.step()
    run.save()
    run.release()
    with pytest.raises(KeyError, match="unknown config key 'optim.lrr'"):
        Counter(tmp_path / "r", resume=True, overrides=dict(optim=dict(lrr=1.0)))
    again = Counter(tmp_path / "r", resume=True, overrides=dict(optim=dict(mode_weights={"grasp": 3.0})))
    assert again.cfg["optim"]["mode_weights"] == {"rotate_x+": 5.0, "grasp": 3.0}
    again.release()


def test_a_resumed_csv_keeps_its_columns_when_the_fields_grow(tmp_path):
    """A run resumed under a version with a new reward term: metrics.csv keeps its header, every row
    lines up with it (the new column goes to metrics.jsonl only)."""
    import csv
    run = Counter(tmp_path / "r")
    run.append_csv("metrics.csv", dict(epoch=1, a=1.0, b=2.0), ["epoch", "a", "b"])
    run.append_csv("metrics.csv", dict(epoch=2, a=3.0, new=9.0, b=4.0), ["epoch", "a", "new", "b"])
    with open(tmp_path / "r" / "metrics.csv", newline="") as f:
        rows = list(csv.reader(f))
    assert rows == [["epoch", "a", "b"], ["1", "1.0", "2.0"], ["2", "3.0", "4.0"]]
