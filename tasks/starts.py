"""Episode and phase starts (part of :class:`unicross.tasks.base.UniCrossEnv`).

:class:`EpisodeStarts` draws the grasp start on the table and the in-hand starts from the grasp
dataset, and holds :meth:`~EpisodeStarts.reset_task_state`, the one place an episode (and a chain
phase) starts its relational targets, relocation goal and accumulated motion. Every draw comes
from the task's generator ``self._gen``, in a fixed order, so a seeded reset replays its episode.
"""
from __future__ import annotations

import math

import torch

from unicross import formulation as F
from unicross.geometry import (
    pose_mul, quat_from_axis_angle, quat_from_euler_xyz, quat_from_matrix, quat_mul, quat_positive,
    relative_pose,
)
from unicross.tasks.scene import CATEGORY_ID


def _random_quaternion(n: int, gen: torch.Generator, device) -> torch.Tensor:
    q = torch.randn(n, 4, generator=gen, device=device)
    return quat_positive(q / torch.linalg.norm(q, dim=-1, keepdim=True))


class EpisodeStarts:
    """Start-state samplers of the UniCross task (a mixin of ``UniCrossEnv``)."""

    def _grasp_start(self, env_idx):
        """Grasp start: the object resting on the table (upright with probability 1/2 where it can
        stand, random yaw and position), the hand top-down above it with the fingers spread
        (theta0/theta1 of the hand spec), fingers along the long axis of an elongated object.
        Returns world hand and object poses and finger joint positions."""
        dev, spec, g, b = self.device, self.hand_spec, self._gen, len(env_idx)
        cat = self.obj_category[env_idx]
        upright = (torch.rand(b, generator=g, device=dev) < 0.5) & self.obj_can_stand[env_idx]
        h = torch.where(upright, self.obj_rest_height[env_idx, 1], self.obj_rest_height[env_idx, 0])
        yaw = torch.rand(b, generator=g, device=dev) * 2 * math.pi
        zaxis = torch.tensor([0.0, 0.0, 1.0], device=dev).expand(b, 3)
        q_yaw = quat_from_axis_angle(zaxis, yaw)
        stand = quat_from_axis_angle(torch.tensor([0.0, 1.0, 0.0], device=dev).expand(b, 3),
                                     torch.full((b,), -math.pi / 2, device=dev))
        obj_q_table = torch.where(upright[:, None], quat_mul(q_yaw, stand), q_yaw)
        r = self.cfg["grasp"]["xy_range"]
        xy = (torch.rand(b, 2, generator=g, device=dev) * 2 - 1) * r
        obj_p_table = torch.cat([xy, h[:, None]], dim=-1)
        # hand: palm normal (+x_h) down; fingers (+z_h) along the object's long axis when elongated
        flip = (torch.rand(b, generator=g, device=dev) < 0.5).float() * math.pi
        hand_yaw = torch.where(cat == CATEGORY_ID["elongated"], yaw + flip,
                               torch.rand(b, generator=g, device=dev) * 2 * math.pi)
        xh = torch.tensor([0.0, 0.0, -1.0], device=dev).expand(b, 3)
        zh = torch.stack([torch.cos(hand_yaw), torch.sin(hand_yaw), torch.zeros_like(hand_yaw)], -1)
        yh = torch.cross(zh, xh, dim=-1)
        hand_q_grasp = quat_from_matrix(torch.stack([xh, yh, zh], dim=-1))
        hand_p_grasp = obj_p_table.clone()
        hand_p_grasp[:, 2] = 2 * h + self.cfg["grasp"]["hover"]
        init_pose = torch.stack([torch.tensor(spec.init_finger_qpos(c), device=dev) for c in ("wrappable", "elongated")])
        return hand_p_grasp, hand_q_grasp, obj_p_table, obj_q_table, init_pose[cat]

    def _in_hand_start(self, env_idx, hand_p, hand_q, obj_p, obj_q, fq):
        """In-hand start (envs whose skill does not start on the table keep the given start): a grasp
        state from the dataset, with the wrist where it was grasped (``Skill.wrist_where_grasped``,
        relocate, and rows marked ``keep_wrist``: states recorded where a chain left the hand) or at
        ``in_hand_start_height`` in a random (or palm-up) orientation (rotate, translate).
        Returns hand and object poses, finger positions and targets, and the recorded coupled-joint
        positions (``(is_grasp, mimic_qpos)`` or None)."""
        dev, g, b = self.device, self._gen, len(env_idx)
        gs = self.grasps.sample(self.obj_index[env_idx], self.object_names, g,
                                needed=~self._starts_on_table[self.mode[env_idx]])
        random_q = _random_quaternion(b, g, dev)
        if self.cfg["in_hand_orientation"] == "palm_up":  # palm normal (+x_h) up, random yaw
            psi = torch.rand(b, generator=g, device=dev) * 2 * math.pi
            xu = torch.tensor([0.0, 0.0, 1.0], device=dev).expand(b, 3)
            zu = torch.stack([torch.cos(psi), torch.sin(psi), torch.zeros_like(psi)], -1)
            random_q = quat_from_matrix(torch.stack([xu, torch.cross(zu, xu, dim=-1), zu], dim=-1))
        keep = self._wrist_where_grasped[self.mode[env_idx]][:, None]
        if "keep_wrist" in gs.keys():  # rows recorded where a chain left the hand start there
            keep = keep | gs["keep_wrist"][:, None]
        world_q = torch.where(keep, gs["wrist_pose"][:, 3:], random_q)
        inhand_p = torch.tensor([0.0, 0.0, self.cfg["in_hand_start_height"]], device=dev).expand(b, 3)
        world_p = torch.where(keep, gs["wrist_pose"][:, :3], inhand_p)
        op, oq = pose_mul(world_p, world_q, gs["object_pose_hand"][:, :3], gs["object_pose_hand"][:, 3:])
        is_grasp = self._starts_on_table[self.mode[env_idx]][:, None]
        mq = None
        if "mimic_qpos" in gs.keys() and gs["mimic_qpos"].shape[-1] == len(self._midx) > 0:
            mq = (is_grasp, gs["mimic_qpos"])
        return (torch.where(is_grasp, hand_p, world_p), torch.where(is_grasp, hand_q, world_q),
                torch.where(is_grasp, obj_p, op), torch.where(is_grasp, obj_q, oq),
                torch.where(is_grasp, fq, gs["finger_qpos"]), torch.where(is_grasp, fq, gs["finger_target"]), mq)

    def reset_task_state(self, env_idx, hand_p, hand_q, obj_p, obj_q, finger_q0, relocate_goal):
        """The task state at the start of an episode or of a chain phase, for envs ``env_idx``, from
        the world poses of the hand (the new root frame) and the object: every relational pose and
        target at its start value, the relocation goal drawn from the paper's ranges around the
        object where ``relocate_goal`` [B] is set (elsewhere the start pose), accumulated motion and
        lift cleared, the finger reference pose ``finger_q0``. The one place both
        ``_initialize_episode`` and the chain's phase switch start a mode from."""
        b, dev, g = len(env_idx), self.device, self._gen
        self.root_p[env_idx], self.root_q[env_idx] = hand_p, hand_q
        xo, qo = relative_pose(hand_p, hand_q, obj_p, obj_q)
        ident = torch.zeros(b, 4, device=dev)
        ident[:, 0] = 1
        init = F.Relational(x_oh=xo, q_oh=qo, x_or=xo, q_or=qo, x_hr=torch.zeros_like(xo), q_hr=ident)
        for rel in (self.init_rel, self.targets, self.prev_rel, self.cur_rel):
            rel.assign(init, env_idx)
        # relocate: final object pose = start + world offsets (x, y, z; roll, pitch, yaw)
        rt = self.cfg["relocate_target"]
        off = torch.rand(b, 3, generator=g, device=dev)
        off = torch.stack([(off[:, 0] * 2 - 1) * rt["xy"], (off[:, 1] * 2 - 1) * rt["xy"],
                           rt["z"][0] + off[:, 2] * (rt["z"][1] - rt["z"][0])], -1)
        rpy = (torch.rand(b, 3, generator=g, device=dev) * 2 - 1) * rt["rpy"]
        fp, fqw = obj_p + off, quat_positive(quat_mul(quat_from_euler_xyz(rpy), obj_q))
        fx, fqr = relative_pose(hand_p, hand_q, fp, fqw)
        self.final_x_or[env_idx] = torch.where(relocate_goal[:, None], fx, xo)
        self.final_q_or[env_idx] = torch.where(relocate_goal[:, None], fqr, qo)
        self.finger_q0[env_idx] = finger_q0
        self.rot_acc[env_idx] = 0
        self.trans_acc[env_idx] = 0
        self.success_paid[env_idx] = 0
        self.obj_z0[env_idx] = obj_p[:, 2]
        self.lift[env_idx] = 0
        self._pending[env_idx] = True

    def _draw_obs_noise(self, n: int) -> torch.Tensor:
        """U(-1, 1) x per-joint noise scale: ``joint_obs_noise`` (rad) on finger joints,
        ``wrist_obs_noise`` (m, rad) on the virtual wrist joints."""
        u = torch.rand(n, self.hand_spec.dof, generator=self._gen, device=self.device) * 2 - 1
        return u * self._obs_noise_scale
