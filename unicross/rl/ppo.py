"""The runner that trains one UniCross expert with PPO (rsl_rl's split: the algorithm, GAE ->
minibatches -> ClipPPOLoss -> Adam with a KL-adaptive rate, is :class:`unicross.rl.algorithm.PPO`;
this module owns collection, evaluation, logging, checkpoints and resume).

On the CPU the collector runs one env per worker process with the actor inside the worker
(:mod:`unicross.rl.collector`); the main process does GAE and the update.

Checkpoints (weights, optimiser, iteration, frames, learning rate, RNG states, config, git commit)
are written atomically every ``logging.checkpoint_every`` iterations and on exit; ``resume=True``
continues the same run directory at the next iteration. Metrics go to ``metrics.csv``,
``metrics.jsonl`` and TensorBoard (``tb/``).
"""
from __future__ import annotations

import json
import math
import sys
import time
from typing import Optional

import torch
from tensordict import TensorDict
from tqdm import tqdm

from unicross import formulation as F
from unicross import registry as R
from unicross.grasps import grasp_dataset_file
from unicross.rewards import term_names
from unicross.rl.algorithm import PPO, obs_stats_frozen
from unicross.rl.collector import (check_overlap, check_teacher, make_collector, resolve_num_envs,
                                   resolve_update_device, same_device)
from unicross.rl.models import OBS_KEYS  # noqa: F401  (re-exported for benchmarks)
from unicross.rl.runner import CKPT_NAME, Runner, atomic_save, git_commit, on_cpu, open_run  # noqa: F401  (re-exported)


def resolve_horizon(collector_cfg: dict, skill: str, num_envs: int) -> int:
    """Steps per env per iteration: ``collector.horizon`` if set; else ``frames_per_batch`` split
    over the envs (rounded up); else the paper's horizon of the skill."""
    if collector_cfg.get("horizon"):
        return int(collector_cfg["horizon"])
    if collector_cfg.get("frames_per_batch"):
        return -(-int(collector_cfg["frames_per_batch"]) // num_envs)
    return R.skill(skill).ppo_horizon


CSV_BASE = ["iteration", "frames", "wall_s", "fps", "collect_s", "update_s", "reward_raw", "reward_scaled", "episodes",
            "episode_return", "success_rate", "loss_objective", "loss_critic", "entropy", "kl", "clip_fraction",
            "ESS", "explained_variance", "value_clip_fraction", "grad_norm_actor", "grad_norm_critic", "lr",
            "value_mean", "value_std", "nonfinite"]


def csv_fields() -> list:
    """metrics.csv columns: the training statistics and the mean of every registered reward term."""
    return CSV_BASE + [f"reward_{t}" for t in term_names()]


def env_kwargs_for(skill: str, axis: Optional[str], hand: str, env_cfg: dict) -> dict:
    """The env constructor arguments of one expert (validates skill and axis before any simulation)."""
    kw = dict(R.skill(skill).env_kwargs(axis), hand=hand, randomize=env_cfg["randomize"],
              reconfiguration_freq=env_cfg["reconfiguration_freq"] if env_cfg["backend"] == "physx_cpu" else 0)
    task = dict(env_cfg.get("task_config") or {})
    ends = (env_cfg.get("terminate_on_drop") or {}).get(skill)
    if ends is not None and "terminate_on_drop" not in task:  # a run's own task_config wins
        task["terminate_on_drop"] = bool(ends)
    if task:
        kw["config"] = task
    if env_cfg.get("reward_config"):
        kw["reward_config"] = env_cfg["reward_config"]
    if env_cfg.get("objects"):
        kw["objects"] = env_cfg["objects"]
    if env_cfg.get("object_limit") is not None:
        kw["object_limit"] = env_cfg["object_limit"]
    if env_cfg.get("grasp_dataset") and not R.skill(skill).starts_on_table:
        kw["grasp_dataset"] = grasp_dataset_file(env_cfg["grasp_dataset"])
    return kw


def policy_to_start_from(path, skill: str, axis: Optional[str], hand: str, base_policy: Optional[str] = None) -> dict:
    """The policy checkpoint that ``model.init_policy`` names (e.g. a gait cloned by
    ``benchmarks/gait_clone.py``), refused unless it acts for this run's skill, axis and hand, on top
    of the same base gait (``model.base_policy``) or of none, as this run."""
    from unicross.rl.policy_io import base_policy_of, read_torch_file, resolve_checkpoint, check_modes
    path = resolve_checkpoint(path)
    ck = read_torch_file(path, "checkpoint")
    if not isinstance(ck, dict) or "policy" not in ck or "obs_dims" not in ck:
        raise ValueError(f"model.init_policy={path} is not a UniCross policy checkpoint")
    check_modes(ck, path)
    theirs, ours = (ck.get("skill"), ck.get("axis"), ck.get("hand")), (skill, axis, hand)
    if theirs != ours:
        raise ValueError(f"model.init_policy={path} acts for skill/axis/hand {theirs}, this run trains {ours}")
    if base_policy_of(ck) != base_policy:
        raise ValueError(f"model.init_policy={path} acts on top of base policy {base_policy_of(ck)}, this run on "
                         f"{base_policy} (model.base_policy)")
    return ck


def adopt_input_floor(model_cfg: dict, ck: dict) -> None:
    """The run's ``model.obs_std_min`` becomes the one ``ck`` (the ``model.init_policy`` checkpoint) was
    trained with: the floor of the std its inputs are divided by is part of that policy (the
    normaliser's statistics come with its weights, the floor is configuration), so a run started
    from it under another floor would start from another policy. Says so when it changes the value."""
    floor = float(((ck.get("config") or {}).get("model") or {}).get("obs_std_min") or 0.0)
    if float(model_cfg.get("obs_std_min") or 0.0) != floor:
        print(f"[unicross] model.obs_std_min={floor}: the input floor model.init_policy was trained with "
              f"(the run's configuration had {model_cfg.get('obs_std_min')})", file=sys.stderr, flush=True)
        model_cfg["obs_std_min"] = floor


def evaluation_shard(actor, skill: str, objects: str, limit, trials_per_object: int, seed: int, hand: str,
                     axis: Optional[str], ablation: Optional[dict], shard, base_policy: Optional[str] = None,
                     sim: Optional[dict] = None) -> list:
    """One worker's share of a held-out evaluation (see :meth:`PPOTrainer._protocol`), under the run's
    physics (``sim``: its ``env.task_config.sim`` overrides)."""
    from unicross import evaluation as E
    from unicross.objects import get_object_set
    from unicross.rl.policy_io import policy_fn
    return E.run_protocol(skill, policy_fn(actor, base_policy), get_object_set(objects, limit=limit),
                          hand=hand, trials_per_object=trials_per_object, seed=seed, progress=False,
                          axes=[axis] if axis else None, ablation=ablation, shard=shard, sim=sim)


class PPOTrainer(Runner):
    """One expert: ``skill`` (+ ``axis`` for rotate/translate) on ``hand``."""

    def __init__(self, run_dir, skill: Optional[str] = None, axis: Optional[str] = None, hand: Optional[str] = None,
                 overrides: Optional[dict] = None, resume: bool = False, progress: bool = True):
        if not resume:  # before the run directory is made
            from unicross.robots.hand import load_hand
            R.skill(skill or "grasp").mode(axis)
            load_hand(hand or "allegro")
        super().__init__(run_dir, resume, overrides, "ppo", progress)
        try:
            self._build(skill, axis, hand, overrides)
        except BaseException:  # whatever failed, no worker is left behind and the directory is free
            self.close()
            raise

    def _build(self, skill, axis, hand, overrides):
        cfg = self.cfg
        if self.ckpt is not None:  # a resumed run keeps what it trains; a contradiction is refused
            ck = dict(skill=self.ckpt["skill"], axis=self.ckpt["axis"], hand=self.ckpt["hand"])
            asked = dict(skill=skill, axis=axis, hand=hand)
            bad = [f"--{k} {v} (the run trains {ck[k]})" for k, v in asked.items() if v is not None and v != ck[k]]
            if bad:
                raise ValueError(f"cannot resume {self.run_dir} with {', '.join(bad)}: start a new run with another --out")
            skill, axis, hand = ck["skill"], ck["axis"], ck["hand"]
        skill, hand = skill or "grasp", hand or "allegro"
        from unicross.robots.hand import load_hand
        spec = load_hand(hand)  # validates
        start_mean, start_policy = None, None
        if self.ckpt is None and cfg["model"].get("init_policy"):  # refused before any simulation
            start_policy = policy_to_start_from(cfg["model"]["init_policy"], skill, axis, hand,
                                                cfg["model"].get("base_policy"))
            adopt_input_floor(cfg["model"], start_policy)
        # what the run started from, kept in its checkpoints (a resumed run keeps its own record)
        self.started_from = (self.ckpt or {}).get("started_from")
        if start_policy is not None:
            self.started_from = dict(policy=str(cfg["model"]["init_policy"]), clone_of=start_policy.get("clone_of"))
        obs_stats_frozen(cfg["model"])  # a bad model.obs_stats is refused before any simulation
        if self.ckpt is None and cfg["model"].get("init_reference") is not None:
            from unicross.audit import reference_action
            start_mean = reference_action(skill, axis, spec, float(cfg["model"]["init_reference"]))
        self.skill, self.axis, self.hand = skill, axis, hand
        self.env_id = R.skill(skill).env_id
        self.env_kwargs = env_kwargs_for(skill, axis, hand, cfg["env"])
        ec = cfg["env"]
        teacher, base = cfg["collector"].get("teacher"), cfg["model"].get("base_policy")
        if base is not None and teacher is not None and teacher != base:
            raise ValueError(f"collector.teacher={teacher} and model.base_policy={base} differ: the base gait "
                             "labels the collected states itself (leave collector.teacher null or set it the same)")
        check_teacher(base, skill, axis, ec["backend"], cfg["collector"].get("ray_address"), what="model.base_policy")
        teacher = teacher or base
        check_teacher(teacher, skill, axis, ec["backend"], cfg["collector"].get("ray_address"))
        if float(cfg["loss"].get("teacher_coef", 0.0)) > 0.0 and base is not None:
            raise ValueError("loss.teacher_coef pulls the network's action toward the gait's, but with model.base_policy "
                             "the network's action is added to the gait's: leave loss.teacher_coef at 0")
        if float(cfg["loss"].get("teacher_coef", 0.0)) > 0.0 and teacher is None:
            raise ValueError("loss.teacher_coef > 0 needs collector.teacher (e.g. allegro/rotate_y-)")
        self.share_cores(ec["backend"])
        num_envs = resolve_num_envs(ec["num_envs"], ec["backend"], cfg["collector"].get("ray_address"))
        self.overlap = bool(cfg["collector"].get("overlap", False))
        check_overlap(self.overlap, ec["backend"], num_envs, cfg["collector"].get("ray_address"))
        learner_device = resolve_update_device(cfg["optim"].get("update_device"), ec["backend"])
        self.horizon = resolve_horizon(cfg["collector"], skill, num_envs)
        # envs of a resumed run start from new seeds (not a replay of the first iteration's starts)
        seed = cfg["seed"] + 1000 * int((self.ckpt or {}).get("iteration", 0))
        self.collector = make_collector(self.env_id, self.env_kwargs, num_envs, self.horizon, seed, ec["backend"],
                                        cfg["collector"].get("ray_address"),
                                        noise_correlation=float(cfg["collector"].get("noise_correlation", 0.0)),
                                        teacher=teacher, residual=base is not None)
        self.device = self.collector.device  # the batches' (episode statistics are kept there)
        self.learner_device = learner_device  # the networks', GAE's and the update's
        dims, self.n_act = self.collector.dims, self.collector.n_act
        self.algo = PPO(dims, self.n_act, cfg, self.collector.frames_per_batch, self.learner_device)
        if start_mean is not None:
            self.algo.actor.start_mean_at(start_mean.to(self.learner_device))
        if start_policy is not None:
            self.algo.start_policy_from(start_policy, cfg["model"]["init_policy"])
        self.iteration, self.frames = 0, 0
        self.dims = dims
        if self.ckpt is not None:
            self._load_state(self.ckpt)
            lr = ((overrides or {}).get("optim") or {}).get("lr")
            if lr is not None:  # the resumed optimiser carries its scheduled rate: the override replaces it
                self.algo.lr = float(lr)
                for g in self.algo.optim.param_groups:
                    g["lr"] = self.algo.lr
                print(f"[unicross] resumed with optim.lr={self.algo.lr:g} (the KL schedule goes on from there)")
            before = self.ckpt["config"]
            for path in ("env.num_envs", "collector.frames_per_batch", "collector.horizon"):
                sec, key = path.split(".")
                if before[sec].get(key) != cfg[sec].get(key):
                    print(f"[unicross] resumed with {path}={cfg[sec].get(key)} (was {before[sec].get(key)}): "
                          f"{num_envs} envs x {self.horizon} steps = {num_envs * self.horizon} frames per iteration")
        # after loading: the workers share these weights (overlap, or a learner on the GPU: a copy of
        # them on the envs' device, synced per batch)
        self._elsewhere = not same_device(self.learner_device, self.device)
        self.collector.set_actor(self.algo.actor, own_copy=self.overlap or self._elsewhere)
        self._ep_return = torch.zeros(num_envs, 1, device=self.device)
        # the episode's success as the skill's protocol counts it (``Skill.success_once``: reached at any
        # step, never dropped; else at its last step), over the training episode
        self._success_once = R.skill(self.skill).success_once
        self._ep_reached = torch.zeros(num_envs, 1, dtype=torch.bool, device=self.device)
        self._ep_dropped = torch.zeros(num_envs, 1, dtype=torch.bool, device=self.device)

    # ------------------------------------------------------------------ state
    # the algorithm's parts, for inspection
    policy = property(lambda self: self.algo.policy)
    value = property(lambda self: self.algo.value)
    norm = property(lambda self: self.algo.norm)
    optim = property(lambda self: self.algo.optim)

    def state(self) -> dict:
        algo = self.algo.state_dict()
        return dict(**(on_cpu(algo) if self._elsewhere else algo), **self.runner_state(),
                    iteration=self.iteration, frames=self.frames, skill=self.skill,
                    axis=self.axis, hand=self.hand, env_id=self.env_id, env_kwargs=self.env_kwargs,
                    obs_dims=self.dims, n_act=self.n_act, modes=list(F.MODES),
                    **({"started_from": self.started_from} if self.started_from else {}))

    def _load_state(self, ck: dict):
        self.algo.load_state_dict(ck)
        self.iteration, self.frames = ck["iteration"], ck["frames"]
        self.load_runner_state(ck)

    # ------------------------------------------------------------------ evaluation
    @torch.no_grad()
    def _protocol(self, objects: str, limit, trials_per_object: int, seed: int):
        """(trials, summary) of the paper's protocol for this expert's skill (and axis) on the first
        ``limit`` objects per group of ``objects``, deterministic actions, with the run's ablation
        switches: run by the collector's env workers (objects split between them; trials are seeded
        per object, so the result does not depend on the number of workers) in envs of their own."""
        from unicross import evaluation as E
        from unicross.objects import get_object_set
        objs = get_object_set(objects, limit=limit)
        shards = self.collector.map_shards(
            evaluation_shard, skill=self.skill, objects=objects, limit=limit, trials_per_object=trials_per_object,
            seed=seed, hand=self.hand, axis=self.axis, ablation=(self.cfg["env"].get("task_config") or {}).get("ablation"),
            base_policy=self.cfg["model"].get("base_policy"), sim=(self.cfg["env"].get("task_config") or {}).get("sim"))
        trials = E.merge_shards(self.skill, objs, shards)
        return trials, E.summarize(self.skill, trials)

    def evaluate(self) -> dict:
        """The in-training evaluation: a fixed held-out set (``logging.eval_objects``, first
        ``eval_limit`` objects per group, ``eval_trials`` trials each) with fixed seeds, so every
        evaluation of a run sees the same objects and starts. The pose, angle and distance
        columns are means over the trials that kept the object (``eval_non_dropped`` of
        ``eval_n``): NaN when every trial dropped it."""
        lc = self.cfg["logging"]
        _, summ = self._protocol(lc["eval_objects"], lc["eval_limit"], lc["eval_trials"], lc["eval_seed"])
        out = dict(eval_success=summ["sr"] / 100.0, eval_ci95_low=summ["ci95"][0] / 100.0,
                   eval_ci95_high=summ["ci95"][1] / 100.0, eval_n=summ["n"],
                   eval_non_dropped=summ["non_dropped"])
        for k in ("pe_cm", "ae_rad", "rot_rad", "trans_cm"):
            if k in summ:
                out[f"eval_{k}"] = summ[k]
        return out

    # ------------------------------------------------------------------ training
    def _episode_stats(self, data: TensorDict) -> dict:
        """Returns and successes of the episodes that ended in this batch (data: [..., T]). An episode's
        success is the protocol's rule over the training episode: for a ``success_once`` skill (rotate,
        translate) the success test held at some step and the object was never dropped (the per-step
        flag of its last step misses the turns and pushes that pass the threshold and slide back);
        otherwise the flag at its last step."""
        rew = data["next", "reward"]
        done = data["next", "done"]
        succ = data["next", "info", "success"]
        drop = data["next", "info", "drop"]
        ret, reached, dropped = self._ep_return, self._ep_reached, self._ep_dropped
        finished_r, finished_s = [], []
        for t in range(rew.shape[-2]):
            ret = ret + rew[..., t, :]
            reached = reached | succ[..., t, :]
            dropped = dropped | drop[..., t, :]
            d = done[..., t, :]
            ok = reached & ~dropped if self._success_once else succ[..., t, :]
            finished_r.append(ret[d])
            finished_s.append(ok[d].float())
            ret = torch.where(d, torch.zeros_like(ret), ret)
            reached, dropped = reached & ~d, dropped & ~d
        self._ep_return, self._ep_reached, self._ep_dropped = ret, reached, dropped
        r, s = torch.cat(finished_r), torch.cat(finished_s)
        out = {"episodes": int(r.numel())}
        if r.numel():
            out.update(episode_return=float(r.mean()), success_rate=float(s.mean()))
        return out

    def train(self, max_iterations: Optional[int] = None, eval_at_ends: bool = True) -> dict:
        """Collect and update until ``collector.total_frames`` (or ``max_iterations`` more
        iterations), with the held-out evaluations of ``logging``; returns their summaries."""
        self.open_logs()
        try:
            return self._train(max_iterations, eval_at_ends)
        finally:
            self.close_logs()

    def _train(self, max_iterations: Optional[int], eval_at_ends: bool) -> dict:
        total = self.cfg["collector"]["total_frames"]
        remaining = max(0, total - self.frames)
        self.run_dir.mkdir(parents=True, exist_ok=True)
        (self.run_dir / "config.json").write_text(json.dumps(dict(config=self.cfg, skill=self.skill, axis=self.axis,
                                                                  hand=self.hand, git_commit=self.commit), indent=1))
        summary = {}
        lc = self.cfg["logging"]
        evaluating = eval_at_ends and lc["eval_trials"] > 0
        if evaluating and self.iteration == 0:
            summary["start"] = self.evaluate()
            self._log_eval(summary["start"])
        if remaining == 0:  # finished: only a missing or stale final evaluation is left to do
            self._final_if_due(summary, eval_at_ends)
            return summary
        bar = tqdm(total=total, initial=self.frames, unit="frame", desc=f"ppo {self.skill}", disable=not self.progress)
        try:
            with self.stop_on_signals():
                self._iterate(total, max_iterations, bar, evaluating)
            self.save()  # not after an error: the last checkpoint stays as it was
        finally:
            bar.close()
        if self.stop_signal is not None:
            return summary
        if evaluating and self.frames >= total:
            summary["end"] = self.evaluate()
            self._log_eval(summary["end"])
        if self.frames >= total:
            self._final_if_due(summary, eval_at_ends)
        return summary

    def _final_if_due(self, summary: dict, eval_at_ends: bool) -> None:
        """The held-out final evaluation of a finished run, unless ``final_eval.json`` already holds it."""
        if eval_at_ends and self.cfg["logging"]["final_eval_trials"] > 0 and not self._final_eval_current():
            summary["final"] = self.final_evaluation()

    def _final_eval_current(self) -> bool:
        """Whether the run directory's ``final_eval.json`` evaluated the policy as it is now (a run
        resumed with more ``--total-frames`` trains on, and its earlier final evaluation is replaced)."""
        path = self.run_dir / "final_eval.json"
        try:
            return json.loads(path.read_text()).get("frames") == self.frames
        except (OSError, ValueError):
            return False

    def _iterate(self, total: int, max_iterations: Optional[int], bar, evaluating: bool) -> None:
        """Iterations (collect, update, log, periodic checkpoint and evaluation) until ``total``
        frames, ``max_iterations`` more, or a stop signal."""
        lc = self.cfg["logging"]
        t_last = time.perf_counter()
        done_iters = 0
        while self.frames < total:
            if self.overlap:  # collected during the previous update, with the weights from before it
                data = self.collector.next_overlapped(more=self.frames + self.collector.frames_per_batch < total)
            else:
                self.collector.sync_actor()  # a copy (learner on the GPU) takes the last update's weights
                data = self.collector.collect()
            t_collect = time.perf_counter() - t_last
            self.iteration += 1
            self.frames += data.numel()
            ep = self._episode_stats(data)
            reward_raw = float(data["next", "reward"].mean())
            ep["nonfinite"] = int(data["next", "info", "nonfinite"].sum())
            t0 = time.perf_counter()
            self.take_update_threads(busy_cores=self.collector.num_envs if self.overlap and self.collector.pending else 0)
            up = self.algo.update(data.to(self.learner_device) if self._elsewhere else data)
            t_update = time.perf_counter() - t0
            bad = sorted(k for k, v in up.items() if isinstance(v, float) and not math.isfinite(v))
            if bad:  # an error: the last checkpoint stays as it was
                raise RuntimeError(f"non-finite {', '.join(bad)} at iteration {self.iteration}; stopped, the last "
                                   f"checkpoint is kept (lower optim.lr, or check env.task_config/reward_config)")
            terms = {k: float(data["next", "info", k].mean()) for k in data["next", "info"].keys()
                     if k.startswith("reward_")}
            row = dict(iteration=self.iteration, frames=self.frames, wall_s=self._wall(),
                       fps=data.numel() / max(t_collect + t_update, 1e-9), collect_s=t_collect, update_s=t_update,
                       reward_raw=reward_raw, reward_scaled=reward_raw * self.cfg["gae"]["reward_scale"],
                       **ep, **up, **terms)
            self._log(row)
            bar.update(data.numel())
            bar.set_postfix(ret=f"{row.get('episode_return', float('nan')):.2f}",
                            succ=f"{row.get('success_rate', float('nan')):.2f}")
            if self.iteration % lc["checkpoint_every"] == 0:
                self.save()
            if evaluating and lc["eval_every"] and self.iteration % lc["eval_every"] == 0:
                self._log_eval(self.evaluate())
            done_iters += 1
            t_last = time.perf_counter()
            if (max_iterations is not None and done_iters >= max_iterations) or self.stop_signal is not None:
                break

    def final_evaluation(self) -> dict:
        """The held-out evaluation of the finished expert: the paper's protocol for its skill on
        ``logging.final_eval_objects`` (first ``final_eval_limit`` per group, ``final_eval_trials``
        trials each, Wilson intervals), written as ``final_eval.json``/``.md`` in the run directory
        in the format of ``unicross eval``."""
        from unicross import evaluation as E
        lc = self.cfg["logging"]
        if self.progress:
            print(f"final evaluation: {self.skill} protocol on {lc['final_eval_objects']} objects "
                  f"(first {lc['final_eval_limit']} per group x {lc['final_eval_trials']} trials) ...", flush=True)
        trials, summ = self._protocol(lc["final_eval_objects"], lc["final_eval_limit"], lc["final_eval_trials"], seed=0)
        label = f"{self.skill}{'_' + self.axis if self.axis else ''} expert"
        result = dict(label=label, policy=dict(kind="checkpoint", path=str(self.run_dir / CKPT_NAME),
                                               skill=self.skill, axis=self.axis, git_commit=self.commit),
                      objects=lc["final_eval_objects"], limit=lc["final_eval_limit"], hand=self.hand,
                      trials_per_object=lc["final_eval_trials"], seed=0, disturb=False, original=False,
                      randomize=False, frames=self.frames, summaries={self.skill: summ}, trials={self.skill: trials})
        path = self.run_dir / "final_eval.json"
        path.write_text(json.dumps(result, indent=1))
        table = E.markdown_table({label: {self.skill: summ}})
        path.with_suffix(".md").write_text(table + "\n")
        print(f"held-out evaluation ({lc['final_eval_objects']}, first {lc['final_eval_limit']} objects per group x "
              f"{lc['final_eval_trials']} trials, paper protocol):\n{table}")
        return dict(success=summ["sr"] / 100.0, ci95_low=summ["ci95"][0] / 100.0, ci95_high=summ["ci95"][1] / 100.0,
                    n=summ["n"])

    def _log_eval(self, row: dict) -> None:
        """Evaluation rows go to metrics.jsonl, eval.csv and TensorBoard (``eval/*``)."""
        row = {"iteration": self.iteration, "frames": self.frames, "wall_s": self._wall(), **row}
        self.log_json(row)
        self.append_csv("eval.csv", row, list(row))
        self.log_scalars(row, self.frames, prefix="eval/")

    def _log(self, row: dict):
        self.log_json(row)
        self.append_csv("metrics.csv", row, csv_fields())
        self.log_scalars(row, self.frames)

    def close(self):
        collector = getattr(self, "collector", None)
        try:
            if collector is not None:
                collector.close()
        except Exception:
            pass
        self.release()
