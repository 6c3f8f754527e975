"""DAgger distillation of the ten per-mode experts into one student (paper §3.3).

Each epoch the student acts (its mean action; CPU: one env per worker process, the lean collector
of :mod:`unicross.rl.collector`) in ``UniCross-MultiSkill-v1`` (environments spread over valid
(object, mode) pairs) for ``rollout_steps``; every visited state is labelled by the frozen expert
of its mode (query rate 100%); the (observation, expert action) pairs go to a TensorDict replay
buffer (``LazyTensorStorage``, capacity 1e6 by default); the student then takes
``grad_steps`` MSE steps on sampled batches (once ``optim.warmup_frames`` rows are stored; 0 by default).

``optim.mode_weights`` (ours, none by default) counts a mode's rows w times in the batch's weighted mean error, for a
teacher whose actions are small (the rotate x+ finger sequence).

``env.chain_share`` (ours, 0 by default): that share of the workers' episodes runs in long-horizon
chains (grasp, relocate, an in-hand mode; :func:`chain_envs`) instead, labelled phase by phase.

The trainer refuses to start unless every mode of ``env.modes`` (default: all ten) has an expert checkpoint
(``<experts>/<mode>/checkpoint.pt``, the run directories of ``unicross train``).
Checkpoints (student, optimiser, epoch, replay buffer, RNG) make runs resumable; per-mode action
MSE and per-mode success rates are logged.
"""
from __future__ import annotations

import hashlib
import math
import os
import shutil
import time
from pathlib import Path
from typing import Dict, Optional, Sequence

import torch
from tensordict import TensorDict
from torchrl.data import Bounded, LazyTensorStorage, TensorDictReplayBuffer
from torchrl.envs.utils import ExplorationType, set_exploration_type
from tqdm import tqdm

from unicross import formulation as F
from unicross import registry as R
from unicross.grasps import grasp_dataset_file
from unicross.rl.collector import (check_overlap, make_collector, resolve_num_envs, resolve_update_device,
                                   same_device)
from unicross.rl.models import OBS_KEYS, make_models
from unicross.rl.policy_io import base_policy_of, load_policy
from unicross.rl.ppo import adopt_input_floor, policy_to_start_from
from unicross.rl.runner import CKPT_NAME, Runner, atomic_save, on_cpu


def expert_paths(experts_dir, modes=F.MODES) -> Dict[str, Path]:
    d = Path(experts_dir)
    paths = {m: d / m / "checkpoint.pt" for m in modes}
    missing = [m for m, p in paths.items() if not p.exists()]
    if missing:
        raise FileNotFoundError(f"no expert checkpoint for mode(s) {missing} under {d} "
                                f"(expected <experts>/<mode>/checkpoint.pt, e.g. from "
                                f"`unicross train --skill rotate --axis x+ --out {d}/rotate_x+`)")
    return paths


def file_digest(path) -> str:
    """The sha256 of a file's bytes (a teacher's identity in a distillation checkpoint)."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def changed_teachers(saved: Optional[Dict[str, str]], saved_dir, digests: Dict[str, str], experts_dir) -> list:
    """The modes whose teacher differs from the one a checkpoint was labelled by: those whose file digest differs
    from ``saved`` (the checkpoint's ``expert_digests``); a checkpoint written before digests were kept names only
    its experts folder, so every mode counts as changed when the folder differs and none when it is the same."""
    if saved is None:
        return [] if str(saved_dir) == str(experts_dir) else list(digests)
    return [m for m, d in digests.items() if saved.get(m) != d]


def walked_modes(modes: Sequence[str], repeats: Optional[Dict[str, int]]) -> list:
    """``env.mode_repeats``: ``modes`` with mode ``m`` written ``repeats[m]`` times in a row, as the
    multi-skill env walks them (:func:`tasks.base.pair_walk` takes one pair per listed mode per round),
    so the student meets that mode's states ``repeats[m]`` times as often; the chains repeat with it."""
    repeats = dict(repeats or {})
    unknown = sorted(set(repeats) - set(modes))
    if unknown:
        raise ValueError(f"env.mode_repeats: {unknown} not among the run's modes {list(modes)}")
    bad = {m: k for m, k in repeats.items() if not isinstance(k, int) or isinstance(k, bool) or k < 1}
    if bad:
        raise ValueError(f"env.mode_repeats: repeats are whole numbers >= 1, got {bad}")
    return [m for m in modes for _ in range(repeats.get(m, 1))]


def chain_envs(multi_kwargs: dict, share: float, repeats: Optional[Dict[str, int]] = None) -> list:
    """``env.chain_share``: the long-horizon chains the student also acts in, as ``(env_id, kwargs)``
    alternates of the multi-skill env (:class:`unicross.rl.collector.Rollout`, which draws one uniformly): grasp,
    relocate, then each rotate or translate mode of the run's modes (the paper's Gr.+Re.+Rot. / Gr.+Re.+Trans.
    sequences, one per axis; a mode the walk repeats, ``env.mode_repeats``, as many times), on the multi-skill env's
    objects (default: the training set) and settings. ``repeats`` (``env.chain_repeats``, ``{mode: k}``) sets how
    many times the chain of ``m`` is listed instead (0 leaves it out), so it is drawn ``k`` times as often. Empty for
    a share of 0; refused when the modes lack grasp, relocate or any rotate or translate mode, or when ``repeats``
    names another mode, is not a whole number >= 0, or leaves no chain."""
    if not 0.0 <= share <= 1.0:
        raise ValueError(f"env.chain_share must be in [0, 1], got {share}")
    if share == 0.0:
        return []
    modes = list(multi_kwargs["modes"])
    walked = [m for m in modes if R.skill_of_mode(m).accumulates]  # rotate, translate
    if "grasp" not in modes or "relocate" not in modes or not walked:
        raise ValueError(f"env.chain_share > 0 needs grasp, relocate and a rotate or translate mode among env.modes, "
                         f"got {modes}")
    repeats = dict(repeats or {})
    unknown = sorted(set(repeats) - set(walked))
    if unknown:
        raise ValueError(f"env.chain_repeats: {unknown} not among the run's rotate and translate modes "
                         f"{sorted(set(walked))}")
    bad = {m: k for m, k in repeats.items() if not isinstance(k, int) or isinstance(k, bool) or k < 0}
    if bad:
        raise ValueError(f"env.chain_repeats: repeats are whole numbers >= 0, got {bad}")
    tails = [m for m in dict.fromkeys(walked) for _ in range(repeats.get(m, walked.count(m)))]
    if not tails:
        raise ValueError(f"env.chain_repeats={repeats} leaves no chain; set env.chain_share=0 for none")
    kw = {k: v for k, v in multi_kwargs.items() if k not in ("modes", "grasp_dataset")}
    kw.setdefault("objects", "train")
    return [("UniCross-Chain-v1", dict(kw, sequence=["grasp", "relocate", m])) for m in tails]


def mode_weight_vector(weights: Optional[Dict[str, float]], device=None) -> torch.Tensor:
    """``optim.mode_weights``: ``{mode: w}`` as a weight per mode index (``F.MODES`` order, 1 where not named); each
    row's squared action error counts ``w`` times in the batch's weighted mean. Refuses unknown modes and weights
    that are not positive numbers."""
    weights = dict(weights or {})
    unknown = sorted(set(weights) - set(F.MODES))
    if unknown:
        raise ValueError(f"optim.mode_weights: unknown mode(s) {unknown}; modes: {list(F.MODES)}")
    bad = {m: w for m, w in weights.items()
           if isinstance(w, bool) or not isinstance(w, (int, float)) or not (w > 0 and math.isfinite(w))}
    if bad:
        raise ValueError(f"optim.mode_weights: weights are positive finite numbers, got {bad}")
    return torch.tensor([float(weights.get(m, 1.0)) for m in F.MODES], device=device)


def check_l1(l1) -> float:
    """``optim.l1`` as a float; refuses anything but a finite number >= 0."""
    if isinstance(l1, bool) or not isinstance(l1, (int, float)) or not (l1 >= 0 and math.isfinite(l1)):
        raise ValueError(f"optim.l1 must be a finite number >= 0, got {l1!r}")
    return float(l1)


def distill_loss(pred: torch.Tensor, target: torch.Tensor, weight: torch.Tensor, l1: float = 0.0):
    """The student's loss on a batch: the rows' squared action errors (mean over the action), in a mean weighted by
    ``weight`` (per row; every weight 1: the paper's MSE), plus ``l1`` times the rows' absolute errors in the same
    mean (``optim.l1``). Near a label the squared error's gradient vanishes with the error, so a student keeps a
    small steady bias where its teachers answer 0 (a finger holding still), and a bias integrates into a drift of
    the commands; the absolute error's gradient does not vanish. Returns (loss, the rows' squared errors)."""
    check_l1(l1)
    diff = pred - target
    err = (diff ** 2).mean(-1)
    per_row = err + l1 * diff.abs().mean(-1) if l1 > 0 else err
    return (weight * per_row).sum() / weight.sum(), err


class Teachers(torch.nn.Module):
    """The frozen experts; labels a batch by each state's mode (read from g's one-hot)."""

    def __init__(self, paths: Dict[str, Path], device):
        super().__init__()
        self.experts = torch.nn.ModuleDict()
        self.hand = None
        for m, p in paths.items():
            pol, ck = load_policy(p, device)
            if base_policy_of(ck) is not None:
                raise ValueError(f"expert {p} acts on top of the gait {base_policy_of(ck)} (model.base_policy): "
                                 "DAgger distils experts that are networks alone")
            trained = R.trained_mode(ck.get("skill"), ck.get("axis"))
            if trained != m:
                raise ValueError(f"expert {p} was trained for mode {trained!r}, not {m!r}: each mode's folder "
                                 f"needs that mode's expert")
            self.n_act = ck["n_act"]
            if self.hand is None:
                self.hand = ck["hand"]
            elif ck["hand"] != self.hand:
                raise ValueError(f"expert {p} is for hand {ck['hand']!r}, the others for {self.hand!r}")
            for prm in pol.parameters():
                prm.requires_grad_(False)
            self.experts[m.replace("+", "p").replace("-", "m")] = pol.eval()
        self.modes = list(paths)

    @torch.no_grad()
    def forward(self, td: TensorDict) -> torch.Tensor:
        mode = td["goal"][..., :F.NUM_MODES].argmax(-1)
        out = torch.zeros(td.batch_size + (self.n_act,), device=td.device)
        with set_exploration_type(ExplorationType.DETERMINISTIC):
            for m in self.modes:
                mask = mode == F.MODES.index(m)
                if bool(mask.any()):
                    sub = td[mask].select(*OBS_KEYS)
                    out[mask] = self.experts[m.replace("+", "p").replace("-", "m")](sub)["action"]
        return out.clamp(-1.0, 1.0)


class DAggerTrainer(Runner):
    STEP_KEY = "epoch"

    def __init__(self, run_dir, experts_dir=None, overrides: Optional[dict] = None, resume: bool = False,
                 progress: bool = True):
        if not resume and experts_dir is None:
            raise ValueError("--experts is required")
        super().__init__(run_dir, resume, overrides, "dagger", progress)
        try:
            self._build(experts_dir)
        except BaseException:  # whatever failed, no worker is left behind and the directory is free
            self.close()
            raise

    def _build(self, experts_dir):
        cfg = self.cfg
        if self.ckpt is not None:
            experts_dir = experts_dir or self.ckpt["experts_dir"]
        self.experts_dir = str(experts_dir)
        modes = cfg["env"]["modes"] or list(F.MODES)
        paths = expert_paths(experts_dir, modes)  # refuses to start without every expert
        self.expert_digests = {m: file_digest(p) for m, p in paths.items()}
        ec = cfg["env"]
        kw = dict(randomize=ec["randomize"], modes=walked_modes(modes, ec.get("mode_repeats")),
                  reconfiguration_freq=ec["reconfiguration_freq"] if ec["backend"] == "physx_cpu" else 0,
                  config=ec["task_config"] or None)
        if ec.get("objects"):
            kw["objects"] = ec["objects"]
        if ec.get("object_limit") is not None:
            kw["object_limit"] = ec["object_limit"]
        if ec.get("grasp_dataset"):
            kw["grasp_dataset"] = grasp_dataset_file(ec["grasp_dataset"])
        # the learner's device (teachers, student, labels, updates): optim.update_device, null: the envs'
        self.device = resolve_update_device(cfg["optim"].get("update_device"), ec["backend"])
        self.share_cores(ec["backend"])
        self.teachers = Teachers(paths, self.device)
        kw["hand"] = self.teachers.hand
        unknown = sorted(set(cfg["optim"].get("label_noise_modes") or []) - set(F.MODES))
        if unknown:
            raise ValueError(f"optim.label_noise_modes: unknown mode(s) {unknown}; modes: {list(F.MODES)}")
        self.mode_weights = mode_weight_vector(cfg["optim"].get("mode_weights"), self.device)
        self.l1 = check_l1(cfg["optim"].get("l1") or 0.0)
        start = None  # model.init_policy: read and checked before any worker starts
        if self.ckpt is None and cfg["model"].get("init_policy"):
            start = policy_to_start_from(cfg["model"]["init_policy"], "multi", None, self.teachers.hand)
            adopt_input_floor(cfg["model"], start)
        self.env_kwargs = kw
        # the student acts (its mean action) in worker processes with shared weights (lean collector),
        # or in Ray env actors (collector.ray_address)
        ray_address = cfg["collector"].get("ray_address")
        seed = cfg["seed"] + 1000 * int((self.ckpt or {}).get("epoch", 0))
        num_envs = resolve_num_envs(ec["num_envs"], ec["backend"], ray_address)
        self.overlap = bool(cfg["collector"].get("overlap", False))
        check_overlap(self.overlap, ec["backend"], num_envs, ray_address)
        chain_share = float(ec.get("chain_share") or 0.0)
        self.collector = make_collector("UniCross-MultiSkill-v1", kw, num_envs, cfg["collector"]["rollout_steps"], seed,
                                        ec["backend"], ray_address, deterministic=True,
                                        alternates=chain_envs(kw, chain_share, ec.get("chain_repeats")),
                                        alternate_share=chain_share)
        self.dims, self.n_act = self.collector.dims, self.collector.n_act
        self.student, _, self.norm = make_models(self.dims, self.n_act, Bounded(-1.0, 1.0, (self.n_act,)),
                                                 cfg["model"])
        if start is not None:
            if dict(start["obs_dims"]) != dict(self.dims) or int(start["n_act"]) != self.n_act:
                raise ValueError(f"model.init_policy={cfg['model']['init_policy']}: observation sizes "
                                 f"{start['obs_dims']} and {start['n_act']} actions, this run has {self.dims} and "
                                 f"{self.n_act}")
            self.student.load_state_dict(start["policy"])  # weights and observation statistics
        self.student.to(self.device)
        self.actor = self.student.module[0]  # hand/object/goal -> loc, scale
        self.optim = torch.optim.Adam(self.actor.parameters(), lr=cfg["optim"]["lr"])
        # the replay buffer stays with the envs' batches (the CPU for CPU env workers); minibatches go to the learner
        self.rb = TensorDictReplayBuffer(storage=LazyTensorStorage(cfg["buffer"]["capacity"],
                                                                   device=self.collector.device),
                                         batch_size=cfg["optim"]["batch_size"])
        self.epoch, self.frames = 0, 0
        if self.ckpt is not None:
            self._load(self.ckpt)
        # after loading: the workers share these weights (overlap, or a learner on the GPU: a copy of them on the
        # envs' device, synced per epoch)
        self._elsewhere = not same_device(self.device, self.collector.device)
        self.collector.set_actor(self.actor.module, own_copy=self.overlap or self._elsewhere)

    # ------------------------------------------------------------------ state
    def state(self) -> dict:
        learner = dict(policy=self.student.state_dict(), optim=self.optim.state_dict())
        return dict(**self.runner_state(), **(on_cpu(learner) if self._elsewhere else learner),
                    epoch=self.epoch, frames=self.frames, experts_dir=self.experts_dir,
                    expert_digests=self.expert_digests, skill="multi", axis=None,
                    hand=self.teachers.hand, obs_dims=self.dims, n_act=self.n_act, modes=list(F.MODES),
                    distilled_modes=list(self.teachers.modes), env_kwargs=self.env_kwargs)

    def save(self):
        """The replay buffer goes to a new directory named by the epoch, then the checkpoint that
        names it is written atomically, then older buffers are removed: a crash at any point leaves
        a checkpoint and the buffer it names."""
        self.run_dir.mkdir(parents=True, exist_ok=True)
        replay = None
        if len(self.rb):
            replay = f"replay-{self.epoch:06d}"
            tmp = self.run_dir / f"{replay}.{os.getpid()}.tmp"
            shutil.rmtree(tmp, ignore_errors=True)
            self.rb.dumps(tmp)
            shutil.rmtree(self.run_dir / replay, ignore_errors=True)
            os.replace(tmp, self.run_dir / replay)
        atomic_save(dict(self.state(), replay_dir=replay), self.run_dir / CKPT_NAME)
        for old in self.run_dir.glob("replay*"):
            if old.name != replay and old.is_dir():
                shutil.rmtree(old, ignore_errors=True)

    def _load(self, ck):
        self.student.load_state_dict(ck["policy"])
        self.optim.load_state_dict(ck["optim"])
        lr, was = self.cfg["optim"]["lr"], ck["config"]["optim"]["lr"]
        for g in self.optim.param_groups:  # the saved state carries the old rate: a resumed run takes optim.lr
            g["lr"] = lr
        if lr != was:
            print(f"[unicross] resumed with optim.lr={lr:g} (was {was:g})")
        self.epoch, self.frames = ck["epoch"], ck["frames"]
        self.load_runner_state(ck)
        replay = self.run_dir / ck.get("replay_dir", "replay")  # "replay": checkpoints before named buffers
        if ck.get("replay_dir", "replay") and replay.exists():
            self.rb.loads(replay)
            changed = changed_teachers(ck.get("expert_digests"), ck.get("experts_dir"), self.expert_digests,
                                       self.experts_dir)
            if changed:
                n = self.relabel(changed)
                which = (", ".join(changed) if ck.get("expert_digests") is not None else
                         f"every mode (a checkpoint without teacher digests, labelled by {ck.get('experts_dir')})")
                print(f"[unicross] resumed with other teachers for {which}: {n} stored rows labelled again by them")

    @torch.no_grad()
    def relabel(self, modes: Sequence[str], chunk: int = 65536) -> int:
        """Labels the replay buffer's rows of ``modes`` again by the current teachers (a resumed run whose
        teachers changed: DAgger fits the labels of the teachers it distils now, not of those that labelled the
        buffer). Returns the number of rows labelled."""
        storage, n, done = self.rb.storage, len(self.rb), 0
        wanted = torch.tensor([F.MODES.index(m) for m in modes])
        for start in range(0, n, chunk):
            rows = torch.arange(start, min(start + chunk, n))
            td = storage.get(rows)
            sel = torch.isin(td["mode"], wanted.to(td["mode"].device))
            if not bool(sel.any()):
                continue
            sub = td[sel]
            labels = self.teachers(sub.select(*OBS_KEYS).to(self.device))
            sub["expert_action"] = labels.to(sub.device)
            storage.set(rows[sel.cpu()], sub, set_cursor=False)
            done += int(sel.sum())
        return done

    # ------------------------------------------------------------------ one epoch
    @torch.no_grad()
    def collect(self, more: bool = False) -> dict:
        """Roll the student out for ``rollout_steps`` (deterministic actions); label every visited
        state by its mode's expert; store (observation, expert action, mode). With
        ``collector.overlap`` the rollout was made during the previous epoch's update, with the
        student of the epoch before (DAgger's labels do not depend on who acted); the workers then
        take the current student and, if ``more`` epochs follow, start the next rollout."""
        if self.overlap:
            data = self.collector.next_overlapped(more)
        else:
            self.collector.sync_actor()  # a copy (learner on the GPU) takes the last update's weights
            data = self.collector.collect()
        flat = data.reshape(-1).to(self.device)
        labels = self.teachers(flat)
        item = flat.select(*OBS_KEYS).clone()
        item["expert_action"] = labels
        item["mode"] = flat["goal"][..., :F.NUM_MODES].argmax(-1)
        self.rb.extend(item.to(self.collector.device) if self._elsewhere else item)
        self.norm.update({k: item[k] for k in OBS_KEYS})
        self.frames += flat.numel()
        done = flat["next", "done"].squeeze(-1)
        succ = flat["next", "info", "success"].squeeze(-1)
        stats = {}
        for i, m in enumerate(F.MODES):
            sel = done & (item["mode"] == i)
            if bool(sel.any()):
                stats[f"success/{m}"] = float(succ[sel].float().mean())
        return stats

    def update(self) -> dict:
        """``grad_steps`` steps of ``distill_loss`` on replay batches (rows weighted by ``optim.mode_weights``, plus
        ``optim.l1`` times the absolute error; 0: the paper's MSE). Returns the mean
        loss, and the MSE overall and per mode on the batches' stored states (with ``optim.label_noise``: on the rows
        left as stored, and ``mse_perturbed`` on the others)."""
        oc = self.cfg["optim"]
        noise = float(oc.get("label_noise") or 0.0)
        total, clean, noisy = 0.0, 0.0, 0.0
        per_mode, counts = torch.zeros(F.NUM_MODES), torch.zeros(F.NUM_MODES)
        for _ in range(oc["grad_steps"]):
            b = self.rb.sample()
            if self._elsewhere:
                b = b.to(self.device)
            obs, target = b.select(*OBS_KEYS).clone(), b["expert_action"]
            moved = torch.zeros(obs.batch_size[0], dtype=torch.bool, device=target.device)
            if noise > 0:
                moved = self._perturb(obs, b["mode"], noise, float(oc.get("label_noise_share", 0.5)))
            any_moved = bool(moved.any())
            if any_moved:
                target = target.clone()
                target[moved] = self.teachers(obs[moved])
            pred = self.actor(obs)["loc"]
            loss, err = distill_loss(pred, target, self.mode_weights[b["mode"]], self.l1)
            self.optim.zero_grad(set_to_none=True)
            loss.backward()
            self.optim.step()
            total += float(loss.detach())
            with torch.no_grad():
                e, kept = err.detach(), ~moved
                clean += float(e[kept].mean()) if not bool(moved.all()) else 0.0
                noisy += float(e[moved].mean()) if any_moved else 0.0
                per_mode.index_add_(0, b["mode"][kept].cpu(), e[kept].cpu())
                counts.index_add_(0, b["mode"][kept].cpu(), torch.ones_like(e[kept]).cpu())
        steps = oc["grad_steps"]
        out = {"loss": total / steps, "mse": clean / steps}
        if noise > 0:
            out["mse_perturbed"] = noisy / steps
        for i, m in enumerate(F.MODES):
            if counts[i] > 0:
                out[f"mse/{m}"] = float(per_mode[i] / counts[i])
        return out

    @torch.no_grad()
    def _perturb(self, obs: TensorDict, mode: torch.Tensor, noise: float, share: float) -> torch.Tensor:
        """Adds Gaussian noise to the hand and object observations of the rows among the first ``share``
        of ``obs`` (a random sample, so a random subset) whose mode is one of ``optim.label_noise_modes``:
        ``noise`` standard deviations of each feature as the student's normaliser divides it (the goal,
        which routes a row to its teacher, is left as is). Returns the mask of the rows changed; their
        labels become the teachers' actions on the changed observations, so the student learns the
        teachers' answers around the states it visits too."""
        moved = torch.zeros(obs.batch_size[0], dtype=torch.bool, device=mode.device)
        moved[:int(round(share * obs.batch_size[0]))] = True
        modes = self.cfg["optim"].get("label_noise_modes")
        if modes is not None:
            moved &= torch.isin(mode, torch.tensor([F.MODES.index(m) for m in modes], device=mode.device))
        n = self.norm
        for key in ("hand", "object"):
            std = torch.sqrt(getattr(n, f"{key}_var") + 1e-8).clamp_min(n.std_min)
            x = obs[key]
            x[moved] += noise * std * torch.randn_like(x[moved])
        return moved

    @torch.no_grad()
    def action_mse(self, td: TensorDict) -> Dict[str, float]:
        """Per-mode MSE between the student's mean action and the experts' labels on ``td``."""
        td = td.to(self.device)
        labels = self.teachers(td)
        pred = self.actor(td.select(*OBS_KEYS).clone())["loc"]
        err = ((pred - labels) ** 2).mean(-1)
        mode = td["goal"][..., :F.NUM_MODES].argmax(-1)
        return {m: float(err[mode == i].mean()) for i, m in enumerate(F.MODES) if bool((mode == i).any())}

    def train(self, epochs: Optional[int] = None) -> dict:
        target = self.cfg["optim"]["epochs"] if epochs is None else self.epoch + epochs
        self.open_logs()
        bar = tqdm(total=target, initial=self.epoch, desc="dagger", unit="epoch", disable=not self.progress)
        last = {}
        try:
            with self.stop_on_signals():
                last = self._epochs(target, bar)
            self.save()  # not after an error: the last checkpoint stays as it was
        finally:
            bar.close()
            self.close_logs()
        return last

    def _epochs(self, target: int, bar) -> dict:
        """Epochs (collect, label, update, log, periodic checkpoint) until ``target`` or a stop signal."""
        last = {}
        while self.epoch < target and self.stop_signal is None:
            t0 = time.perf_counter()
            more = self.epoch + 1 < target
            self.take_update_threads(busy_cores=self.collector.num_envs if self.overlap and more else 0)
            col = self.collect(more=more)
            upd = self.update() if len(self.rb) >= int(self.cfg["optim"].get("warmup_frames") or 0) else {}
            self.epoch += 1
            last = dict(epoch=self.epoch, frames=self.frames, wall_s=self._wall(), buffer=len(self.rb),
                        seconds=time.perf_counter() - t0, **upd, **col)
            self.log_json(last)
            self.log_scalars(last, self.frames)
            if self.epoch % self.cfg["logging"]["checkpoint_every"] == 0:
                self.save()
            bar.update(1)
            bar.set_postfix(mse=f"{upd['mse']:.4f}" if upd else "warm-up")
        return last

    def close(self):
        try:
            if getattr(self, "collector", None) is not None:
                self.collector.close()
        finally:
            self.release()
