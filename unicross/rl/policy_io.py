"""Loading trained policies from checkpoints and running them on UniCross tasks."""
from __future__ import annotations

from pathlib import Path

import torch
from torchrl.envs.utils import ExplorationType, set_exploration_type

from unicross.rl.env import obs_to_td
from unicross.rl.models import make_models


def load_policy(path, device="cpu"):
    """(policy, checkpoint) from a PPO checkpoint; fails with a clear message if missing/invalid."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"checkpoint not found: {path}")
    ck = torch.load(path, map_location=device, weights_only=False)
    if not isinstance(ck, dict) or "policy" not in ck or "obs_dims" not in ck:
        raise ValueError(f"{path} is not a UniCross policy checkpoint")
    policy, _, _ = make_models(ck["obs_dims"], ck["n_act"], None, ck["config"]["model"])
    policy.load_state_dict(ck["policy"])
    policy.to(device).eval()
    return policy, ck


@torch.no_grad()
def act(policy, obs: dict, deterministic: bool = True) -> torch.Tensor:
    """Action [N, A] of ``policy`` for a UniCross ``state_dict`` observation."""
    td = obs_to_td(obs)
    with set_exploration_type(ExplorationType.DETERMINISTIC if deterministic else ExplorationType.RANDOM):
        return policy(td)["action"].clamp(-1.0, 1.0)
