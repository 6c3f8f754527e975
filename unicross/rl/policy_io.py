"""Loading trained policies from checkpoints and running them on UniCross tasks."""
from __future__ import annotations

from pathlib import Path

import torch

from unicross.rl.env import split_obs
from unicross.rl.models import acting, make_models


SHIPPED_DIR = Path(__file__).resolve().parent.parent / "checkpoints"
SHIPPED_KEYS = ("policy", "obs_dims", "n_act", "modes", "distilled_modes", "config", "skill", "axis", "hand", "env_id",
                "env_kwargs", "iteration", "epoch", "frames", "git_commit", "commits", "clone_of", "started_from")


def resolve_checkpoint(spec) -> Path:
    """A checkpoint path, or the shorthand ``<hand>/<mode>`` of a shipped one
    (``unicross/checkpoints/<hand>/<mode>.pt``, e.g. ``allegro/grasp``)."""
    path = Path(spec)
    if path.exists() or path.suffix:
        return path
    shipped = SHIPPED_DIR / f"{spec}.pt"
    if shipped.exists():
        return shipped
    have = sorted(str(p.relative_to(SHIPPED_DIR).with_suffix("")) for p in SHIPPED_DIR.glob("*/*.pt"))
    raise FileNotFoundError(f"checkpoint not found: {spec} (shipped checkpoints: {have})")


def read_torch_file(path, what: str, device="cpu"):
    """``torch.load`` of a file the user named, with a clear error for a directory or a file that is
    not a torch file (``what``: "checkpoint", "grasp dataset")."""
    path = Path(path)
    if path.is_dir():
        hint = f"; the run's checkpoint is {path / 'checkpoint.pt'}" if (path / "checkpoint.pt").exists() else ""
        raise ValueError(f"{path} is a directory, not a {what}{hint}")
    if not path.exists():
        raise FileNotFoundError(f"{what} not found: {path}")
    try:
        return torch.load(path, map_location=device, weights_only=False)
    except Exception as e:  # pickle/zip errors of all kinds
        raise ValueError(f"{path} is not a UniCross {what} (it cannot be read by torch.load: "
                         f"{type(e).__name__})") from None


def export_policy(run_checkpoint, out, sidecar: dict) -> Path:
    """Writes the acting part of a PPO run checkpoint (policy weights with their observation
    statistics, sizes, config; no critic or optimiser) to ``out`` and ``sidecar`` (plus the
    checkpoint's own facts) to ``out`` with suffix ``.json``."""
    import json
    ck = read_torch_file(run_checkpoint, "checkpoint")
    small = {k: ck[k] for k in SHIPPED_KEYS if k in ck}
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    torch.save(small, out)
    facts = {k: small[k] for k in ("skill", "axis", "hand", "iteration", "epoch", "frames", "distilled_modes",
                                   "git_commit", "commits", "clone_of", "started_from") if k in small}
    out.with_suffix(".json").write_text(json.dumps({**facts, **sidecar}, indent=1) + "\n")
    return out


def load_policy(path, device="cpu"):
    """(policy, checkpoint) from a PPO checkpoint (or a shipped ``<hand>/<mode>``); fails with a
    clear message if missing/invalid."""
    path = resolve_checkpoint(path)
    ck = read_torch_file(path, "checkpoint", device)
    if not isinstance(ck, dict) or "policy" not in ck or "obs_dims" not in ck:
        raise ValueError(f"{path} is not a UniCross policy checkpoint")
    check_modes(ck, path)
    policy, _, _ = make_models(ck["obs_dims"], ck["n_act"], None, ck["config"]["model"])
    policy.load_state_dict(ck["policy"])
    policy.to(device).eval()
    return policy, ck


def check_modes(ck: dict, path) -> None:
    """Refuses a checkpoint whose goal (mode one-hot) differs from this install's skill registry:
    its network would read another layout of the observation. Checkpoints without ``modes``
    (written before it was stored) are checked by the goal size alone."""
    from unicross import formulation as F
    goal, modes = ck["obs_dims"].get("goal"), ck.get("modes")
    if goal != F.GOAL_DIM or (modes is not None and list(modes) != list(F.MODES)):
        raise ValueError(f"{path} was trained with a {goal}-D goal over modes {modes or '(not stored)'}; this "
                         f"install's skill registry gives a {F.GOAL_DIM}-D goal over {list(F.MODES)}: retrain it, "
                         f"or load it with the registry it was trained with")


@torch.no_grad()
def act(policy, obs: dict, deterministic: bool = True) -> torch.Tensor:
    """Action [N, A] of ``policy`` (a :func:`make_models` actor) for a UniCross ``state_dict``
    observation: the Gaussian's mean, or a sample of it, clipped to [-1, 1]. Calls the network
    directly (the TensorDict actor costs ~2 ms per call on a CPU, the network ~0.3 ms)."""
    return actor_action(policy.module[0].module, obs, deterministic)


@torch.no_grad()
def actor_action(actor, obs: dict, deterministic: bool = True, base=None) -> torch.Tensor:
    """:func:`act` for the bare network ``(hand, object, goal) -> (loc, scale)``; with ``base`` (the
    action of the policy's base gait, ``model.base_policy``) the network's action is added to it
    before the clip, as in training (:func:`residual_action`)."""
    loc, scale = actor(*split_obs(obs))
    if not deterministic:
        loc = loc + scale * torch.randn_like(loc)
    return loc.clamp(-1.0, 1.0) if base is None else residual_action(base, loc)


def residual_action(base: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
    """The env's action under ``model.base_policy``: the base gait's action plus the network's,
    clipped to the action box (the env would clip it too)."""
    return (base + action).clamp(-1.0, 1.0)


def base_policy_of(ck: dict):
    """The scripted gait a checkpoint's network acts on top of (``model.base_policy``), or None."""
    return ((ck.get("config") or {}).get("model") or {}).get("base_policy")


def policy_fn(actor, base_policy=None):
    """``(obs, task) -> action`` of the bare network (its mean), on top of its base gait when it has
    one (:func:`base_policy_of`): the way a checkpoint acts wherever it is evaluated. A network with
    ``acting_fn()`` (:class:`GaussianHead`) acts through one taken now, with its observation
    statistics as they are now: build a new ``policy_fn`` after they change."""
    net = acting(actor)
    if base_policy is None:
        return lambda obs, u: actor_action(net, obs)
    from unicross.gaits import make_gait_policy
    gait = make_gait_policy(base_policy)
    return lambda obs, u: actor_action(net, obs, base=gait(obs, u))
