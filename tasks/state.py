"""The task state next to the simulation state (part of :class:`unicross.tasks.base.UniCrossEnv`).

:class:`TaskStateIO` saves and restores everything the next observation and reward depend on
beyond the simulator's own state (targets, accumulated motion, commands, noise, forces), through
ManiSkill's ``get_state_dict``/``set_state_dict`` under the key ``"task"``.
"""
from __future__ import annotations

from typing import Any, Dict

import torch
from mani_skill.utils import common

from unicross import formulation as F


class TaskStateIO:
    """Task-state save and restore of the UniCross task (a mixin of ``UniCrossEnv``)."""

    _TASK_STATE = ("root_p", "root_q", "init_rel", "targets", "prev_rel", "final_x_or", "final_q_or", "axis",
                   "command", "finger_q0", "rot_acc", "trans_acc", "ever_dropped", "obj_z0", "lift", "perturb",
                   "obs_noise", "obj_vel_h", "obj_angvel_h", "hand_vel", "hand_angvel", "link_force", "disturb", "mode")

    def _task_state(self) -> Dict[str, torch.Tensor]:
        out = {}
        for k in self._TASK_STATE:
            v = getattr(self, k)
            if isinstance(v, F.Relational):
                v = v.flat()
            v = v.float()
            out[k] = v[:, None] if v.ndim == 1 else v
        return out

    def get_state_dict(self):
        state = super().get_state_dict()
        state["task"] = self._task_state()
        return state

    def set_state_dict(self, state: dict, env_idx: torch.Tensor = None):
        super().set_state_dict(state, env_idx)
        task = state.get("task")
        if task is None:
            return
        idx = slice(None) if env_idx is None else env_idx
        for k in self._TASK_STATE:
            cur = getattr(self, k)
            v = common.to_tensor(task[k], device=self.device)
            if isinstance(cur, F.Relational):
                flat = cur.flat()
                flat[idx] = v
                setattr(self, k, F.Relational.unflat(flat).clone())
            else:
                v = v.reshape(v.shape[0], *cur.shape[1:]).to(cur.dtype)
                cur[idx] = v
        self._apply_command()
        self._pending[idx] = False
        # the observation reflects the restored state
        self.evaluate()

    def set_state(self, state, env_idx: torch.Tensor = None):
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
        for k, v in self._task_state().items():
            task[k] = state[:, start:start + v.shape[-1]]
            start += v.shape[-1]
        if start == state.shape[-1]:
            sd["task"] = task
        self.set_state_dict(sd, env_idx)
