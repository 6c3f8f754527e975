"""What the PPO experts and the DAgger student share around their algorithms (rsl_rl's runner
side): a run directory with an atomically written checkpoint and resume, the commits of every
segment of a run, the RNG states, the wall clock over all segments, and the logs
(``metrics.jsonl``, CSV files, TensorBoard).

:class:`Runner` holds these; :class:`unicross.rl.ppo.PPOTrainer` and
:class:`unicross.rl.dagger.DAggerTrainer` add their collection, update and evaluation loops.
"""
from __future__ import annotations

import csv
import json
import os
import random
import subprocess
import time
from pathlib import Path
from typing import Optional

import numpy as np
import torch

from unicross.config import deep_merge, load_config

CKPT_NAME = "checkpoint.pt"


def git_commit() -> str:
    try:
        return subprocess.check_output(["git", "rev-parse", "HEAD"], cwd=Path(__file__).parent,
                                       stderr=subprocess.DEVNULL).decode().strip()
    except Exception:
        return "unknown"


def atomic_save(obj, path: Path) -> None:
    tmp = path.with_name(path.name + ".tmp")
    torch.save(obj, tmp)
    with open(tmp, "rb") as f:
        os.fsync(f.fileno())
    os.replace(tmp, path)


def open_run(run_dir: Path, resume: bool, overrides: Optional[dict], config_name: str):
    """(checkpoint or None, config) of a run directory: resume needs its checkpoint (whose config
    the overrides update); a new run refuses to overwrite one and starts from ``configs/<name>``."""
    ckpt_path = run_dir / CKPT_NAME
    if resume:
        if not ckpt_path.exists():
            raise FileNotFoundError(f"cannot resume: no checkpoint at {ckpt_path}")
        ckpt = torch.load(ckpt_path, map_location="cpu", weights_only=False)
        from unicross.rl.policy_io import check_modes
        check_modes(ckpt, ckpt_path)
        return ckpt, deep_merge(ckpt["config"], overrides)
    if ckpt_path.exists():
        raise FileExistsError(f"{ckpt_path} exists: pass --resume to continue it or choose another --out")
    return None, load_config(config_name, overrides)


class Runner:
    """A run directory and what every trainer keeps in it (see the module docstring).

    Subclasses build their algorithm after ``super().__init__`` (which seeds every generator from
    ``config["seed"]``), return ``{**self.runner_state(), ...}`` from :meth:`state`, and call
    :meth:`load_runner_state` when resuming (``self.ckpt`` is the checkpoint, or None)."""

    def __init__(self, run_dir, resume: bool, overrides: Optional[dict], config_name: str, progress: bool = True):
        self.run_dir = Path(run_dir)
        self.ckpt, self.cfg = open_run(self.run_dir, resume, overrides, config_name)
        self.progress = progress
        # the code this segment runs (read once: HEAD may move while a long run trains)
        self.commit = git_commit()
        self.commits = list((self.ckpt or {}).get("commits", [])) + [self.commit]
        self.wall_s = 0.0  # wall clock over all segments of the run
        self._wall_mark = time.perf_counter()
        self._writer = None  # TensorBoard, open between open_logs() and close_logs()
        self.seed_everything(self.cfg["seed"])

    @staticmethod
    def seed_everything(seed: int) -> None:
        torch.manual_seed(seed)
        np.random.seed(seed)
        random.seed(seed)

    # ------------------------------------------------------------------ checkpoint
    def state(self) -> dict:
        raise NotImplementedError

    def runner_state(self) -> dict:
        return dict(config=self.cfg, wall_s=self._wall(), git_commit=self.commit, commits=self.commits,
                    rng=dict(torch=torch.get_rng_state(), numpy=np.random.get_state(), python=random.getstate()))

    def load_runner_state(self, ck: dict) -> None:
        self.wall_s, self._wall_mark = float(ck.get("wall_s", 0.0)), time.perf_counter()
        torch.set_rng_state(ck["rng"]["torch"])
        np.random.set_state(ck["rng"]["numpy"])
        random.setstate(ck["rng"]["python"])

    def save(self) -> None:
        self.run_dir.mkdir(parents=True, exist_ok=True)
        atomic_save(self.state(), self.run_dir / CKPT_NAME)

    def _wall(self) -> float:
        now = time.perf_counter()
        self.wall_s += now - self._wall_mark
        self._wall_mark = now
        return self.wall_s

    # ------------------------------------------------------------------ logs
    def open_logs(self) -> None:
        self.run_dir.mkdir(parents=True, exist_ok=True)
        try:
            from torch.utils.tensorboard import SummaryWriter
        except Exception:  # tensorboard missing: the JSON/CSV logs still work
            self._writer = None
        else:
            self._writer = SummaryWriter(str(self.run_dir / "tb"))

    def close_logs(self) -> None:
        if self._writer is not None:
            self._writer.close()
        self._writer = None

    def log_json(self, row: dict) -> None:
        self.run_dir.mkdir(parents=True, exist_ok=True)
        with open(self.run_dir / "metrics.jsonl", "a") as f:
            f.write(json.dumps(row) + "\n")

    def append_csv(self, name: str, row: dict, fields) -> None:
        self.run_dir.mkdir(parents=True, exist_ok=True)
        path = self.run_dir / name
        new = not path.exists()
        with open(path, "a", newline="") as f:
            w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
            if new:
                w.writeheader()
            w.writerow(row)

    def log_scalars(self, row: dict, step: int, prefix: str = "", skip=("iteration", "epoch", "frames")) -> None:
        if self._writer is None:
            return
        for k, v in row.items():
            if k not in skip and isinstance(v, (int, float)):
                self._writer.add_scalar(prefix + k, v, step)
