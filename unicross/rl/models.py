"""Networks of the paper (supplementary): experts and student share one architecture.

An MLP encoder on g (hidden [128, 64]) and a main MLP on [s^h, s^o, enc(g)] (hidden
[512, 256, 128]). The actor outputs a Gaussian mean with a learned, state-independent std; the
value network has the same shape with one output. Inputs are normalised by running statistics
(:class:`ObsNormalizer`), which are part of the checkpoint.

Initialisation follows CleanRL/TorchRL's PPO examples: the last layer of the action mean is scaled
by ``action_init_scale`` (0.01) with zero bias, so the untrained deterministic policy is close to
the zero action (residual actions integrate any bias into the wrist and finger targets). The
critic predicts returns in units of running return statistics (:class:`ValueNormalizer`); the
value module used by GAE and inference outputs them denormalised as ``state_value``.
"""
from __future__ import annotations

from typing import Sequence

import torch
from tensordict.nn import TensorDictModule, TensorDictSequential
from torch import nn
from torchrl.modules import IndependentNormal, ProbabilisticActor, ValueOperator

from unicross.robots.hand import WRIST_JOINTS

OBS_KEYS = ("hand", "object", "goal")


def mlp(inp: int, hidden: Sequence[int], out: int | None, act=nn.ELU) -> nn.Sequential:
    layers, d = [], inp
    for h in hidden:
        layers += [nn.Linear(d, h), act()]
        d = h
    if out is not None:
        layers.append(nn.Linear(d, out))
    return nn.Sequential(*layers)


@torch.no_grad()
def merge_moments(mean: torch.Tensor, var: torch.Tensor, count: torch.Tensor, x: torch.Tensor) -> None:
    """Fold the rows of ``x`` [n, ...] into running ``mean``/``var`` (in place) held over ``count``
    earlier rows (the caller adds n to its count)."""
    n = x.shape[0]
    delta, tot = x.mean(0) - mean, count + n
    var.copy_((var * count + x.var(0, unbiased=False) * n + delta ** 2 * count * n / tot) / tot)
    mean += delta * n / tot


class ObsNormalizer(nn.Module):
    """Running mean/variance per observation group; ``update`` is called by the trainer on each
    collected batch (after the update that used the previous statistics).

    ``std_min`` floors the standard deviation a feature is divided by (``model.obs_std_min``). A
    feature that barely varied in the data the statistics came from (the wrist command while a gait
    holds the wrist still: std ~1e-4) otherwise turns a millimetre's difference into the clip value
    +-5, and a network fitted there answers such states from saturated inputs."""

    def __init__(self, dims: dict, clip: float = 5.0, std_min: float = 0.0):
        super().__init__()
        self.keys = list(dims)
        for k, d in dims.items():
            self.register_buffer(f"{k}_mean", torch.zeros(d))
            self.register_buffer(f"{k}_var", torch.ones(d))
        self.register_buffer("count", torch.tensor(1e-4))
        self.clip = clip
        self.std_min = float(std_min)

    @torch.no_grad()
    def update(self, batch: dict) -> int:
        """Folds the rows of ``batch`` (dict of [..., d] tensors) into the statistics; rows with a
        non-finite entry in any group are left out. Returns the number of rows used."""
        rows = {k: batch[k].reshape(-1, batch[k].shape[-1]).float() for k in self.keys}
        finite = torch.stack([torch.isfinite(x).all(-1) for x in rows.values()]).all(0)
        n = int(finite.sum())
        if n == 0:
            return 0
        for k in self.keys:
            merge_moments(getattr(self, f"{k}_mean"), getattr(self, f"{k}_var"), self.count, rows[k][finite])
        self.count += n
        return n

    def forward(self, key: str, x: torch.Tensor) -> torch.Tensor:
        m, v = getattr(self, f"{key}_mean"), getattr(self, f"{key}_var")
        return ((x - m) / torch.sqrt(v + 1e-8).clamp_min(self.std_min)).clamp(-self.clip, self.clip)


class UniCrossNet(nn.Module):
    """[s^h, s^o, enc(g)] -> out; g is routed through its own encoder."""

    def __init__(self, dims: dict, out: int, norm: ObsNormalizer, enc_hidden=(128, 64),
                 main_hidden=(512, 256, 128)):
        super().__init__()
        self.norm = norm
        self.encoder = mlp(dims["goal"], enc_hidden, None)
        self.main = mlp(dims["hand"] + dims["object"] + enc_hidden[-1], main_hidden, out)

    def forward(self, hand, obj, goal):
        n = self.norm
        z = self.encoder(n("goal", goal))
        return self.main(torch.cat([n("hand", hand), n("object", obj), z], dim=-1))


class ValueNormalizer(nn.Module):
    """Running mean/variance of the value targets (returns); the critic learns in their units."""

    def __init__(self):
        super().__init__()
        self.register_buffer("mean", torch.zeros(()))
        self.register_buffer("var", torch.ones(()))
        self.register_buffer("count", torch.tensor(1e-4))

    @torch.no_grad()
    def update(self, x: torch.Tensor) -> None:
        x = x.reshape(-1).float()
        x = x[torch.isfinite(x)]
        if x.numel() == 0:
            return
        merge_moments(self.mean, self.var, self.count, x)
        self.count += x.numel()

    def std(self) -> torch.Tensor:
        return torch.sqrt(self.var + 1e-8)

    def normalize(self, x: torch.Tensor) -> torch.Tensor:
        return (x - self.mean) / self.std()

    def forward(self, x_norm: torch.Tensor) -> torch.Tensor:
        """Denormalise a prediction."""
        return x_norm * self.std() + self.mean


class GaussianHead(nn.Module):
    """A diagonal Gaussian over the action: the network's mean and a state-independent log std,
    ``init_log_std`` at the start (``init_log_std_wrist`` for the six virtual wrist dims, which come
    first in every hand's action, when given)."""

    def __init__(self, net: UniCrossNet, n_act: int, init_log_std: float = -0.5, init_scale: float = 1.0,
                 init_log_std_wrist: float | None = None):
        super().__init__()
        self.net = net
        self.log_std = nn.Parameter(torch.full((n_act,), init_log_std))
        if init_log_std_wrist is not None:
            with torch.no_grad():
                self.log_std[:len(WRIST_JOINTS)] = init_log_std_wrist
        last = net.main[-1]
        with torch.no_grad():  # near-zero initial action mean
            last.weight.mul_(init_scale)
            last.bias.zero_()

    @torch.no_grad()
    def start_mean_at(self, action: torch.Tensor) -> None:
        """Sets the last layer's bias so that the untrained mean is ``action`` [n_act] (plus the
        near-zero state-dependent part of the scaled last layer)."""
        self.net.main[-1].bias.copy_(action)

    def forward(self, hand, obj, goal):
        loc = self.net(hand, obj, goal)
        return loc, self.log_std.exp().expand_as(loc)

    @torch.no_grad()
    def acting_fn(self):
        """The same map as :meth:`forward` for acting in rollouts, in about a third of the calls: the
        normaliser's offsets and divisors and the action std are computed here once (not per step),
        the three groups are normalised as one vector, and the layers run as plain functions. The
        weights are read live, the statistics and std as they are now: take a fresh one whenever
        they may have changed (:meth:`Rollout.collect` takes one per batch). Equal to ``forward`` to
        rounding (the same element-wise operations). For acting only: no gradient reaches the
        action std or the statistics through it (training uses :meth:`forward`)."""
        n, keys = self.net.norm, OBS_KEYS
        mean = torch.cat([getattr(n, f"{k}_mean") for k in keys])
        std = torch.cat([torch.sqrt(getattr(n, f"{k}_var") + 1e-8).clamp_min(n.std_min) for k in keys])
        split = sum(getattr(n, f"{k}_mean").numel() for k in keys[:2])  # hand + object | goal
        clip, scale = n.clip, self.log_std.exp()
        encoder, main = _functional(self.net.encoder), _functional(self.net.main)

        def act(hand, obj, goal):
            x = ((torch.cat((hand, obj, goal), dim=-1) - mean) / std).clamp_(-clip, clip)
            loc = main(torch.cat((x[..., :split], encoder(x[..., split:])), dim=-1))
            return loc, scale.expand_as(loc)
        return act


def acting(actor):
    """What to act with for a while of fixed weights and statistics: ``actor.acting_fn()`` where it
    has one (:class:`GaussianHead`), else ``actor`` itself (any ``(hand, object, goal) -> (loc,
    scale)`` module)."""
    return actor.acting_fn() if hasattr(actor, "acting_fn") else actor


def _functional(seq: nn.Sequential):
    """``seq``'s forward without the per-module call overhead: ``Linear`` as ``F.linear`` on its live
    weights, an ``ELU`` right after a ``Linear`` in place on that fresh output; any other layer is
    called as is."""
    steps, prev = [], None
    for m in seq:
        if isinstance(m, nn.Linear):
            steps.append(lambda x, w=m.weight, b=m.bias: nn.functional.linear(x, w, b))
        elif isinstance(m, nn.ELU) and isinstance(prev, nn.Linear):
            steps.append(lambda x, a=m.alpha: nn.functional.elu(x, a, inplace=True))
        else:
            steps.append(m)
        prev = m

    def run(x):
        for f in steps:
            x = f(x)
        return x
    return run


def make_models(dims: dict, n_act: int, action_spec=None, cfg: dict | None = None):
    """Returns (policy, value, normalizer) as TensorDict modules over keys hand/object/goal.

    ``value`` writes ``state_value_norm`` (the critic's output, in units of the return
    statistics ``value.value_norm``) and ``state_value`` (denormalised, for GAE); ``value.critic``
    is the first of the two modules (what the critic loss trains)."""
    cfg = cfg or {}
    enc, main = tuple(cfg.get("encoder_hidden", (128, 64))), tuple(cfg.get("main_hidden", (512, 256, 128)))
    norm = ObsNormalizer(dims, std_min=cfg.get("obs_std_min", 0.0))
    actor = GaussianHead(UniCrossNet(dims, n_act, norm, enc, main), n_act, cfg.get("init_log_std", -0.5),
                         cfg.get("action_init_scale", 1.0), cfg.get("init_log_std_wrist"))
    policy = ProbabilisticActor(
        TensorDictModule(actor, in_keys=list(OBS_KEYS), out_keys=["loc", "scale"]),
        in_keys=["loc", "scale"], distribution_class=IndependentNormal, return_log_prob=True, spec=action_spec)
    critic = ValueOperator(UniCrossNet(dims, 1, norm, enc, main), in_keys=list(OBS_KEYS),
                           out_keys=["state_value_norm"])
    value_norm = ValueNormalizer()
    value = TensorDictSequential(critic, TensorDictModule(value_norm, in_keys=["state_value_norm"],
                                                          out_keys=["state_value"]))
    value.__dict__.update(critic=critic, value_norm=value_norm)  # handles, not extra registrations
    return policy, value, norm


def obs_dims_from_spec(spec) -> dict:
    return {k: spec[k].shape[-1] for k in OBS_KEYS}
