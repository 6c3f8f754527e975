"""The PPO algorithm on its own: batches in, losses out (rsl_rl's algorithm/runner split).

:class:`PPO` owns the networks (actor, critic, running observation and return statistics), the
TorchRL loss (``ClipPPOLoss`` with a normalised, clipped critic), GAE, the optimiser and the
KL-adaptive learning rate. It knows nothing of environments, files or logs: the runner
(:class:`unicross.rl.ppo.PPOTrainer`) collects batches, calls :meth:`PPO.update` and logs the
dict it returns. So the update can be tested on synthetic TensorDicts without a simulator.

A batch is a TensorDict ``[..., T]`` with the collector's keys: ``hand``, ``object``, ``goal``,
``action``, ``action_log_prob``, ``loc``, ``scale`` and ``next`` (``hand``, ``object``, ``goal``,
``reward``, ``done``, ``terminated``, ``truncated``); with a teacher, ``teacher_action`` too
(see :meth:`PPO.teacher_coef`).
"""
from __future__ import annotations

from typing import Dict

import torch
from tensordict import TensorDict
from torchrl.data import Bounded, LazyTensorStorage, TensorDictReplayBuffer
from torchrl.data.replay_buffers.samplers import SamplerWithoutReplacement
from torchrl.objectives import ClipPPOLoss
from torchrl.objectives.value import GAE

from unicross.rl.models import OBS_KEYS, make_models

LOSS_KEYS = ("loss_objective", "loss_critic", "entropy", "kl_approx", "clip_fraction", "ESS",
             "explained_variance", "value_clip_fraction", "loss_teacher")


def obs_stats_frozen(model_cfg: dict) -> bool:
    """Whether the observation statistics stay fixed once they exist (``model.obs_stats``): "frozen",
    "running" (folded in from every collected batch), or null: frozen when the run starts from
    ``model.init_policy``, whose statistics are part of the policy it copies, running otherwise."""
    mode = model_cfg.get("obs_stats")
    if mode not in (None, "running", "frozen"):
        raise ValueError(f"model.obs_stats must be 'running', 'frozen' or null, not {mode!r}")
    return mode == "frozen" or (mode is None and bool(model_cfg.get("init_policy")))


class PPO:
    """PPO for one policy (``cfg``: the ``model``, ``loss``, ``gae`` and ``optim`` sections of
    ``configs/ppo.yaml``) on observations of sizes ``dims`` with ``n_act`` actions in [-1, 1];
    ``frames_per_batch`` sizes the replay buffer the minibatches are drawn from."""

    def __init__(self, dims: Dict[str, int], n_act: int, cfg: dict, frames_per_batch: int, device="cpu"):
        self.cfg, self.n_act = cfg, n_act
        self.updates = 0  # updates done (optim.critic_warmup counts them)
        oc = cfg["optim"]
        if oc["schedule"] not in ("fixed", "adaptive"):
            raise ValueError(f"optim.schedule must be 'fixed' or 'adaptive', not {oc['schedule']!r}")
        self.policy, self.value, self.norm = make_models(dims, n_act, Bounded(-1.0, 1.0, (n_act,)), cfg["model"])
        self.frozen_stats = obs_stats_frozen(cfg["model"])
        self.policy.to(device)
        self.value.to(device)
        lc = cfg["loss"]
        # the critic loss is taken in normalised return units (value targets standardised by
        # running statistics), with PPO-style value clipping around the predictions that collected
        self.loss = ClipPPOLoss(self.policy, self.value.critic, clip_epsilon=lc["clip_epsilon"],
                                entropy_bonus=True, entropy_coeff=lc["entropy_coeff"],
                                critic_coeff=lc["critic_coeff"], loss_critic_type=lc["loss_critic_type"],
                                normalize_advantage=lc["normalize_advantage"], clip_value=lc["clip_value"])
        self.loss.set_keys(value="state_value_norm", value_target="value_target_norm")
        self._actor_params = list(self.policy.parameters())
        self._critic_params = list(self.value.critic.parameters())
        self.gae = GAE(gamma=cfg["gae"]["gamma"], lmbda=cfg["gae"]["lmbda"], value_network=self.value,
                       average_gae=False)
        # fused: one kernel per parameter instead of ~10 ops each (CPU and CUDA; the same update to
        # float rounding); on 2 CPU cores a 1024-frame update is ~3% faster (0.302 -> 0.292 s)
        self.optim = torch.optim.Adam(self.loss.parameters(), lr=oc["lr"], fused=True)
        self.lr = oc["lr"]
        self.frames_per_batch = frames_per_batch
        self.minibatch = min(oc["minibatch_size"], frames_per_batch)
        self.rb = TensorDictReplayBuffer(storage=LazyTensorStorage(frames_per_batch, device=device),
                                         sampler=SamplerWithoutReplacement(), batch_size=self.minibatch)

    @property
    def actor(self) -> torch.nn.Module:
        """The bare network ``(hand, object, goal) -> (loc, scale)`` the collector's workers run."""
        return self.policy.module[0].module

    @torch.no_grad()
    def start_policy_from(self, ck: dict, name) -> None:
        """Starts the actor from the policy of checkpoint ``ck`` (its weights and observation
        statistics, which the critic shares); the exploration noise stays at ``model.init_log_std``."""
        dims = {k: getattr(self.norm, f"{k}_mean").numel() for k in self.norm.keys}
        if dict(ck["obs_dims"]) != dims or int(ck["n_act"]) != self.n_act:
            raise ValueError(f"model.init_policy={name}: observation sizes {ck['obs_dims']} and {ck['n_act']} actions, "
                             f"this run has {dims} and {self.n_act}")
        log_std = self.actor.log_std.clone()
        self.policy.load_state_dict(ck["policy"])
        self.actor.log_std.copy_(log_std)

    # ------------------------------------------------------------------ state
    def state_dict(self) -> dict:
        return dict(policy=self.policy.state_dict(), value=self.value.state_dict(), optim=self.optim.state_dict(),
                    lr=self.lr, updates=self.updates)

    def load_state_dict(self, state: dict) -> None:
        self.policy.load_state_dict(state["policy"])
        self.value.load_state_dict(state["value"])
        self.optim.load_state_dict(state["optim"])
        self.lr = state["lr"]
        self.updates = int(state.get("updates", 0))
        for g in self.optim.param_groups:
            g["lr"] = self.lr

    # ------------------------------------------------------------------ update
    def update(self, data: TensorDict) -> dict:
        """One PPO update on a collected batch ``data`` [..., T]: GAE on scaled rewards, return
        statistics, then ``mini_epochs`` passes of minibatches through ClipPPOLoss (policy) and
        the clipped critic loss in normalised units; actor and critic gradients are clipped
        separately; the epochs end early at ``optim.kl_stop``. Rewrites ``data["next", "reward"]``
        scaled. Returns the means of the loss module's diagnostics, ``kl``, ``lr``,
        ``minibatch_steps`` and the return statistics."""
        oc = self.cfg["optim"]
        fitted_first = bool(self.norm.count < 1)
        if fitted_first:  # first batch: fit the observation statistics before any update, and express
            # the behaviour distribution under them (the initial action mean is ~0 either way)
            self.norm.update({k: data[k] for k in OBS_KEYS})
            with torch.no_grad():
                obs = data.select(*OBS_KEYS).clone()
                loc_scale = self.policy.module[0](obs)
                data["loc"], data["scale"] = loc_scale["loc"], loc_scale["scale"]
                data["action_log_prob"] = self.policy.get_dist(obs).log_prob(data["action"])
        data["next", "reward"] = data["next", "reward"] * self.cfg["gae"]["reward_scale"]
        with torch.no_grad():
            self.gae(data)
            vn = self.value.value_norm
            vn.update(data["value_target"])
            data["value_target_norm"] = vn.normalize(data["value_target"])
            data["state_value_norm"] = vn.normalize(data["state_value"])  # old predictions, new units
        flat = data.reshape(-1)
        self.rb.empty()
        self.rb.extend(flat)
        n_mb = max(1, self.frames_per_batch // self.minibatch)
        stats = {k: 0.0 for k in LOSS_KEYS}
        stats.update(grad_norm_actor=0.0, grad_norm_critic=0.0)
        count, stopped = 0, False
        kl_stop = oc.get("kl_stop")
        critic_only = self.updates < int(oc.get("critic_warmup") or 0)
        for _ in range(oc["mini_epochs"]):
            if stopped:
                break
            for _ in range(n_mb):
                klv = self._step(self.rb.sample(), stats, first=count == 0, critic_only=critic_only)
                count += 1
                if kl_stop is not None and klv > kl_stop:  # the policy moved far enough for this batch
                    stopped = True
                    break
        if not (fitted_first or self.frozen_stats):
            self.norm.update({k: flat[k] for k in OBS_KEYS})
        out = {k: v / count for k, v in stats.items()}
        out["kl"] = out.pop("kl_approx")
        out["lr"] = self.lr
        out["minibatch_steps"] = count
        out["critic_only"] = float(critic_only)
        out["teacher_coef"] = 0.0 if critic_only else self.teacher_coef
        self.updates += 1
        out["value_mean"], out["value_std"] = float(vn.mean), float(vn.std())
        return out

    def _step(self, mb: TensorDict, stats: dict, first: bool = False, critic_only: bool = False) -> float:
        """One minibatch gradient step; adds its diagnostics to ``stats``; returns its KL. ``first``:
        the update's first step, whose KL is measured on the policy that collected the batch (0 by
        construction), so it does not move the adaptive rate (it would always raise it; with
        ``kl_stop`` that pinned the rate at ``lr_max``: one step per update at the largest rate).
        ``critic_only``: the critic's loss alone (``optim.critic_warmup``); the actor stays as it is."""
        oc = self.cfg["optim"]
        losses = self.loss(mb)
        loss = losses["loss_critic"]
        if not critic_only:
            loss = loss + losses["loss_objective"]
            if "loss_entropy" in losses.keys():
                loss = loss + losses["loss_entropy"]
            coef = self.teacher_coef
            if coef > 0.0:
                losses["loss_teacher"] = self._teacher_loss(mb)
                loss = loss + coef * losses["loss_teacher"]
        self.optim.zero_grad(set_to_none=True)
        loss.backward()
        ga = torch.nn.utils.clip_grad_norm_(self._actor_params, oc["max_grad_norm"])
        gc = torch.nn.utils.clip_grad_norm_(self._critic_params, oc["max_grad_norm_critic"])
        self.optim.step()
        klv = float(losses["kl_approx"])
        if not first and not critic_only:
            self._schedule_lr(klv)
        for k in LOSS_KEYS:
            if k in losses.keys():
                stats[k] += float(losses[k].detach().float().mean())
        stats["grad_norm_actor"] += float(ga)
        stats["grad_norm_critic"] += float(gc)
        return klv

    @property
    def teacher_coef(self) -> float:
        """The weight of the teacher term in this update: ``loss.teacher_coef`` x
        ``loss.teacher_decay`` ** (actor updates so far). The term is the mean squared distance of the
        actor's mean action to ``teacher_action`` on the minibatch's own states, added to the PPO
        loss (kickstarting, Schmitt et al. 2018: the teacher labels the student's states, and its
        weight decays so that PPO's return takes over; cf. DAPG's decaying demonstration term)."""
        lc = self.cfg["loss"]
        k = max(0, self.updates - int(self.cfg["optim"].get("critic_warmup") or 0))
        return float(lc.get("teacher_coef", 0.0)) * float(lc.get("teacher_decay", 1.0)) ** k

    def _teacher_loss(self, mb: TensorDict) -> torch.Tensor:
        loc, _ = self.actor(*(mb[k] for k in OBS_KEYS))
        return torch.nn.functional.mse_loss(loc, mb["teacher_action"])

    def _schedule_lr(self, kl: float) -> None:
        """``optim.schedule``: ``fixed``, or ``adaptive`` (rl_games): the rate shrinks by 1.5 when
        the minibatch KL exceeds twice ``kl_threshold`` and grows by 1.5 below half of it, within
        [``lr_min``, ``lr_max``] (a floor that keeps learning alive)."""
        oc = self.cfg["optim"]
        if oc["schedule"] == "fixed":
            return
        if kl > 2.0 * oc["kl_threshold"]:
            self.lr = max(self.lr / 1.5, oc["lr_min"])
        elif kl < 0.5 * oc["kl_threshold"]:
            self.lr = min(self.lr * 1.5, oc["lr_max"])
        for g in self.optim.param_groups:
            g["lr"] = self.lr
