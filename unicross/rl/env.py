"""A TorchRL environment over a batched ManiSkill UniCross task.

``ManiSkillEnv`` keeps tensors on the env device, exposes the observation groups as TensorDict
keys (``hand``, ``object``, ``goal``), reports ``terminated`` (object dropped) and ``truncated``
(episode length reached) separately, carries the task's per-term rewards and success flags under
``info``, and supports partial resets (``_reset`` masks) on the GPU backend.

For TorchRL users (its collectors, transforms, ``rollout``). Training here does not go through it:
on the CPU, :mod:`unicross.rl.collector` runs the policy inside one-env worker processes, which
measured several times faster than a ``ParallelEnv`` of these envs with TorchRL's collector.
"""
from __future__ import annotations

from typing import Optional

import torch
from tensordict import TensorDict, TensorDictBase
from torchrl.data import Bounded, Categorical, Composite, Unbounded
from torchrl.envs import EnvBase

from unicross.rewards import term_names

INFO_METRICS = ("rotation", "translation", "relocate_pos_err", "relocate_rot_err")
INFO_BOOL = ("success", "drop", "nonfinite")


def info_float_keys() -> tuple:
    """The float ``info`` entries an RL env carries: the protocol metrics and every registered
    reward term (read from the registry when called, so a term registered later is included)."""
    return INFO_METRICS + tuple(f"reward_{t}" for t in term_names())


def split_obs(obs: dict) -> tuple:
    """(hand, object, goal) tensors [N, d] of a UniCross ``state_dict`` observation."""
    o = obs["extra"]
    obj = torch.cat(list(o["object"].values()), dim=-1)  # its terms in config order
    return o["hand"], obj, o["goal"]


def obs_splitter(layout: list):
    """``obs -> (hand, object, goal)`` for a UniCross ``state`` observation [N, D] with the task's
    ``_obs_layout``: three views, no copy (the object terms lie side by side in the flat observation,
    so its group needs no ``cat``); the same tensors as :func:`split_obs` of the ``state_dict`` one."""
    widths = [w if isinstance(w, int) else sum(x for _, x in w) for _, w in layout]

    def split(flat: torch.Tensor) -> tuple:
        return tuple(torch.split(flat, widths, dim=-1))
    return split


def obs_to_td(obs: dict, device=None) -> TensorDict:
    """A UniCross ``state_dict`` observation -> TensorDict with keys hand, object, goal ([N, ...])."""
    hand, obj, goal = split_obs(obs)
    return TensorDict({"hand": hand, "object": obj, "goal": goal}, batch_size=[hand.shape[0]], device=device)


class ManiSkillEnv(EnvBase):
    """TorchRL ``EnvBase`` over ``gym.make(env_id, obs_mode="state_dict", **env_kwargs)``.

    With ``num_envs == 1`` the batch dimension is squeezed (batch_size ``[]``), so that a
    ``ParallelEnv`` of CPU workers has batch ``[W]`` like a GPU env of ``W`` sub-scenes.
    """

    def __init__(self, env_id: str, env_kwargs: Optional[dict] = None, device=None):
        import gymnasium as gym
        import unicross  # noqa: F401  (registers the tasks)
        kw = dict(obs_mode="state_dict", render_backend="none")
        kw.update(env_kwargs or {})
        kw["obs_mode"] = "state_dict"
        self._gym = gym.make(env_id, **kw)
        self.task = self._gym.unwrapped
        n = self.task.num_envs
        self._squeeze = n == 1
        batch = torch.Size([]) if self._squeeze else torch.Size([n])
        super().__init__(device=self.task.device, batch_size=batch)
        self.env_id = env_id
        self._seed: Optional[int] = None
        self._make_specs()

    # ------------------------------------------------------------------ specs
    def _make_specs(self):
        b = self.batch_size
        obs = self.task.get_obs(unflattened=True)["extra"]
        dims = dict(hand=obs["hand"].shape[-1], goal=obs["goal"].shape[-1],
                    object=sum(v.shape[-1] for v in obs["object"].values()))
        dev = self.device
        self._info_float = info_float_keys()
        info = Composite({k: Unbounded(b + (1,), device=dev) for k in self._info_float}, shape=b, device=dev)
        for k in INFO_BOOL:
            info[k] = Categorical(2, b + (1,), dtype=torch.bool, device=dev)
        self.observation_spec = Composite(hand=Unbounded(b + (dims["hand"],), device=dev),
                                          object=Unbounded(b + (dims["object"],), device=dev),
                                          goal=Unbounded(b + (dims["goal"],), device=dev),
                                          info=info, shape=b, device=dev)
        n_act = self.task.single_action_space.shape[0]
        self.action_spec = Bounded(-1.0, 1.0, b + (n_act,), device=dev)
        self.reward_spec = Unbounded(b + (1,), device=dev)
        self.done_spec = Composite(done=Categorical(2, b + (1,), dtype=torch.bool, device=dev),
                                   terminated=Categorical(2, b + (1,), dtype=torch.bool, device=dev),
                                   truncated=Categorical(2, b + (1,), dtype=torch.bool, device=dev),
                                   shape=b, device=dev)

    # ------------------------------------------------------------------ conversions
    def _pack(self, obs: dict, info: dict) -> TensorDict:
        td = obs_to_td(obs, self.device)
        td["info"] = TensorDict({k: info[k].reshape(-1, 1).float() for k in self._info_float}
                                | {k: info[k].reshape(-1, 1).bool() for k in INFO_BOOL}, batch_size=td.batch_size)
        return td[0] if self._squeeze else td

    # ------------------------------------------------------------------ EnvBase hooks
    def _reset(self, tensordict: Optional[TensorDictBase] = None, **kwargs) -> TensorDictBase:
        options = {}
        if tensordict is not None and "_reset" in tensordict.keys() and not self._squeeze:
            mask = tensordict["_reset"].reshape(-1)
            if not bool(mask.all()):
                options["env_idx"] = torch.nonzero(mask).flatten()
        seed, self._seed = self._seed, None
        obs, info = self.task.reset(seed=seed, options=options)
        info = dict(info)
        n = self.task.num_envs
        for k in self._info_float + INFO_BOOL:
            info.setdefault(k, torch.zeros(n, device=self.device))
        td = self._pack(obs, info)
        zeros = torch.zeros(self.batch_size + (1,), dtype=torch.bool, device=self.device)
        td.update({"done": zeros, "terminated": zeros.clone(), "truncated": zeros.clone()})
        return td

    def _step(self, tensordict: TensorDictBase) -> TensorDictBase:
        action = tensordict["action"]
        if self._squeeze:
            action = action.unsqueeze(0)
        obs, reward, terminated, truncated, info = self.task.step(action)
        td = self._pack(obs, info)
        shape = self.batch_size + (1,)
        td.update({"reward": reward.reshape(shape).float(), "terminated": terminated.reshape(shape),
                   "truncated": truncated.reshape(shape), "done": (terminated | truncated).reshape(shape)})
        return td

    def _set_seed(self, seed: Optional[int]):
        self._seed = seed
        return seed

    def close(self, *, raise_if_closed: bool = True):
        self._gym.close()
        super().close(raise_if_closed=raise_if_closed)
