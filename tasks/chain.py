"""Long-horizon skill chaining in one continuous episode (paper §4.6).

``UniCross-Chain-v1`` starts like the grasp task and runs a sequence of modes such as
``grasp -> relocate -> rotate_x+``. At each phase boundary the mode switches and the targets are
re-instantiated *without resetting the simulation*: the root frame is re-based on the current
hand pose (the articulation root moves to the hand frame and the virtual wrist joints to zero, so
every link keeps its world pose and velocity), Fixed targets take their values at the phase start
and a relocation goal is drawn from the paper's ranges around the current object pose.

Phase success follows DESIGN §6 (grasp: lifted; relocate: within 3 cm and 0.15 rad at the end of
the phase; rotate/translate: > pi/2 rad or > 5 cm within the phase; never dropped). ``info``
carries ``phase`` and ``phase_success`` ([N, P]); the episode ends after the last phase.
"""
from __future__ import annotations

from typing import List, Sequence

import torch
from unicross.tasks.registration import register_task
from mani_skill.utils.structs.pose import Pose

from unicross import formulation as F
from unicross.geometry import quat_apply, quat_inv
from unicross.objects import get_object_set, resolve_objects
from unicross.registry import SKILLS, skill_of_mode
from unicross.tasks.base import UniCrossEnv

PHASE_STEPS = {s.name: s.protocol_steps for s in SKILLS.values()}  # the evaluation protocols' lengths


def parse_sequence(seq: str | Sequence[str]) -> List[str]:
    """'grasp,relocate,rotate:x+' (or a list) -> mode names; validates skills and axes."""
    items = seq.split(",") if isinstance(seq, str) else list(seq)
    modes = []
    for it in items:
        it = it.strip()
        if it in F.MODES:
            modes.append(it)
            continue
        skill, _, axis = it.partition(":")
        modes.append(F.MODES[F.mode_index(skill, axis or None)])
    if not modes or not skill_of_mode(modes[0]).starts_on_table:
        starters = [s.name for s in SKILLS.values() if s.starts_on_table]
        raise ValueError(f"a chain starts with a skill that starts from the table ({starters}), got {items}")
    return modes


def objects_for_chain(objects: Sequence, modes: Sequence[str]) -> list:
    """The objects of ``objects`` whose category can do every phase of ``modes`` (rotate: wrappable,
    translate: elongated, grasp and relocate: both); raises when none can."""
    cats = set.intersection(*(set(skill_of_mode(m).categories) for m in modes))
    objs = [o for o in objects if o.category in cats]
    if not objs:
        raise ValueError(f"no object of the set can do every phase of {list(modes)} "
                         f"(rotate needs wrappable objects, translate elongated ones)")
    return objs


@register_task("UniCross-Chain-v1", max_episode_steps=sum(PHASE_STEPS.values()))
class ChainEnv(UniCrossEnv):
    """Grasp, then the following phases in one continuous episode with one policy."""

    DEFAULT_OBJECTS = "test"

    def __init__(self, *args, sequence="grasp,relocate,rotate:z+", phase_steps=None, **kwargs):
        self.sequence = parse_sequence(sequence)
        steps = dict(PHASE_STEPS, **(phase_steps or {}))
        self.phase_lengths = [steps[F.mode_skill(m)] for m in self.sequence]
        self.phase_ends = torch.cumsum(torch.tensor(self.phase_lengths), 0).tolist()
        cfg = dict(kwargs.pop("config", None) or {})
        cfg.setdefault("episode_length", {})[F.mode_skill(self.sequence[0])] = self.phase_ends[-1]
        objects = kwargs.pop("objects", None) or self.DEFAULT_OBJECTS
        limit = kwargs.pop("object_limit", None)
        objs = get_object_set(objects, limit=limit) if isinstance(objects, str) else resolve_objects(objects)
        objs = objects_for_chain(objs, self.sequence)  # only objects that can do every phase
        super().__init__(*args, modes=(self.sequence[0],), objects=objs, config=cfg, **kwargs)

    TASK_STATE = UniCrossEnv.TASK_STATE + ("phase", "phase_success")

    def _graph_context(self) -> str:
        return repr((super()._graph_context(), self.sequence, self.phase_lengths))

    def _alloc_buffers(self):
        super()._alloc_buffers()
        n, dev, p = self.num_envs, self.device, len(self.sequence)
        self.phase = torch.zeros(n, dtype=torch.long, device=dev)  # per env: partial resets restart one env
        self.phase_success = torch.zeros(n, p, dtype=torch.bool, device=dev)
        self._phase_end = torch.tensor(self.phase_ends, device=dev)
        self._phase_mode = torch.tensor([F.MODES.index(m) for m in self.sequence], device=dev)
        self._phase_once = torch.tensor([SKILLS[F.mode_skill(m)].success_once for m in self.sequence], device=dev)

    def _initialize_episode(self, env_idx, options):
        super()._initialize_episode(env_idx, options)
        self.phase[env_idx] = 0
        self.phase_success[env_idx] = False
        self.mode[env_idx] = self._phase_mode[0]
        self._set_static_skill()

    def load_task_state(self, task, env_idx=None):
        super().load_task_state(task, env_idx)
        self._set_static_skill()

    def _set_static_skill(self):
        """The target update skips other skills' rules when every env is in the same phase."""
        phases = torch.unique(self.phase).tolist()
        self.static_skill = F.mode_skill(self.sequence[phases[0]]) if len(phases) == 1 else None

    # ------------------------------------------------------------------ stepping
    def step(self, action):
        obs, reward, terminated, truncated, info = super().step(action)
        envs = torch.arange(self.num_envs, device=self.device)
        ph = self.phase
        at_end = self.elapsed_steps >= self._phase_end[ph]
        seen = self.phase_success[envs, ph]
        # rotate/translate: exceeded within the phase and never dropped in it (a drop later in the phase
        # takes the success back, as the per-skill protocol's ``dropped`` does); grasp/relocate: at the
        # end of the phase
        self.phase_success[envs, ph] = torch.where(self._phase_once[ph], (seen | info["success"]) & ~info["drop"],
                                                   torch.where(at_end, info["success"], seen))
        switch = at_end & (ph + 1 < len(self.sequence))
        if bool(switch.any()):
            self._switch_phase(switch.nonzero()[:, 0])
            info = self.get_info()
            obs = self.get_obs(info)
        truncated = self.elapsed_steps >= self._phase_end[-1]
        info["phase"] = self.phase.clone()
        info["phase_success"] = self.phase_success.clone()
        return obs, reward, terminated, truncated, info

    def _switch_phase(self, env_idx: torch.Tensor):
        """Envs ``env_idx`` go to their next phase: re-base the root frame on the current hand pose and
        re-instantiate the targets. Writes whole batches (the other envs get their current values back),
        so it needs no partial-reset mask on the GPU backend."""
        robot = self.agent.robot
        pos, quat = self.sensor.poses()
        hand_p, hand_q, obj_p, obj_q = pos[:, 0], quat[:, 0], pos[:, -1], quat[:, -1]
        hand_link = next(l for l in robot.links if l.name == "hand_frame")
        v_w, w_w = hand_link.get_linear_velocity(), hand_link.get_angular_velocity()
        inv = quat_inv(hand_q)
        q, qd = robot.get_qpos().clone(), robot.get_qvel().clone()
        rows, wrist = env_idx[:, None], self._qidx[:6]
        q[rows, wrist] = 0.0
        # at zero Euler angles the wrist rates are the hand's velocities in the new root frame
        qd[rows, wrist] = torch.cat([quat_apply(inv, v_w), quat_apply(inv, w_w)], dim=-1)[env_idx]
        root_p, root_q = robot.pose.p.clone(), robot.pose.q.clone()
        root_p[env_idx], root_q[env_idx] = hand_p[env_idx], hand_q[env_idx]
        robot.set_root_pose(Pose.create_from_pq(root_p, root_q))
        robot.set_qpos(q)
        robot.set_qvel(qd)
        if self.gpu_sim_enabled:
            self.scene._gpu_apply_all()
            self.scene.px.gpu_update_articulation_kinematics()
            self.scene._gpu_fetch_all()
        self.command[env_idx, :6] = 0.0
        self._apply_command()
        # task state of the new phase
        self.phase[env_idx] += 1
        self.mode[env_idx] = self._phase_mode[self.phase[env_idx]]
        every = torch.ones(len(env_idx), dtype=torch.bool, device=self.device)
        self.reset_task_state(env_idx, hand_p[env_idx], hand_q[env_idx], obj_p[env_idx], obj_q[env_idx],
                              robot.get_qpos()[env_idx][:, self._qidx[6:]].clone(), relocate_goal=every)
        self._set_static_skill()
        self._stepped = False
