"""The lean collector's workers as Ray actors, so one training run can use the cores of many
machines (optional: ``pip install "unicross[ray]"``).

Each actor holds one CPU env and a copy of the actor network, exactly like a worker process of
:class:`unicross.rl.collector.LeanCollector` (same seeds: actor ``i`` starts from ``seed + i``), but
across machines there is no shared memory: every :meth:`RayCollector.collect` puts the current
weights and observation statistics into Ray's object store once (~1 MB) and each actor loads them
before its rollout; its ``[1, T]`` rollout comes back through the object store. The main process
does GAE and the update, as with local workers.

Point a run at a cluster with ``--set collector.ray_address=auto`` (a node of a running cluster;
``ray start --head`` on one machine, ``ray start --address=HEAD:6379`` on the others) or
``ray://HEAD:10001`` (Ray Client); ``local`` starts a Ray instance on this machine. ``env.num_envs``
is then the number of env actors (one CPU each), which may exceed this machine's cores.
"""
from __future__ import annotations

import copy

from typing import Optional

import torch
from tensordict import TensorDict

from unicross.rl.collector import Rollout, make_buffer


def _require_ray():
    try:
        import ray
    except ImportError as e:  # a clear message before any simulation
        raise ImportError('collector.ray_address needs Ray: pip install "unicross[ray]" (or pip install ray)') from e
    return ray


def connect(address: str) -> None:
    """``ray.init`` for ``collector.ray_address`` (``local``: a new instance on this machine), once."""
    ray = _require_ray()
    if ray.is_initialized():
        return
    if address == "local":
        ray.init(include_dashboard=False, log_to_driver=False)
    else:
        ray.init(address=address, log_to_driver=False)


class _EnvActor:
    """One env and a copy of the actor network (a Ray actor; see the module docstring)."""

    def __init__(self, env_id: str, env_kwargs: dict, seed: int, deterministic: bool, noise_correlation: float = 0.0):
        torch.set_num_threads(1)
        self.rollout = Rollout(env_id, env_kwargs, seed, deterministic, noise_correlation)

    def sizes(self):
        return self.rollout.dims, self.rollout.n_act

    def set_actor(self, actor: torch.nn.Module) -> None:
        self.rollout.set_actor(actor)

    def collect(self, weights: dict, horizon: int) -> TensorDict:
        self.rollout.actor.load_state_dict(weights)
        buf = make_buffer(1, horizon, self.rollout.dims, self.rollout.n_act)
        self.rollout.collect(buf)
        return buf

    def call(self, weights: dict, fn, kwargs: dict):
        self.rollout.actor.load_state_dict(weights)
        return fn(self.rollout.actor, **kwargs)

    def close(self) -> None:
        self.rollout.close()


class RayCollector:
    """:class:`unicross.rl.collector.LeanCollector`'s interface over ``num_envs`` Ray env actors."""

    def __init__(self, env_id: str, env_kwargs: dict, num_envs: int, horizon: int, seed: int = 0,
                 address: str = "local", deterministic: bool = False, noise_correlation: float = 0.0):
        ray = _require_ray()
        connect(address)
        self._ray = ray
        self.horizon, self.num_envs = horizon, num_envs
        kw = dict(env_kwargs, sim_backend="physx_cpu", num_envs=1)
        remote = ray.remote(num_cpus=1)(_EnvActor)
        self._actors = [remote.remote(env_id, kw, seed + i, deterministic, noise_correlation) for i in range(num_envs)]
        self.dims, self.n_act = ray.get(self._actors[0].sizes.remote())
        self.device = torch.device("cpu")
        self.actor: Optional[torch.nn.Module] = None
        self.buf: Optional[TensorDict] = None

    @property
    def frames_per_batch(self) -> int:
        return self.num_envs * self.horizon

    def set_actor(self, actor: torch.nn.Module, own_copy: bool = False) -> None:
        """The module ``(hand, object, goal) -> (loc, scale)`` the envs act with; its current
        weights go to the env actors at every :meth:`collect` (the actors always act with their own
        copy on the CPU, whatever ``own_copy`` says; overlapped collection is refused before the run,
        :func:`unicross.rl.collector.check_overlap`)."""
        self.actor = actor
        cpu_copy = copy.deepcopy(actor).to("cpu")
        self._ray.get([a.set_actor.remote(cpu_copy) for a in self._actors])
        self.buf = make_buffer(self.num_envs, self.horizon, self.dims, self.n_act)

    def _weights(self):
        return self._ray.put({k: v.detach().cpu() for k, v in self.actor.state_dict().items()})

    def collect(self) -> TensorDict:
        """One batch ``[num_envs, horizon]``, row ``i`` from env actor ``i``."""
        if self.actor is None:
            raise RuntimeError("set_actor() first")
        w = self._weights()
        rows = self._ray.get([a.collect.remote(w, self.horizon) for a in self._actors])
        for i, row in enumerate(rows):
            self.buf[i:i + 1] = row
        return self.buf.clone()

    def map_shards(self, fn, **kwargs) -> list:
        """``fn(actor, shard=(i, n), **kwargs)`` in each env actor (see LeanCollector.map_shards)."""
        w, n = self._weights(), len(self._actors)
        return self._ray.get([a.call.remote(w, fn, dict(kwargs, shard=(i, n))) for i, a in enumerate(self._actors)])

    def close(self) -> None:
        for a in self._actors:
            try:
                self._ray.get(a.close.remote())
                self._ray.kill(a)
            except Exception:  # an actor that already died: nothing to close
                pass
        self._actors = []
