"""The task state next to the simulation state (part of :class:`unicross.tasks.base.UniCrossEnv`).

:class:`TaskStateIO` saves and restores everything the next observation and reward depend on
beyond the simulator's own state (targets, accumulated motion, commands, noise, forces), through
ManiSkill's ``get_state_dict``/``set_state_dict`` under the key ``"task"``.
"""
from __future__ import annotations

from typing import Any, Dict

import torch
from mani_skill.utils import common

from tensordict import TensorDict

from unicross import formulation as F


def _flat(v):
    return v.flat() if isinstance(v, F.Relational) else v


def _column(v: torch.Tensor) -> torch.Tensor:
    """A task-state entry as ManiSkill's flat state vector holds it: float, [N, k], a copy (the live
    tensors change in place: a state that aliased them would follow the episode it was taken from)."""
    v = v.float().clone()
    return v[:, None] if v.ndim == 1 else v


class TaskStateIO:
    """Task-state save and restore of the UniCross task (a mixin of ``UniCrossEnv``).

    ``TASK_STATE`` names every per-env tensor the next observation and reward depend on beyond the
    simulator's state; a subclass with more state extends it (the chain env adds its phase).
    :meth:`task_state` is that state as one TensorDict (batch [N]); ManiSkill's state dict stores it
    under ``"task"`` as float columns (its flat state vector concatenates them)."""

    TASK_STATE = ("root_p", "root_q", "init_rel", "targets", "prev_rel", "final_x_or", "final_q_or", "axis",
                  "command", "finger_q0", "rot_acc", "trans_acc", "success_paid", "ever_dropped", "obj_z0", "lift", "perturb",
                  "obs_noise", "obj_vel_h", "obj_angvel_h", "hand_vel", "hand_angvel", "link_force", "disturb", "mode")

    def task_state(self) -> TensorDict:
        """The task state (``TASK_STATE``) as one TensorDict of batch [N], in its own dtypes; relational
        poses as their 21 numbers (``Relational.flat``)."""
        return TensorDict({k: _flat(getattr(self, k)) for k in self.TASK_STATE}, batch_size=[self.num_envs])

    def load_task_state(self, task, env_idx: torch.Tensor = None) -> None:
        """Writes ``task`` (a TensorDict or dict of [N, ...] tensors, e.g. :meth:`task_state` or the
        ``"task"`` entry of a state dict) into the task state of envs ``env_idx`` (all if None)."""
        idx = slice(None) if env_idx is None else env_idx
        for k in self.TASK_STATE:
            cur = getattr(self, k)
            flat = _flat(cur)
            v = common.to_tensor(task[k], device=self.device)
            flat[idx] = v.reshape(-1, *flat.shape[1:]).to(flat.dtype)  # also unbatched states (replay tools)
            if isinstance(cur, F.Relational):
                setattr(self, k, F.Relational.unflat(flat).clone())

    def get_state_dict(self):
        state = super().get_state_dict()
        state["task"] = {k: _column(v) for k, v in self.task_state().items()}
        return state

    def set_state_dict(self, state: dict, env_idx: torch.Tensor = None):
        super().set_state_dict(state, env_idx)
        if state.get("task") is None:
            return
        self.load_task_state(state["task"], env_idx)
        self._apply_command()
        self._pending[slice(None) if env_idx is None else env_idx] = False
        # the observation reflects the restored state; no random draw (evaluate() would draw the
        # observation noise), so the task generator's sequence stays the episode's and a replay by
        # env states steps on as the recording did
        self._step_math(*self._read(), self.elapsed_steps, self.obs_noise)

    def set_state(self, state, env_idx: torch.Tensor = None):
        """ManiSkill's flat-vector ``set_state`` with the task state: ManiSkill 3.0.1 rebuilds only the
        actors and articulations from a vector, dropping every other key of ``get_state()``; this
        reads the ``"task"`` columns too (when the vector has them) and accepts one unbatched state
        (``replay_trajectory --use-env-states`` passes those)."""
        state = common.to_tensor(state, device=self.device)
        if state.ndim == 1:
            state = state[None]
        sd: Dict[str, Any] = dict(actors={}, articulations={})
        start = 0
        for k in self._init_raw_state["actors"]:
            sd["actors"][k] = state[:, start:start + 13]
            start += 13
        for k, v in self._init_raw_state["articulations"].items():
            sd["articulations"][k] = state[:, start:start + v.shape[-1]]
            start += v.shape[-1]
        task = {}
        for k, v in self.task_state().items():
            width = _column(v).shape[-1]
            task[k] = state[:, start:start + width]
            start += width
        if start == state.shape[-1]:
            sd["task"] = task
        self.set_state_dict(sd, env_idx)
