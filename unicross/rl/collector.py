"""A lean rollout collector: the policy runs next to the physics, rollouts land in shared memory.

On the CPU, SAPIEN simulates one env per process. Each worker process holds one env and the
actor (weights and observation statistics in shared memory, so every optimiser step is seen by
the workers without copying) and writes its rollout straight into its row of a preallocated
shared ``[num_envs, T]`` TensorDict; the main process only computes GAE and the update. This
replaces TorchRL's ``ParallelEnv`` + ``Collector`` on the CPU, which measured slower with two
workers than one in-process env (the parallel env's main process busy-waits on its workers, and
the TensorDict policy and env-wrapper calls cost ~2 ms per frame; see ``benchmarks/``).

With ``num_envs == 1`` on the CPU, or on the GPU (one ``physx_cuda`` env of ``num_envs``
sub-scenes), the same rollout loop runs in the main process.

Batch layout (what TorchRL's GAE and ``ClipPPOLoss`` read), ``[num_envs, T]``: ``hand``,
``object``, ``goal`` (observation), ``action`` (the sampled, unclipped action; the task clips),
``action_log_prob``, ``loc``, ``scale``, and under ``next``: the observation after the step (the
last one of an episode, before the reset), ``reward``, ``done``, ``terminated`` (object dropped),
``truncated`` (episode length), and ``info`` (the task's per-term rewards and flags,
:func:`unicross.rl.env.info_float_keys` / ``INFO_BOOL``). With a teacher (``collector.teacher``),
also ``teacher_action``: the teacher's action in the state the policy acted in (kickstarting's
label, Schmitt et al. 2018; :class:`unicross.rl.algorithm.PPO` fits the actor's mean to it).
"""
from __future__ import annotations

import atexit
import contextlib
import copy
import math
import os
import signal
import tempfile
import traceback
from pathlib import Path
from typing import Optional

import torch
import torch.multiprocessing as mp
from tensordict import TensorDict

from unicross.rl.env import INFO_BOOL, info_float_keys, obs_splitter
from unicross.rl.models import acting
from unicross.rl.policy_io import residual_action

OBS_KEYS = ("hand", "object", "goal")


def make_buffer(n: int, horizon: int, dims: dict, n_act: int, device="cpu", teacher: bool = False) -> TensorDict:
    """Zeroed rollout storage ``[n, horizon]`` with the keys of the module docstring (``teacher``:
    with ``teacher_action``)."""
    b = (n, horizon)
    z = lambda *s, dtype=torch.float32: torch.zeros(b + s, dtype=dtype, device=device)  # noqa: E731
    obs = {k: z(dims[k]) for k in OBS_KEYS}
    info = {k: z(1) for k in info_float_keys()} | {k: z(1, dtype=torch.bool) for k in INFO_BOOL}
    nxt = {k: z(dims[k]) for k in OBS_KEYS} | dict(
        reward=z(1), done=z(1, dtype=torch.bool), terminated=z(1, dtype=torch.bool),
        truncated=z(1, dtype=torch.bool), info=TensorDict(info, batch_size=b, device=device))
    extra = {"teacher_action": z(n_act)} if teacher else {}
    return TensorDict({**obs, "action": z(n_act), "action_log_prob": z(), "loc": z(n_act), "scale": z(n_act),
                       **extra, "next": TensorDict(nxt, batch_size=b, device=device)}, batch_size=b, device=device)


def make_teacher(spec: Optional[str]):
    """``collector.teacher``: None, or a scripted gait (a shipped ``<hand>/<mode>`` such as
    ``allegro/rotate_y-``, or a gait search log) as a function ``task -> action``. A gait reads the
    task's state and keeps one clock for its envs, so it must see every step, and its envs must
    start their episodes together (one env per CPU worker; :func:`check_teacher`)."""
    if spec is None:
        return None
    from unicross.gaits import make_gait_policy
    gait = make_gait_policy(spec)
    return lambda task: gait(None, task)


def check_teacher(spec: Optional[str], skill: str, axis: Optional[str], backend: str,
                  ray_address: Optional[str] = None, what: str = "collector.teacher") -> None:
    """Refuses (before any simulation) a ``collector.teacher`` that is not a gait of this run's mode,
    or one on the GPU backend (its sub-scenes reset one by one; a gait keeps one clock) or with Ray
    env actors (which do not carry it)."""
    if spec is None:
        return
    if ray_address:
        raise ValueError(f"{what} is not supported with collector.ray_address (Ray env actors)")
    if backend != "physx_cpu":
        raise ValueError(f"{what} (a scripted gait) needs env.backend physx_cpu: a gait keeps one clock "
                         "for all its envs, and GPU sub-scenes reset one by one")
    from unicross.gaits import gait_mode, make_gait_policy
    mode = gait_mode(make_gait_policy(spec).gait_row)  # also checks the gait's options
    ours = f"{skill}_{axis}" if axis else skill
    if mode != ours:
        raise ValueError(f"{what}={spec} is a gait for {mode}, this run trains {ours}")


class Rollout:
    """One (batched) UniCross task stepped by an actor (a module ``(hand, object, goal) -> (loc,
    scale)`` of a diagonal Gaussian, set with :meth:`set_actor`; where it offers ``acting_fn()``
    (:class:`GaussianHead`), each :meth:`collect` acts with one taken at its start, the weights
    being fixed during a batch). Episodes run on across
    :meth:`collect` calls; finished envs are reset (unseeded: each reset continues the task's
    generator) right after their last step.

    ``noise_correlation`` ρ makes the exploration noise a stationary AR(1) process per env,
    ``ε_t = ρ ε_{t-1} + sqrt(1 - ρ²) η_t`` (fresh ``ε ~ N(0, I)`` at each episode start), so every
    action is still ``loc + scale * ε`` with ``ε ~ N(0, I)`` marginally and its stored
    log-probability is that marginal's, as PPO's ratio reads it (temporally correlated "coloured"
    noise in PPO, Hollenstein et al. 2024). ρ = 0: white noise. Residual finger targets integrate
    the actions, so correlated noise moves them ~sqrt((1 + ρ)/(1 - ρ)) times farther per episode
    (4.4x at 0.9) at the same per-step spread.

    ``teacher`` (:func:`make_teacher`): its action in every state is written to ``teacher_action``;
    with ``residual`` the env also takes it added to the policy's action (``model.base_policy``:
    :func:`residual_action`; the stored action, its log-probability and PPO's ratio are the
    network's, the gait being part of the env as PPO sees it).

    ``alternates`` (one env, CPU workers): other envs ``[(env_id, kwargs), ...]`` with the same
    observation and action sizes, e.g. DAgger's long-horizon chains (``env.chain_share``). At each
    episode's end the next episode runs in one of them with probability ``alternate_share`` (which one
    uniformly), else in the first env; each is made at its first episode (a reset seeded with
    ``seed + 1000 k``) and kept, later episodes continuing its generator. The draws have their own
    generator, so the first env's episodes and the action noise are as without alternates."""

    def __init__(self, env_id: str, env_kwargs: dict, seed: int, deterministic: bool = False,
                 noise_correlation: float = 0.0, teacher: Optional[str] = None, residual: bool = False,
                 alternates: Optional[list] = None, alternate_share: float = 0.0):
        import unicross  # noqa: F401  (registers the tasks)
        self._seed = seed
        self._specs = [(env_id, env_kwargs)] + [(i, dict(k)) for i, k in (alternates or [])]
        self._share = float(alternate_share)
        self._pick = torch.Generator().manual_seed(seed + 7919)  # which env runs the next episode
        self._slots: dict = {}
        self._use(0)
        if len(self._specs) > 1 and self.task.num_envs != 1:
            raise ValueError("alternate envs need one env per rollout (CPU env workers)")
        self.actor: Optional[torch.nn.Module] = None
        self.deterministic = deterministic
        self.device = self.task.device
        self.gen = torch.Generator(device=self.device)
        self.gen.manual_seed(seed)
        self.rho = float(noise_correlation)
        self.eps: Optional[torch.Tensor] = None  # the AR(1) noise state (rho > 0)
        self.teacher = make_teacher(teacher)
        if residual and self.teacher is None:
            raise ValueError("a residual rollout needs its base gait (teacher)")
        self.residual = residual
        obs, _ = self.task.reset(seed=seed)
        self.obs = self._split(obs)
        self.dims = {k: x.shape[-1] for k, x in zip(OBS_KEYS, self.obs)}
        self.n_act = int(self.task.single_action_space.shape[0])

    def _use(self, k: int) -> bool:
        """Env ``k`` of ``_specs`` becomes the one stepped (made now if new: True)."""
        new = k not in self._slots
        if new:
            import gymnasium as gym
            env_id, env_kwargs = self._specs[k]
            kw = dict(render_backend="none", **env_kwargs)
            kw["obs_mode"] = "state"  # flat: the three groups are views of it (obs_splitter)
            env = gym.make(env_id, **kw)
            self._slots[k] = (env, env.unwrapped, obs_splitter(env.unwrapped._obs_layout))
        _, self.task, self._split = self._slots[k]
        return new

    def _reset_done(self, done: torch.Tensor) -> tuple:
        """Resets the envs that finished (``done`` [N]); their first observations (split). With
        alternates, the next episode may run in another env (see the class)."""
        if len(self._specs) == 1:
            options = {} if self.task.num_envs == 1 else {"env_idx": torch.nonzero(done).flatten()}
            obs, _ = self.task.reset(options=options)
            return self._split(obs)
        k = 0
        if float(torch.rand((), generator=self._pick)) < self._share:
            k = 1 + int(torch.randint(len(self._specs) - 1, (), generator=self._pick))
        if self._use(k):
            obs, _ = self.task.reset(seed=self._seed + 1000 * k)
            fresh = self._split(obs)
            got = {key: x.shape[-1] for key, x in zip(OBS_KEYS, fresh)}
            if got != self.dims or int(self.task.single_action_space.shape[0]) != self.n_act:
                raise ValueError(f"alternate env {self._specs[k][0]}: observation sizes {got} and "
                                 f"{self.task.single_action_space.shape[0]} actions, the first env has {self.dims} "
                                 f"and {self.n_act}")
            return fresh
        obs, _ = self.task.reset()
        return self._split(obs)

    def set_actor(self, actor: torch.nn.Module) -> None:
        self.actor = actor

    @torch.no_grad()
    def collect(self, buf: TensorDict) -> None:
        """Fills ``buf`` [num_envs, T]. The step loop only keeps references to each step's tensors
        (every one a fresh output of the actor or the task's step); they are stacked into the buffer
        once per key at the end, ~30 copies per rollout instead of per step (so a rollout's tensors are
        held twice at the end: on a GPU env of many sub-scenes, a long horizon's peak memory doubles)."""
        leaves = {k: buf.get(k) for k in buf.keys(include_nested=True, leaves_only=True)}
        info_names = info_float_keys() + INFO_BOOL
        horizon = buf.shape[1]
        actor = acting(self.actor)
        obs_s, nxt_s, info_s, rew_s, term_s, trunc_s = [], [], [], [], [], []
        act_s, loc_s, scale_s, noise_s, teacher_s = [], [], [], [], []
        for _ in range(horizon):
            obs_s.append(self.obs)
            base = None
            if self.teacher is not None:
                base = self.teacher(self.task)
                teacher_s.append(base)
            loc, scale = actor(*self.obs)
            noise = torch.zeros_like(loc) if self.deterministic else self._noise(loc.shape)
            a = loc + scale * noise
            act_s.append(a), loc_s.append(loc), scale_s.append(scale), noise_s.append(noise)
            obs, reward, terminated, truncated, info = self.task.step(residual_action(base, a) if self.residual else a)
            nxt = self._split(obs)
            nxt_s.append(nxt)
            rew_s.append(reward), term_s.append(terminated), trunc_s.append(truncated)
            info_s.append([info[k] for k in info_names])
            done = terminated | truncated
            if bool(done.any()):
                fresh = self._reset_done(done)
                nxt = fresh if self.task.num_envs == 1 else \
                    tuple(torch.where(done[:, None], f, x) for f, x in zip(fresh, nxt))
                if self.eps is not None:  # a new episode starts its noise from the stationary law
                    self.eps = torch.where(done[:, None], torch.randn(self.eps.shape, generator=self.gen,
                                                                      device=self.eps.device), self.eps)
            self.obs = nxt

        def put(dst: torch.Tensor, steps: list) -> None:  # [N, ...] per step -> dst [N, T, ...]
            dst.copy_(torch.stack(steps, dim=1).view(dst.shape))

        for i, k in enumerate(OBS_KEYS):
            put(leaves[k], [o[i] for o in obs_s])
            put(leaves[("next", k)], [o[i] for o in nxt_s])
        for k, steps in (("action", act_s), ("loc", loc_s), ("scale", scale_s), (("next", "reward"), rew_s),
                         (("next", "terminated"), term_s), (("next", "truncated"), trunc_s)):
            put(leaves[k], steps)
        term, trunc = leaves[("next", "terminated")], leaves[("next", "truncated")]
        torch.logical_or(term, trunc, out=leaves[("next", "done")])
        noise, scale = torch.stack(noise_s, dim=1), leaves["scale"]
        leaves["action_log_prob"].copy_((-0.5 * noise ** 2 - scale.log() - 0.5 * math.log(2 * math.pi)).sum(-1))
        for j, k in enumerate(info_names):
            put(leaves[("next", "info", k)], [s[j] for s in info_s])
        if teacher_s:
            put(leaves["teacher_action"], teacher_s)

    def _noise(self, shape) -> torch.Tensor:
        white = torch.randn(shape, generator=self.gen, device=self.device)
        if self.rho == 0.0:
            return white
        self.eps = white if self.eps is None else self.rho * self.eps + math.sqrt(1.0 - self.rho ** 2) * white
        return self.eps

    def close(self):
        for env, _, _ in self._slots.values():
            env.close()
        self._slots = {}


def _worker(rank: int, env_id: str, env_kwargs: dict, seed: int, deterministic: bool, noise_correlation: float,
            teacher: Optional[str], residual: bool, conn, alternates: Optional[list] = None,
            alternate_share: float = 0.0) -> None:
    """Worker process: one env (and its ``alternates``, :class:`Rollout`). Reports its sizes, receives
    the shared actor and buffer, then fills row ``rank`` of the buffer on every "collect"."""
    torch.set_num_threads(1)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C reaches the whole group; the main process stops us
    try:
        rollout = Rollout(env_id, env_kwargs, seed, deterministic, noise_correlation, teacher, residual,
                          alternates, alternate_share)
        conn.send(("ready", (rollout.dims, rollout.n_act)))
        msg, (actor, buf) = conn.recv()
        rollout.set_actor(actor)
        row = buf[rank:rank + 1]
        conn.send(("ready", None))
    except Exception:  # reported to the main process, which raises it
        conn.send(("error", traceback.format_exc()))
        return
    while True:
        cmd = conn.recv()
        if cmd == "close":
            break
        try:
            if cmd == "collect":
                rollout.collect(row)
                conn.send(("done", None))
            else:  # ("call", fn, kwargs): fn(actor, **kwargs) with the worker's actor
                _, fn, kwargs = cmd
                conn.send(("done", fn(rollout.actor, **kwargs)))
        except Exception:
            conn.send(("error", traceback.format_exc()))
    rollout.close()


def usable_cores() -> int:
    """Cores this process may run on (its CPU affinity where the OS reports it)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


RUNS_DIR = Path(tempfile.gettempdir()) / "unicross-runs"


def register_run() -> None:
    """Marks this process as a training run on this machine (a file named by its pid under
    :data:`RUNS_DIR`, removed at exit), so that runs started side by side share the cores in their
    updates (:func:`update_threads`)."""
    RUNS_DIR.mkdir(parents=True, exist_ok=True)
    mark = RUNS_DIR / str(os.getpid())
    mark.touch()
    atexit.register(lambda: mark.unlink(missing_ok=True))


def concurrent_runs() -> int:
    """Training runs alive on this machine (:func:`register_run`), this one included; at least 1."""
    alive = 0
    for mark in RUNS_DIR.glob("*") if RUNS_DIR.is_dir() else []:
        try:
            os.kill(int(mark.name), 0)
        except (ValueError, ProcessLookupError):
            continue
        except PermissionError:  # another user's live process
            pass
        alive += 1
    return max(alive, 1)


def update_threads(value) -> int:
    """Torch threads for the main process's update (``optim.update_threads``): ``None`` -> the
    usable cores divided among the training runs alive on this machine (at least 1), else the
    positive integer given. Measured on 2 cores (grasp, 2 workers per run, frames/s per run): one
    run 372 on 2 threads, 351 on 1; two runs at once 88 each on 2 threads (the update 13x slower:
    OpenMP threads wait at every op's barrier for a thread descheduled by the other run's workers),
    176 each on 1 (benchmarks/update_contention.py isolates the update)."""
    if value is None:
        return max(1, usable_cores() // concurrent_runs())
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ValueError(f"optim.update_threads must be null or an integer >= 1, got {value!r}")
    return value


@contextlib.contextmanager
def one_thread():
    """Torch on one intra-op thread inside the block. Stepping one env and its policy on a batch of
    one gains nothing from more threads, and their spin-waits stole the cores of a second run on the
    same machine (two one-env runs on 2 cores: 45-60 frames/s each instead of ~450)."""
    n = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(n)


class LeanCollector:
    """Rollouts in ``num_envs`` envs of ``env_id``, ``horizon`` steps per env per batch.

    CPU with ``num_envs > 1``: one worker process per env (spawned). CPU with one env, or the GPU
    backend: in the main process. Env ``i`` starts from a reset seeded with ``seed + i`` and draws
    its action noise from a generator seeded likewise (``deterministic``: the mean action, as
    DAgger's student acts; the stored log-probability is then that of the mean), AR(1) in time with
    ``noise_correlation`` (see :class:`Rollout`); ``teacher``: a gait labelling every state
    (:func:`make_teacher`), which the envs also take added to the policy's action with ``residual``
    (``model.base_policy``). The envs are built first (``dims``,
    ``n_act`` come from them); :meth:`set_actor` then hands them the actor, whose tensors are moved
    to shared memory, so the optimiser's in-place steps and the statistics updates reach the workers.

    Overlapped collection (``set_actor(actor, own_copy=True)``, PPO's ``collector.overlap``): the
    workers act with a copy of the actor in shared memory, refreshed from the learner's only by
    :meth:`sync_actor`, so that :meth:`start` can launch the next batch while the main process
    updates the learner's weights (the batch then comes from the weights of one update earlier).
    :meth:`finish` waits for the batch; :meth:`collect` is the two in a row.
    """

    def __init__(self, env_id: str, env_kwargs: dict, num_envs: int, horizon: int, seed: int = 0,
                 backend: str = "physx_cpu", deterministic: bool = False, noise_correlation: float = 0.0,
                 teacher: Optional[str] = None, residual: bool = False, alternates: Optional[list] = None,
                 alternate_share: float = 0.0):
        self.horizon, self.num_envs, self.teacher = horizon, num_envs, teacher is not None
        if alternates and backend == "physx_cuda":
            raise ValueError("alternate envs (e.g. DAgger's env.chain_share) run in CPU env workers, not on the GPU "
                             "backend")
        if not 0.0 <= alternate_share <= 1.0:
            raise ValueError(f"the share of episodes in alternate envs must be in [0, 1], got {alternate_share}")
        kw = dict(env_kwargs)
        self._procs, self._conns, self._local, self.buf = [], [], None, None
        self._learner: Optional[torch.nn.Module] = None  # the actor the workers' copy follows (own_copy)
        self._shared: Optional[torch.nn.Module] = None  # the actor the envs run (in shared memory for worker processes)
        self._pending = False  # a batch is being collected (start() without finish())
        self._stash: Optional[TensorDict] = None  # a finished batch not yet taken (see map_shards)
        if backend == "physx_cuda":
            kw.update(sim_backend="physx_cuda", num_envs=num_envs)
        else:
            kw.update(sim_backend="physx_cpu", num_envs=1)
        alt = [(i, dict(k, sim_backend=kw["sim_backend"], num_envs=kw["num_envs"])) for i, k in alternates or []]
        if backend == "physx_cuda" or num_envs == 1:
            self._local = Rollout(env_id, kw, seed, deterministic, noise_correlation, teacher, residual, alt,
                                  alternate_share)
            self.dims, self.n_act, self.device = self._local.dims, self._local.n_act, self._local.device
            return
        ctx = mp.get_context("spawn")
        for rank in range(num_envs):
            parent, child = ctx.Pipe()
            p = ctx.Process(target=_worker, args=(rank, env_id, kw, seed + rank, deterministic, noise_correlation, teacher,
                                                          residual, child, alt, alternate_share), daemon=True,
                            name=f"unicross-env-{rank}")
            p.start()
            self._procs.append(p)
            self._conns.append(parent)
        self.dims, self.n_act = self._wait("ready")[0]
        self.device = torch.device("cpu")

    @property
    def frames_per_batch(self) -> int:
        return self.num_envs * self.horizon

    def set_actor(self, actor: torch.nn.Module, own_copy: bool = False) -> None:
        """The module ``(hand, object, goal) -> (loc, scale)`` the envs act with; ``own_copy``: they act
        with a copy of it on the envs' device that :meth:`sync_actor` refreshes (overlapped collection,
        or a learner on another device, ``optim.update_device``)."""
        if own_copy:
            self._learner, actor = actor, copy.deepcopy(actor).to(self.device)
        self._shared = actor
        if self._local is not None:
            self._local.set_actor(actor)
            self.buf = make_buffer(self.num_envs, self.horizon, self.dims, self.n_act, self.device, self.teacher)
            return
        actor.share_memory()
        self.buf = make_buffer(self.num_envs, self.horizon, self.dims, self.n_act, teacher=self.teacher).share_memory_()
        for conn in self._conns:
            conn.send(("setup", (actor, self.buf)))
        self._wait("ready")

    def _wait(self, expected: str) -> list:
        errors, payloads = [], []
        for rank, conn in enumerate(self._conns):
            try:
                msg, payload = conn.recv()
            except EOFError:
                msg, payload = "error", f"worker {rank} exited (exit code {self._procs[rank].exitcode})"
            if msg == "error":
                errors.append(f"env worker {rank}:\n{payload}")
            elif msg != expected:
                errors.append(f"env worker {rank}: unexpected message {msg!r}")
            payloads.append(payload)
        if errors:
            self.close()
            raise RuntimeError("\n".join(errors))
        return payloads

    @torch.no_grad()
    def sync_actor(self) -> None:
        """The workers' copy of the actor takes the learner's current weights and statistics
        (``set_actor(..., own_copy=True)``; no-op otherwise). Only between batches."""
        if self._pending:
            raise RuntimeError("sync_actor() while a batch is being collected")
        if self._learner is not None:
            self._shared.load_state_dict(self._learner.state_dict())  # in place: stays in shared memory

    @property
    def pending(self) -> bool:
        """A batch started and not yet taken by :meth:`finish`."""
        return self._pending or self._stash is not None

    def start(self) -> None:
        """Launches the next batch in the workers and returns at once (in-process envs: the batch
        is collected by :meth:`finish`)."""
        if self.buf is None:
            raise RuntimeError("set_actor() first")
        if self.pending:
            raise RuntimeError("start() while a batch is pending: finish() it first")
        if self._local is None:
            for conn in self._conns:
                conn.send("collect")
        self._pending = True

    def finish(self) -> TensorDict:
        """The batch of the last :meth:`start`, ``[num_envs, horizon]`` (a copy: the caller may add
        keys and rescale), once the workers are done with it."""
        if self._stash is not None:
            data, self._stash = self._stash, None
            return data
        if not self._pending:
            raise RuntimeError("finish() without start()")
        try:
            if self._local is not None:
                with one_thread():
                    self._local.collect(self.buf)
            else:
                self._wait("done")
        finally:
            self._pending = False
        return self.buf.clone()

    def collect(self) -> TensorDict:
        """One batch ``[num_envs, horizon]`` (a copy: the caller may add keys and rescale)."""
        self.start()
        return self.finish()

    def next_overlapped(self, more: bool) -> TensorDict:
        """Overlapped collection's batch: the one started earlier (started now if none), then the
        workers take the learner's current weights and, if ``more`` batches follow, start the next
        one, which they collect while the caller updates on this one."""
        if not self.pending:
            self.start()
        data = self.finish()
        self.sync_actor()
        if more:
            self.start()
        return data

    def map_shards(self, fn, **kwargs) -> list:
        """``fn(actor, shard=(i, n), **kwargs)`` in each of the n workers (their envs idle), e.g. an
        evaluation split over objects; returns the n results. One env in the main process: one call
        with ``shard=None``. ``fn`` must be a module-level function (it is pickled)."""
        if self._local is not None:
            self.sync_actor()  # a copy (learner on the GPU) evaluates the learner's current weights
            with one_thread():
                return [fn(self._local.actor, shard=None, **kwargs)]
        if self._pending:  # a batch in flight: kept for the next finish()
            self._stash = self.finish()
        self.sync_actor()  # the workers evaluate the learner's current weights
        n = len(self._conns)
        for rank, conn in enumerate(self._conns):
            conn.send(("call", fn, dict(kwargs, shard=(rank, n))))
        return self._wait("done")

    def close(self) -> None:
        if self._local is not None:
            self._local.close()
            self._local = None
        for conn, p in zip(self._conns, self._procs):
            try:
                if p.is_alive():
                    conn.send("close")
            except (BrokenPipeError, OSError):
                pass
        for p in self._procs:
            p.join(timeout=10)
            if p.is_alive():
                p.terminate()
        self._procs, self._conns = [], []


def resolve_num_envs(num_envs, backend: str, ray_address: Optional[str] = None) -> int:
    """``env.num_envs``: null means one env per usable CPU core (CPU backend; with Ray, per CPU
    of the cluster, which it connects to first)."""
    if ray_address:
        if backend != "physx_cpu":
            raise ValueError("collector.ray_address runs CPU env actors: it needs env.backend physx_cpu")
        from unicross.rl.ray_collector import connect
        connect(ray_address)
    if num_envs is None:
        if backend != "physx_cpu":
            raise ValueError("env.num_envs must be set for the GPU backend (e.g. 4096)")
        if ray_address:
            import ray
            return max(1, int(ray.cluster_resources().get("CPU", 1)))
        return usable_cores()
    if int(num_envs) < 1:
        raise ValueError(f"env.num_envs must be >= 1, got {num_envs}")
    return int(num_envs)


def check_overlap(overlap: bool, backend: str, num_envs: int, ray_address: Optional[str]) -> None:
    """``collector.overlap`` needs env worker processes on this machine: refused (before any
    simulation) with one env, the GPU backend or Ray env actors."""
    if overlap and (backend != "physx_cpu" or num_envs < 2 or ray_address):
        raise ValueError(f"collector.overlap needs env worker processes on this machine (env.backend physx_cpu, "
                         f"num_envs > 1, no collector.ray_address); this run has {backend}, {num_envs} env(s), "
                         f"ray_address {ray_address}")


def same_device(a, b) -> bool:
    """Whether two torch devices are one ("cuda" and "cuda:0" are, on a process whose current GPU is 0)."""
    a, b = torch.device(a), torch.device(b)
    if a.type != b.type:
        return False
    if a.type != "cuda":
        return True
    current = torch.cuda.current_device() if torch.cuda.is_available() else 0
    return (current if a.index is None else a.index) == (current if b.index is None else b.index)


def resolve_update_device(value: Optional[str], backend: str) -> torch.device:
    """``optim.update_device``: where the networks, GAE and the update live. null: where the envs'
    tensors are (the CPU for physx_cpu, the GPU for physx_cuda); "cuda" (or "cuda:N") puts the
    learner of CPU env workers on a GPU, the workers acting with a CPU copy refreshed after each
    update; "auto": the GPU when torch sees one. Refused before any simulation when no GPU is there,
    or with physx_cuda on another device than the envs'."""
    envs = torch.device("cuda" if backend == "physx_cuda" else "cpu")
    if value is None:
        return envs
    if value == "auto":
        return torch.device("cuda") if torch.cuda.is_available() else envs
    try:
        dev = torch.device(value)
    except (RuntimeError, TypeError) as e:
        raise ValueError(f"optim.update_device must be null, 'auto', 'cpu' or 'cuda[:N]', not {value!r}") from e
    if dev.type not in ("cpu", "cuda"):
        raise ValueError(f"optim.update_device must be null, 'auto', 'cpu' or 'cuda[:N]', not {value!r}")
    if dev.type == "cuda" and not torch.cuda.is_available():
        raise ValueError(f"optim.update_device={value}: torch sees no CUDA device here (torch {torch.__version__}); "
                         "leave it null to update on the CPU")
    if backend == "physx_cuda" and dev.type != "cuda":
        raise ValueError(f"optim.update_device={value} with env.backend physx_cuda: the envs' tensors are on the GPU, "
                         "the update runs there (leave it null)")
    return dev


def make_collector(env_id: str, env_kwargs: dict, num_envs: int, horizon: int, seed: int, backend: str,
                   ray_address: Optional[str] = None, deterministic: bool = False, noise_correlation: float = 0.0,
                   teacher: Optional[str] = None, residual: bool = False, alternates: Optional[list] = None,
                   alternate_share: float = 0.0):
    """The collector of a trainer: Ray env actors when ``ray_address`` is set (see
    :func:`resolve_num_envs`, which connects), else :class:`LeanCollector` (``alternates``: see
    :class:`Rollout`)."""
    if not 0.0 <= noise_correlation < 1.0:
        raise ValueError(f"collector.noise_correlation must be in [0, 1), got {noise_correlation}")
    if ray_address and alternates:
        raise ValueError("alternate envs (e.g. DAgger's env.chain_share) run in local env workers, not Ray env actors")
    if ray_address:
        from unicross.rl.ray_collector import RayCollector
        return RayCollector(env_id, env_kwargs, num_envs, horizon, seed=seed, address=ray_address,
                            deterministic=deterministic, noise_correlation=noise_correlation)
    return LeanCollector(env_id, env_kwargs, num_envs, horizon, seed=seed, backend=backend,
                         deterministic=deterministic, noise_correlation=noise_correlation, teacher=teacher,
                         residual=residual, alternates=alternates, alternate_share=alternate_share)
