"""PPO for one UniCross expert with TorchRL building blocks.

    Collector -> GAE -> TensorDict replay buffer (mini-batches) -> ClipPPOLoss -> Adam
    (+ KL-adaptive learning rate, grad-norm clipping, running observation normalisation)

Checkpoints (weights, optimiser, iteration, frames, learning rate, RNG states, config, git commit)
are written atomically every ``logging.checkpoint_every`` iterations and on exit; ``resume=True``
continues the same run directory at the next iteration. Metrics go to ``metrics.csv``,
``metrics.jsonl`` and TensorBoard (``tb/``).
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
from tensordict import TensorDict
from torchrl.collectors import Collector
from torchrl.data import LazyTensorStorage, TensorDictReplayBuffer
from torchrl.data.replay_buffers.samplers import SamplerWithoutReplacement
from torchrl.envs.utils import ExplorationType, set_exploration_type
from torchrl.objectives import ClipPPOLoss
from torchrl.objectives.value import GAE
from tqdm import tqdm

from unicross import formulation as F
from unicross.config import deep_merge, load_config
from unicross.rl.env import make_env
from unicross.rl.models import OBS_KEYS, make_models, obs_dims_from_spec

SKILL_ENV = {"grasp": "UniCross-Grasp-v1", "relocate": "UniCross-Relocate-v1", "rotate": "UniCross-Rotate-v1",
             "translate": "UniCross-Translate-v1"}
DEFAULT_HORIZON = {"grasp": 64, "relocate": 64, "rotate": 8, "translate": 8}
CKPT_NAME = "checkpoint.pt"
CSV_FIELDS = ["iteration", "frames", "fps", "collect_s", "update_s", "reward", "episodes", "episode_return",
              "success_rate", "loss_objective", "loss_critic", "loss_entropy", "kl", "grad_norm", "lr",
              "reward_contact", "reward_motion", "reward_track", "reward_pose", "reward_wrist_velocity",
              "reward_energy", "reward_drop"]


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
        return ckpt, deep_merge(ckpt["config"], overrides)
    if ckpt_path.exists():
        raise FileExistsError(f"{ckpt_path} exists: pass --resume to continue it or choose another --out")
    return None, load_config(config_name, overrides)


def env_kwargs_for(skill: str, axis: Optional[str], hand: str, env_cfg: dict) -> dict:
    F.mode_index(skill, axis)  # validates skill and axis before any simulation
    kw = dict(hand=hand, randomize=env_cfg["randomize"], reconfiguration_freq=env_cfg["reconfiguration_freq"])
    if env_cfg.get("task_config"):
        kw["config"] = env_cfg["task_config"]
    if env_cfg.get("reward_config"):
        kw["reward_config"] = env_cfg["reward_config"]
    if env_cfg.get("objects"):
        kw["objects"] = env_cfg["objects"]
    if env_cfg.get("object_limit") is not None:
        kw["object_limit"] = env_cfg["object_limit"]
    if skill == "rotate":
        kw["axis"] = axis
    if skill == "translate":
        kw["direction"] = axis
    return kw


def gaussian_kl(loc0, scale0, loc1, scale1) -> torch.Tensor:
    """KL(N0 || N1) of diagonal Gaussians, summed over action dims."""
    return (torch.log(scale1 / scale0) + (scale0 ** 2 + (loc0 - loc1) ** 2) / (2 * scale1 ** 2) - 0.5).sum(-1)


class PPOTrainer:
    """One expert: ``skill`` (+ ``axis`` for rotate/translate) on ``hand``."""

    def __init__(self, run_dir, skill: str = "grasp", axis: Optional[str] = None, hand: str = "allegro",
                 overrides: Optional[dict] = None, resume: bool = False, progress: bool = True):
        self.run_dir = Path(run_dir)
        self.ckpt, cfg = open_run(self.run_dir, resume, overrides, "ppo")
        if self.ckpt is not None:
            skill, axis, hand = self.ckpt["skill"], self.ckpt["axis"], self.ckpt["hand"]
        from unicross.robots.hand import load_hand
        load_hand(hand)  # validates
        self.skill, self.axis, self.hand, self.cfg = skill, axis, hand, cfg
        self.env_id = SKILL_ENV[skill] if skill in SKILL_ENV else None
        if self.env_id is None:
            raise ValueError(f"unknown skill {skill!r}; valid skills: {list(SKILL_ENV)}")
        self.env_kwargs = env_kwargs_for(skill, axis, hand, cfg["env"])
        self.progress = progress
        self.horizon = cfg["collector"]["horizon"] or DEFAULT_HORIZON[skill]
        self._seed_everything(cfg["seed"])
        ec = cfg["env"]
        if ec["backend"] == "physx_cpu":  # leave the cores to the env worker processes
            torch.set_num_threads(max(1, (os.cpu_count() or 1) - ec["num_envs"]))
        self.env = make_env(self.env_id, self.env_kwargs, ec["num_envs"], ec["backend"])
        self.env.set_seed(cfg["seed"])
        self.device = self.env.device
        dims = obs_dims_from_spec(self.env.observation_spec)
        self.n_act = self.env.action_spec.shape[-1]
        self.policy, self.value, self.norm = make_models(dims, self.n_act, self.env.action_spec, cfg["model"])
        self.policy.to(self.device)
        self.value.to(self.device)
        lc = cfg["loss"]
        self.loss = ClipPPOLoss(self.policy, self.value, clip_epsilon=lc["clip_epsilon"],
                                entropy_bonus=lc["entropy_coeff"] > 0, entropy_coeff=lc["entropy_coeff"],
                                critic_coeff=lc["critic_coeff"], loss_critic_type=lc["loss_critic_type"],
                                normalize_advantage=lc["normalize_advantage"])
        self.gae = GAE(gamma=cfg["gae"]["gamma"], lmbda=cfg["gae"]["lmbda"], value_network=self.value,
                       average_gae=False)
        self.optim = torch.optim.Adam(self.loss.parameters(), lr=cfg["optim"]["lr"])
        self.lr = cfg["optim"]["lr"]
        self.iteration, self.frames = 0, 0
        self.dims = dims
        if self.ckpt is not None:
            self._load_state(self.ckpt)
        self.batch_envs = int(np.prod(self.env.batch_size)) if len(self.env.batch_size) else 1
        self.frames_per_batch = self.batch_envs * self.horizon
        self.minibatch = min(cfg["optim"]["minibatch_size"], self.frames_per_batch)
        self.rb = TensorDictReplayBuffer(storage=LazyTensorStorage(self.frames_per_batch, device=self.device),
                                         sampler=SamplerWithoutReplacement(), batch_size=self.minibatch)
        self._ep_return = torch.zeros(self.env.batch_size + (1,), device=self.device)

    # ------------------------------------------------------------------ state
    def _seed_everything(self, seed: int):
        torch.manual_seed(seed)
        np.random.seed(seed)
        random.seed(seed)

    def state(self) -> dict:
        return dict(policy=self.policy.state_dict(), value=self.value.state_dict(), optim=self.optim.state_dict(),
                    iteration=self.iteration, frames=self.frames, lr=self.lr, config=self.cfg, skill=self.skill,
                    axis=self.axis, hand=self.hand, env_id=self.env_id, env_kwargs=self.env_kwargs,
                    obs_dims=self.dims, n_act=self.n_act, git_commit=git_commit(),
                    rng=dict(torch=torch.get_rng_state(), numpy=np.random.get_state(), python=random.getstate()))

    def _load_state(self, ck: dict):
        self.policy.load_state_dict(ck["policy"])
        self.value.load_state_dict(ck["value"])
        self.optim.load_state_dict(ck["optim"])
        self.iteration, self.frames, self.lr = ck["iteration"], ck["frames"], ck["lr"]
        for g in self.optim.param_groups:
            g["lr"] = self.lr
        torch.set_rng_state(ck["rng"]["torch"])
        np.random.set_state(ck["rng"]["numpy"])
        random.setstate(ck["rng"]["python"])

    def save(self):
        self.run_dir.mkdir(parents=True, exist_ok=True)
        atomic_save(self.state(), self.run_dir / CKPT_NAME)

    # ------------------------------------------------------------------ evaluation
    @torch.no_grad()
    def evaluate(self, episodes_per_env: int = 1, seed: int = 12345) -> dict:
        """Deterministic rollouts (mean action): mean return and success of the first episode of
        each env, ``episodes_per_env`` times."""
        ep_len = load_config("task")["episode_length"][self.skill]
        if getattr(self.env, "is_closed", False):  # the collector closes its env when it finishes
            ec = self.cfg["env"]
            self.env = make_env(self.env_id, self.env_kwargs, ec["num_envs"], ec["backend"])
        env = self.env
        returns, successes = [], []
        for k in range(episodes_per_env):
            env.set_seed(seed + k)
            with set_exploration_type(ExplorationType.DETERMINISTIC):
                td = env.rollout(ep_len, self.policy, break_when_any_done=False)
            td = td if len(env.batch_size) else td.unsqueeze(0)  # [B, T]
            done = td["next", "done"].squeeze(-1)
            first = torch.where(done.any(-1), done.float().argmax(-1), torch.full_like(done[:, 0], ep_len - 1, dtype=torch.long))
            t = torch.arange(done.shape[1], device=done.device)
            mask = (t[None] <= first[:, None]).float()
            returns.append((td["next", "reward"].squeeze(-1) * mask).sum(-1))
            successes.append(td["next", "info", "success"].squeeze(-1).gather(1, first[:, None]).squeeze(1).float())
        r, s = torch.cat(returns), torch.cat(successes)
        return dict(eval_return=float(r.mean()), eval_success=float(s.mean()), eval_episodes=int(r.numel()))

    # ------------------------------------------------------------------ training
    def _episode_stats(self, data: TensorDict) -> dict:
        """Returns/successes of episodes that ended in this batch (data: [..., T])."""
        rew = data["next", "reward"]
        done = data["next", "done"]
        succ = data["next", "info", "success"]
        ret = self._ep_return
        finished_r, finished_s = [], []
        for t in range(rew.shape[-2]):
            ret = ret + rew[..., t, :]
            d = done[..., t, :]
            finished_r.append(ret[d])
            finished_s.append(succ[..., t, :][d].float())
            ret = torch.where(d, torch.zeros_like(ret), ret)
        self._ep_return = ret
        r, s = torch.cat(finished_r), torch.cat(finished_s)
        out = {"episodes": int(r.numel())}
        if r.numel():
            out.update(episode_return=float(r.mean()), success_rate=float(s.mean()))
        return out

    def _update(self, data: TensorDict) -> dict:
        oc = self.cfg["optim"]
        data["next", "reward"] = data["next", "reward"] * self.cfg["gae"]["reward_scale"]
        with torch.no_grad():
            self.gae(data)
        flat = data.reshape(-1)
        self.rb.empty()
        self.rb.extend(flat)
        n_mb = max(1, self.frames_per_batch // self.minibatch)
        stats = {"loss_objective": 0.0, "loss_critic": 0.0, "loss_entropy": 0.0, "kl": 0.0, "grad_norm": 0.0}
        count = 0
        actor = self.policy.module[0]  # TensorDictModule producing loc, scale
        for _ in range(oc["mini_epochs"]):
            for _ in range(n_mb):
                mb = self.rb.sample()
                losses = self.loss(mb)
                loss = losses["loss_objective"] + losses["loss_critic"]
                if "loss_entropy" in losses.keys():
                    loss = loss + losses["loss_entropy"]
                self.optim.zero_grad(set_to_none=True)
                loss.backward()
                gn = torch.nn.utils.clip_grad_norm_(self.loss.parameters(), oc["max_grad_norm"])
                self.optim.step()
                with torch.no_grad():
                    new = actor(mb.select(*OBS_KEYS).clone())
                    kl = gaussian_kl(mb["loc"], mb["scale"], new["loc"], new["scale"]).mean()
                # KL-adaptive learning rate (rl_games): shrink when the policy moved too far
                klv = float(kl)
                if klv > 2.0 * oc["kl_threshold"]:
                    self.lr = max(self.lr / 1.5, oc["lr_min"])
                elif klv < 0.5 * oc["kl_threshold"]:
                    self.lr = min(self.lr * 1.5, oc["lr_max"])
                for g in self.optim.param_groups:
                    g["lr"] = self.lr
                for k in ("loss_objective", "loss_critic", "loss_entropy"):
                    if k in losses.keys():
                        stats[k] += float(losses[k].detach())
                stats["kl"] += klv
                stats["grad_norm"] += float(gn)
                count += 1
        self.norm.update({k: flat[k] for k in OBS_KEYS})
        out = {k: v / count for k, v in stats.items()}
        out["lr"] = self.lr
        return out

    def train(self, max_iterations: Optional[int] = None, eval_at_ends: bool = True) -> dict:
        total = self.cfg["collector"]["total_frames"]
        remaining = max(0, total - self.frames)
        self.run_dir.mkdir(parents=True, exist_ok=True)
        (self.run_dir / "config.json").write_text(json.dumps(dict(config=self.cfg, skill=self.skill, axis=self.axis,
                                                                  hand=self.hand, git_commit=git_commit()), indent=1))
        summary = {}
        if eval_at_ends and self.iteration == 0 and self.cfg["logging"]["eval_episodes"] > 0:
            summary["start"] = self.evaluate(self._eval_rounds())
            self._log_json({"iteration": 0, "frames": 0, **summary["start"]})
        if remaining == 0:
            return summary
        collector = Collector(self.env, self.policy, frames_per_batch=self.frames_per_batch, total_frames=remaining,
                              device=self.device, auto_register_policy_transforms=False)
        writer = self._tb()
        bar = tqdm(total=total, initial=self.frames, unit="frame", desc=f"ppo {self.skill}", disable=not self.progress)
        t_last = time.perf_counter()
        done_iters = 0
        try:
            for data in collector:
                t_collect = time.perf_counter() - t_last
                self.iteration += 1
                self.frames += data.numel()
                ep = self._episode_stats(data)
                t0 = time.perf_counter()
                up = self._update(data)
                t_update = time.perf_counter() - t0
                collector.update_policy_weights_()
                terms = {k: float(data["next", "info", k].mean()) for k in data["next", "info"].keys()
                         if k.startswith("reward_")}
                row = dict(iteration=self.iteration, frames=self.frames, fps=data.numel() / max(t_collect + t_update, 1e-9),
                           collect_s=t_collect, update_s=t_update, reward=float(data["next", "reward"].mean()),
                           **ep, **up, **terms)
                self._log(row, writer)
                bar.update(data.numel())
                bar.set_postfix(ret=f"{row.get('episode_return', float('nan')):.2f}", succ=f"{row.get('success_rate', float('nan')):.2f}")
                if self.iteration % self.cfg["logging"]["checkpoint_every"] == 0:
                    self.save()
                done_iters += 1
                t_last = time.perf_counter()
                if max_iterations is not None and done_iters >= max_iterations:
                    break
        finally:
            self.save()
            bar.close()
            collector.shutdown(close_env=False)
            if writer is not None:
                writer.close()
        if eval_at_ends and self.cfg["logging"]["eval_episodes"] > 0 and self.frames >= total:
            summary["end"] = self.evaluate(self._eval_rounds())
            self._log_json({"iteration": self.iteration, "frames": self.frames, **summary["end"]})
        return summary

    def _eval_rounds(self) -> int:
        return max(1, self.cfg["logging"]["eval_episodes"] // self.batch_envs)

    # ------------------------------------------------------------------ logging
    def _tb(self):
        try:
            from torch.utils.tensorboard import SummaryWriter
        except Exception:  # tensorboard missing: CSV/JSON logs still work
            return None
        return SummaryWriter(str(self.run_dir / "tb"))

    def _log_json(self, row: dict):
        with open(self.run_dir / "metrics.jsonl", "a") as f:
            f.write(json.dumps(row) + "\n")

    def _log(self, row: dict, writer):
        self._log_json(row)
        path = self.run_dir / "metrics.csv"
        new = not path.exists()
        with open(path, "a", newline="") as f:
            w = csv.DictWriter(f, fieldnames=CSV_FIELDS, extrasaction="ignore")
            if new:
                w.writeheader()
            w.writerow(row)
        if writer is not None:
            for k, v in row.items():
                if k not in ("iteration", "frames") and isinstance(v, (int, float)):
                    writer.add_scalar(k, v, self.frames)

    def close(self):
        try:
            self.env.close()
        except Exception:
            pass
