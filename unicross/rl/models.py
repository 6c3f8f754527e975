"""Networks of the paper (supplementary): experts and student share one architecture.

An MLP encoder on g (hidden [128, 64]) and a main MLP on [s^h, s^o, enc(g)] (hidden
[512, 256, 128]). The actor outputs a Gaussian mean with a learned, state-independent std; the
value network has the same shape with one output. Inputs are normalised by running statistics
(:class:`ObsNormalizer`), which are part of the checkpoint.
"""
from __future__ import annotations

from typing import Sequence

import torch
from tensordict.nn import TensorDictModule
from torch import nn
from torchrl.modules import IndependentNormal, ProbabilisticActor, ValueOperator

OBS_KEYS = ("hand", "object", "goal")


def mlp(inp: int, hidden: Sequence[int], out: int | None, act=nn.ELU) -> nn.Sequential:
    layers, d = [], inp
    for h in hidden:
        layers += [nn.Linear(d, h), act()]
        d = h
    if out is not None:
        layers.append(nn.Linear(d, out))
    return nn.Sequential(*layers)


class ObsNormalizer(nn.Module):
    """Running mean/variance per observation group; ``update`` is called by the trainer on each
    collected batch (after the update that used the previous statistics)."""

    def __init__(self, dims: dict, clip: float = 5.0):
        super().__init__()
        self.keys = list(dims)
        for k, d in dims.items():
            self.register_buffer(f"{k}_mean", torch.zeros(d))
            self.register_buffer(f"{k}_var", torch.ones(d))
        self.register_buffer("count", torch.tensor(1e-4))
        self.clip = clip

    @torch.no_grad()
    def update(self, batch: dict) -> None:
        n = None
        for k in self.keys:
            x = batch[k].reshape(-1, batch[k].shape[-1]).float()
            n = x.shape[0]
            mean, var = x.mean(0), x.var(0, unbiased=False)
            m, v, c = getattr(self, f"{k}_mean"), getattr(self, f"{k}_var"), self.count
            delta = mean - m
            tot = c + n
            m += delta * n / tot
            v.copy_((v * c + var * n + delta ** 2 * c * n / tot) / tot)
        self.count += n

    def forward(self, key: str, x: torch.Tensor) -> torch.Tensor:
        m, v = getattr(self, f"{key}_mean"), getattr(self, f"{key}_var")
        return ((x - m) / torch.sqrt(v + 1e-8)).clamp(-self.clip, self.clip)


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


class GaussianHead(nn.Module):
    def __init__(self, net: UniCrossNet, n_act: int, init_log_std: float = -0.5):
        super().__init__()
        self.net = net
        self.log_std = nn.Parameter(torch.full((n_act,), init_log_std))

    def forward(self, hand, obj, goal):
        loc = self.net(hand, obj, goal)
        return loc, self.log_std.exp().expand_as(loc)


def make_models(dims: dict, n_act: int, action_spec=None, cfg: dict | None = None):
    """Returns (policy, value, normalizer) as TensorDict modules over keys hand/object/goal."""
    cfg = cfg or {}
    enc, main = tuple(cfg.get("encoder_hidden", (128, 64))), tuple(cfg.get("main_hidden", (512, 256, 128)))
    norm = ObsNormalizer(dims)
    actor = GaussianHead(UniCrossNet(dims, n_act, norm, enc, main), n_act, cfg.get("init_log_std", -0.5))
    policy = ProbabilisticActor(
        TensorDictModule(actor, in_keys=list(OBS_KEYS), out_keys=["loc", "scale"]),
        in_keys=["loc", "scale"], distribution_class=IndependentNormal, return_log_prob=True, spec=action_spec)
    value = ValueOperator(UniCrossNet(dims, 1, norm, enc, main), in_keys=list(OBS_KEYS))
    return policy, value, norm


def obs_dims_from_spec(spec) -> dict:
    return {k: spec[k].shape[-1] for k in OBS_KEYS}
