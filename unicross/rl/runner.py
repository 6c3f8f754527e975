"""What the PPO experts and the DAgger student share around their algorithms (rsl_rl's runner
side): a run directory with an atomically written checkpoint and resume, the commits and
overrides of every segment of a run, the RNG states, the wall clock over all segments, the logs
(``metrics.jsonl``, CSV files, TensorBoard), a lock (one process per run directory) and signals.

Faults: SIGINT and SIGTERM stop the run at the end of the current iteration, which is saved (a
second SIGINT stops at once, keeping the last checkpoint); an error keeps the last checkpoint as
it was (a segment that failed is not written over it); resuming cuts the logs back to the
checkpoint's iteration, so rows written after it (by a run killed with -9) are not there twice.

:class:`Runner` holds these; :class:`unicross.rl.ppo.PPOTrainer` and
:class:`unicross.rl.dagger.DAggerTrainer` add their collection, update and evaluation loops.
"""
from __future__ import annotations

import csv
import fcntl
import json
import os
import random
import signal
import subprocess
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Optional

import numpy as np
import torch

from unicross.config import atomic_write, deep_merge, load_config, validate_ranges
from unicross.rl.collector import register_run, update_threads

CKPT_NAME = "checkpoint.pt"


def git_commit() -> str:
    try:
        return subprocess.check_output(["git", "rev-parse", "HEAD"], cwd=Path(__file__).parent,
                                       stderr=subprocess.DEVNULL).decode().strip()
    except Exception:
        return "unknown"


def fsync_dir(path: Path) -> None:
    """Makes a rename inside ``path`` durable."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def on_cpu(tree):
    """``tree`` (nested dicts, lists and tuples, e.g. a state dict with an optimiser's) with every
    tensor on the CPU, so that a checkpoint of a learner on the GPU loads anywhere as it is."""
    if isinstance(tree, torch.Tensor):
        return tree.cpu()
    if isinstance(tree, dict):
        out = type(tree)((k, on_cpu(v)) for k, v in tree.items())
        if hasattr(tree, "_metadata"):  # a module's state dict: its versions, as load_state_dict reads them
            out._metadata = tree._metadata
        return out
    if isinstance(tree, (list, tuple)):
        return type(tree)(on_cpu(v) for v in tree)
    return tree


def atomic_save(obj, path: Path) -> None:
    """``torch.save`` to a temporary file of this process, fsync, rename over ``path``, fsync the
    directory: a reader sees the old file or the new one, never a torn one."""
    def write(tmp: Path) -> None:
        torch.save(obj, tmp)
        with open(tmp, "rb") as f:
            os.fsync(f.fileno())
    atomic_write(path, write)
    fsync_dir(path.parent)


def lock_run_dir(run_dir: Path):
    """An exclusive lock on ``run_dir`` (the file ``.lock`` holds the owner's pid), released when the
    process closes it or dies; a second process gets a clear error naming the holder."""
    try:
        run_dir.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError) as e:
        raise ValueError(f"--out {run_dir}: cannot make the run directory ({e.strerror}: {e.filename})") from None
    f = open(run_dir / ".lock", "a+")
    try:
        fcntl.flock(f.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        f.seek(0)
        holder = f.read().strip() or "?"
        f.close()
        raise RuntimeError(f"run directory {run_dir} is in use by another process (pid {holder}); "
                           f"wait for it or stop it, or choose another --out") from None
    f.seek(0)
    f.truncate()
    f.write(str(os.getpid()))
    f.flush()
    return f


def truncate_logs(run_dir: Path, key: str, last: int) -> int:
    """Drops the rows of ``metrics.jsonl`` and of the CSV logs in ``run_dir`` whose ``key``
    (iteration, epoch) is past ``last``; returns how many rows were dropped."""
    dropped = 0
    for path in sorted(run_dir.glob("*.csv")) + [run_dir / "metrics.jsonl"]:
        if not path.exists():
            continue
        lines = path.read_text().splitlines(keepends=True)
        if path.suffix == ".jsonl":
            keep = [l for l in lines if not l.strip() or json.loads(l).get(key, last) <= last]
        else:
            header = next(csv.reader(lines[:1]), [])
            if key not in header:
                continue
            col = header.index(key)
            keep = lines[:1] + [l for l in lines[1:] if int(float(next(csv.reader([l]))[col])) <= last]
        if len(keep) < len(lines):
            dropped += len(lines) - len(keep)
            atomic_write(path, lambda tmp: tmp.write_text("".join(keep)))
    return dropped


def open_run(run_dir: Path, resume: bool, overrides: Optional[dict], config_name: str):
    """(checkpoint or None, config) of a run directory: resume needs its checkpoint (whose config
    the overrides update); a new run refuses to overwrite one and starts from ``configs/<name>``."""
    ckpt_path = run_dir / CKPT_NAME
    if resume:
        if not ckpt_path.exists():
            raise FileNotFoundError(f"cannot resume: no checkpoint at {ckpt_path}")
        from unicross.rl.policy_io import read_torch_file
        ckpt = read_torch_file(ckpt_path, "checkpoint")
        kind = "distill" if "epoch" in ckpt else "train"  # DAgger counts epochs, PPO iterations
        if (config_name == "dagger") != (kind == "distill"):
            raise ValueError(f"{run_dir} is a `unicross {kind}` run: continue it with "
                             f"`unicross {kind} --resume --out {run_dir}`")
        from unicross.rl.policy_io import check_modes
        check_modes(ckpt, ckpt_path)
        cfg = deep_merge(ckpt["config"], overrides, defaults=load_config(config_name))
        validate_ranges(config_name, cfg)
    else:
        if ckpt_path.exists():
            raise FileExistsError(f"{ckpt_path} exists: pass --resume to continue it or choose another --out")
        ckpt, cfg = None, load_config(config_name, overrides)
    env = cfg.get("env") or {}  # the task and reward overrides the envs will apply: checked before any worker starts
    load_config("task", env.get("task_config") or None)
    load_config("reward", env.get("reward_config") or None)
    return ckpt, cfg


class Runner:
    """A run directory and what every trainer keeps in it (see the module docstring).

    Subclasses build their algorithm after ``super().__init__`` (which seeds every generator from
    ``config["seed"]``), return ``{**self.runner_state(), ...}`` from :meth:`state`, and call
    :meth:`load_runner_state` when resuming (``self.ckpt`` is the checkpoint, or None)."""

    STEP_KEY = "iteration"  # the log column of the runner's unit of progress (DAgger: "epoch")

    def __init__(self, run_dir, resume: bool, overrides: Optional[dict], config_name: str, progress: bool = True):
        self.run_dir = Path(run_dir)
        self.ckpt, self.cfg = open_run(self.run_dir, resume, overrides, config_name)
        self._lock = lock_run_dir(self.run_dir)
        self.progress = progress
        self.stop_signal: Optional[int] = None  # set by SIGINT/SIGTERM while train() runs
        # the code this segment runs (read once: HEAD may move while a long run trains) and its overrides
        self.commit = git_commit()
        self.commits = list((self.ckpt or {}).get("commits", [])) + [self.commit]
        self.segments = list((self.ckpt or {}).get("segments", [])) + [dict(commit=self.commit, overrides=overrides or {})]
        self.wall_s = 0.0  # wall clock over all segments of the run
        self._wall_mark = time.perf_counter()
        self._writer = None  # TensorBoard, open between open_logs() and close_logs()
        self.seed_everything(self.cfg["seed"])

    @staticmethod
    def seed_everything(seed: int) -> None:
        torch.manual_seed(seed)
        np.random.seed(seed)
        random.seed(seed)

    # ------------------------------------------------------------------ cores
    def share_cores(self, backend: str) -> None:
        """Checks ``optim.update_threads`` (before any simulation) and, on the CPU backend, where the
        env workers and the main process take turns, marks this run so that runs side by side share
        the cores in their updates."""
        update_threads(self.cfg["optim"].get("update_threads"))
        self._cpu_update = backend == "physx_cpu"
        if self._cpu_update:
            register_run()

    def take_update_threads(self, busy_cores: int = 0) -> None:
        """Before the main process's work of an iteration: torch threads = its share of the cores
        (:func:`unicross.rl.collector.update_threads`), less ``busy_cores`` (env workers collecting
        during the update, ``collector.overlap``) when the share is automatic; at least 1."""
        if self._cpu_update:
            value = self.cfg["optim"].get("update_threads")
            torch.set_num_threads(max(1, update_threads(value) - (busy_cores if value is None else 0)))

    # ------------------------------------------------------------------ checkpoint
    def state(self) -> dict:
        raise NotImplementedError

    def runner_state(self) -> dict:
        return dict(config=self.cfg, wall_s=self._wall(), git_commit=self.commit, commits=self.commits,
                    segments=self.segments, rng=dict(torch=torch.get_rng_state(), numpy=np.random.get_state(), python=random.getstate()))

    def load_runner_state(self, ck: dict) -> None:
        """Restores the RNG states and the wall clock, and cuts the logs back to the checkpoint."""
        truncate_logs(self.run_dir, self.STEP_KEY, int(ck[self.STEP_KEY]))
        self.wall_s, self._wall_mark = float(ck.get("wall_s", 0.0)), time.perf_counter()
        torch.set_rng_state(ck["rng"]["torch"])
        np.random.set_state(ck["rng"]["numpy"])
        random.setstate(ck["rng"]["python"])

    def save(self) -> None:
        self.run_dir.mkdir(parents=True, exist_ok=True)
        atomic_save(self.state(), self.run_dir / CKPT_NAME)

    def release(self) -> None:
        """Gives the run directory's lock back (``close()`` of the trainers)."""
        if self._lock is not None:
            self._lock.close()
            self._lock = None

    @contextmanager
    def stop_on_signals(self):
        """While the loop runs, SIGINT and SIGTERM set ``stop_signal`` (the loop saves and stops at
        the end of its iteration); a second SIGINT raises KeyboardInterrupt at once. Outside the
        main thread (no signal handlers there) it does nothing."""
        def request(signum, frame):
            if self.stop_signal == signal.SIGINT and signum == signal.SIGINT:
                raise KeyboardInterrupt
            self.stop_signal = signum
            print(f"\n[unicross] {signal.Signals(signum).name}: stopping after this {self.STEP_KEY} "
                  f"(SIGINT again to stop now)", flush=True)
        try:
            old = {s: signal.signal(s, request) for s in (signal.SIGINT, signal.SIGTERM)}
        except ValueError:  # not the main thread
            yield
            return
        try:
            yield
        finally:
            for s, h in old.items():
                signal.signal(s, h)

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
        if not new:  # a run resumed under a newer version keeps its file's columns (a new reward term: jsonl only)
            with open(path, newline="") as f:
                fields = next(csv.reader(f), None) or fields
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
