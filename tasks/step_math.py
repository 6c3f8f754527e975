"""The per-step tensor math of the task (part of :class:`unicross.tasks.base.UniCrossEnv`).

:class:`StepMath` holds what happens between the simulator's reads and the next action: the action
-> joint command map, the measurements (link-to-surface vectors, finger torques), relational poses,
accumulated motion, drop, success, the reward terms, the next targets and the observation parts.
It is pure tensor math on the task state (no reads, no random draws), compiled to one graph per
task when ``UNICROSS_COMPILE`` is on (``unicross/compiling.py``).
"""
from __future__ import annotations

import json
from typing import Dict

import torch

from unicross import formulation as F
from unicross import registry as R
from unicross.observations import observe_flat
from unicross.geometry import (
    closest_point_shapes, pose_mul, quat_apply,
    quat_angle, quat_inv,
)


class StepMath:
    """Per-step math of the UniCross task (a mixin of ``UniCrossEnv``)."""

    def _graph_key(self):
        """The Python values the step math reads that may change after construction: the skill
        every env shares (``static_skill``, per chain phase), the closest-point formulas and whether
        the scene has meshes (scene rebuilds). They select the compiled graph
        (``unicross.compiling.GraphMethod``); every other Python value it reads (configuration,
        reward terms, hand) is fixed when the task is made."""
        return self.static_skill, self._closest_kinds, self.obj_tris is None

    def _graph_context(self) -> str:
        """Everything fixed when the task is made that the compiled step math may bake in (class,
        hand, configuration, reward configuration, modes, sizes): tasks with the same context share
        their compiled graphs in a process (``unicross.compiling.GraphMethod``; evaluation makes a
        task per object and axis). A subclass with more such values adds them."""
        return repr((type(self).__module__, type(self).__qualname__, self.hand_spec,
                     json.dumps(self.cfg, sort_keys=True, default=repr),
                     json.dumps(self.reward_cfg, sort_keys=True, default=repr), tuple(self.modes_used),
                     self.num_envs, str(self.device), self._sim_steps_per_control, self._control_freq))

    def _command_math_eager(self, a: torch.Tensor, elapsed_steps: torch.Tensor, perturb_normal=None,
                            perturb_uniform=None):
        """The normalised action [-1, 1] -> this step's joint command (``self.command``; the wrist
        reference is the target hand pose, raised during the grasp lift) -> the drive targets of all
        driven joints; and the external forces on the object for this step's substeps
        (:meth:`_object_forces`, from the draws of ``UniCrossEnv._draw_perturbation``). Pure tensor
        math on the task state, compiled like ``_step_math_eager``. Returns ``(targets, forces)``."""
        a = a.clamp(-1.0, 1.0)
        ref = F.wrist_reference(self.targets)
        ref[:, :3] = ref[:, :3] + self._advance_lift(elapsed_steps)
        self.command = F.map_action(a, self.command, ref, self.action_scale, self.q_lower, self.q_upper,
                                    wrist_from_target=not self.cfg["ablation"]["no_target_action"])
        return self._drive_targets(), self._object_forces(elapsed_steps, perturb_normal, perturb_uniform)

    def _object_forces(self, elapsed_steps: torch.Tensor, normal, uniform):
        """This control step's external object forces for all substeps [k, N, 3] (None: none): the
        decaying random perturbation of domain randomisation (a new force ``scale * m * normal`` with
        probability ``perturb_prob`` per substep, else the last one times ``perturb_decay``; state
        ``self.perturb``) plus the constant disturbance of the robustness protocol (for grasp only
        while lifting)."""
        rc = self.cfg["randomization"]
        k, n = self._sim_steps_per_control, self.num_envs
        forces = None
        if normal is not None:
            new = rc["perturb_scale"] * self.obj_mass[:, None] * normal
            redraw = uniform < rc["perturb_prob"]
            f, steps = self.perturb, []
            for i in range(k):  # the decay recursion over the substeps of one control step
                f = torch.where(redraw[i], new[i], f * rc["perturb_decay"])
                steps.append(f)
            self.perturb = f
            forces = torch.stack(steps)
        if self.cfg["disturbance"]["max_scale"] > 0:
            active = torch.ones(n, 1, dtype=torch.bool, device=self.device)
            lift_after = self.cfg["grasp"]["lift_after"]
            if lift_after is not None:
                active = (~self._lifts[self.mode] | (elapsed_steps >= lift_after))[:, None]
            disturb = torch.where(active, self.disturb, torch.zeros_like(self.disturb))
            forces = disturb.expand(k, n, 3) if forces is None else forces + disturb
        return forces

    def _advance_lift(self, elapsed_steps: torch.Tensor) -> torch.Tensor:
        """Grasp lift phase: the wrist reference (the Free current wrist pose) rises by
        ``lift_speed * dt`` per step after ``lift_after`` steps; ``self.lift`` accumulates the rise,
        which the Fixed object target follows. Returns this step's increment (root frame)."""
        lift_after = self.cfg["grasp"]["lift_after"]
        if lift_after is None or (self.static_skill is not None and not R.skill(self.static_skill).lifts):
            return torch.zeros_like(self.lift)
        lifting = self._lifts[self.mode] & (elapsed_steps >= lift_after)
        up_root = quat_apply(quat_inv(self.root_q), self._world_up.expand_as(self.lift))
        step = lifting[:, None].float() * up_root * self.cfg["grasp"]["lift_speed"] * self.control_dt
        self.lift = self.lift + step
        return step

    def _measure(self, pos, quat, force, qpos, qvel) -> Dict[str, torch.Tensor]:
        hand_p, hand_q = pos[:, 0], quat[:, 0]
        link_p, link_q = pos[:, 1:-1], quat[:, 1:-1]
        obj_p, obj_q = pos[:, -1], quat[:, -1]
        L = link_p.shape[1]
        probe_w = link_p + quat_apply(link_q, self.link_probe.expand(self.num_envs, L, 3))
        inv_q = quat_inv(obj_q)[:, None].expand(-1, L, 4)
        probe_o = quat_apply(inv_q, probe_w - obj_p[:, None])
        closest_o = closest_point_shapes(probe_o, self.obj_shape, self.obj_params, self.obj_tris, self._closest_kinds)
        vec_w = quat_apply(obj_q[:, None].expand(-1, L, 4), closest_o - probe_o)  # link -> surface, world axes
        vec_h = quat_apply(quat_inv(hand_q)[:, None].expand(-1, L, 4), vec_w)      # ... in the hand frame
        q = qpos[:, self._qidx]
        qd = qvel[:, self._qidx]
        kp, kd, fl = self._finger_pd
        torque = torch.clamp(kp * (self.command[:, 6:] - q[:, 6:]) - kd * qd[:, 6:], -fl, fl)
        return dict(hand_p=hand_p, hand_q=hand_q, obj_p=obj_p, obj_q=obj_q, link_vec=vec_h,
                    link_distance=torch.linalg.norm(vec_h, dim=-1), force=force, qpos=q,
                    finger_torque=torque)

    def _step_math_eager(self, pos, quat, force, qpos, qvel, elapsed_steps, noise):
        """Everything ``evaluate()`` computes from the step's reads: distances, relational poses,
        velocities, accumulated motion, drop, success, reward terms, the next targets, the
        observation parts and the joint-reading noise (``noise``, drawn outside: a step's new
        draw, kept only after a physics step). Pure tensor math on the task's state (no reads, no
        random draws), so it compiles to one graph (``UNICROSS_COMPILE``).

        Returns ``(info, out)``: ``info`` is ``evaluate()``'s; ``out`` = (state observation, dense
        reward, terminated, truncated) as ``step()`` returns them when ManiSkill's generic assembly
        is skipped (``UniCrossEnv.step``): a non-finite observation or reward (a physics blow-up)
        is zeroed, reported as ``info["nonfinite"]`` and ends the episode (truncated)."""
        m = self._measure(pos, quat, force, qpos, qvel)
        cur = F.relational_poses(self.root_p, self.root_q, m["hand_p"], m["hand_q"], m["obj_p"], m["obj_q"])
        pend = self._pending
        self.obs_noise = torch.where(pend[:, None], noise, self.obs_noise)
        skill = F.MODE_SKILL_ID.to(self.device)[self.mode]
        axis_prev = self.axis
        goal_err_prev, goal_err = self._goal_errors(cur)
        self._advance_motion(cur, pend, axis_prev)
        # reward compares against the targets the last action aimed at; Free targets = current
        reward_targets = F.with_free_as_current(self.mode, self.targets, cur)
        held = ~self.ever_dropped  # before this step's drop test
        drop = self._drop(m["link_distance"], elapsed_steps)
        self._advance_targets(cur, pend)
        success, contact, lifted, pos_err, rot_err = self._success(m, skill)
        force_c = m["force"].clamp(max=self.cfg["force_clip"])
        # motion along the axis the last action was asked to follow
        is_rot = self._accumulates_rotation[self.mode]
        speed = torch.where(is_rot, (self.obj_angvel_h * axis_prev).sum(-1), (self.obj_vel_h * axis_prev).sum(-1))
        meas = dict(link_distance=m["link_distance"], contact=contact, force_clipped=force_c, speed_along_axis=speed,
                    speed_cap=self._speed_cap[self.mode], relational=cur, reward_targets=reward_targets,
                    finger_qpos=m["qpos"][:, 6:], finger_qpos0=self.finger_q0, hand_lin_vel=self.hand_vel,
                    hand_ang_vel=self.hand_angvel, finger_torque=m["finger_torque"], drop=drop, held=held, success=success,
                    goal_err_prev=goal_err_prev, goal_err=goal_err, success_paid=self.success_paid,
                    obj_speed_hand=self.obj_vel_h.norm(dim=-1), obj_angspeed_hand=self.obj_angvel_h.norm(dim=-1))
        terms = self.rewards(self.mode, meas)
        self.success_paid = torch.where(pend, self.success_paid + terms["success"], self.success_paid)
        self._observation_parts(m, cur, contact, force_c)
        info = dict(success=success, fail=drop, drop=drop, ever_dropped=self.ever_dropped.clone(),
                    lifted=lifted, relocate_pos_err=pos_err, relocate_rot_err=rot_err,
                    rotation=self.rot_acc.clone(), translation=self.trans_acc.clone(),
                    num_contacts=contact.sum(-1), mode=self.mode.clone())
        info.update({f"reward_{k}": v for k, v in terms.items()})
        return info, self._step_outputs(info, elapsed_steps)

    def _step_outputs(self, info: dict, elapsed_steps):
        """(state observation, dense reward, terminated, truncated) after the step, non-finite rows
        zeroed and truncated; sets ``info["nonfinite"]``."""
        reward = self.dense_reward(info)
        obs = observe_flat(self, self._obs_terms)
        bad = ~torch.isfinite(reward) | ~torch.isfinite(obs).all(-1)
        info["nonfinite"] = bad
        terminated = info["fail"].clone() if self.cfg["terminate_on_drop"] else torch.zeros_like(info["fail"])
        truncated = (elapsed_steps >= self.episode_length[self.mode]) | bad
        obs = torch.nan_to_num(obs, nan=0.0, posinf=0.0, neginf=0.0)
        return obs, torch.where(bad, torch.zeros_like(reward), reward), terminated, truncated

    def dense_reward(self, info: dict) -> torch.Tensor:
        """The dense reward: the sum of the reward terms in ``info``."""
        return sum(info[f"reward_{k}"] for k in self.rewards.names)

    def _goal_errors(self, cur: F.Relational):
        """The object's position (m) and angle (rad) error to its final root-frame pose before and
        after the step ([N, 2] each; ``r_progress``)."""
        prev = self.prev_rel
        before = torch.stack([torch.linalg.norm(prev.x_or - self.final_x_or, dim=-1),
                              quat_angle(prev.q_or, self.final_q_or)], dim=-1)
        after = torch.stack([torch.linalg.norm(cur.x_or - self.final_x_or, dim=-1),
                             quat_angle(cur.q_or, self.final_q_or)], dim=-1)
        return before, after

    def _advance_motion(self, cur: F.Relational, pend, axis_prev):
        """Velocities over the last control step (object in the hand frame, hand in the root frame)
        and the rotation / translation accumulated along the mode's axis, once per control step."""
        dt = self.control_dt
        (xp, qp), (xc, qc) = self.prev_rel.poses(), cur.poses()
        vel, angvel = F.finite_velocity(xp[:, ::2], qp[:, ::2], xc[:, ::2], qc[:, ::2], dt)
        v, w, hv, hw = vel[:, 0], angvel[:, 0], vel[:, 1], angvel[:, 1]
        p1 = pend[:, None]
        self.obj_vel_h = torch.where(p1, v, self.obj_vel_h)
        self.obj_angvel_h = torch.where(p1, w, self.obj_angvel_h)
        self.hand_vel = torch.where(p1, hv, self.hand_vel)
        self.hand_angvel = torch.where(p1, hw, self.hand_angvel)
        is_rot, is_trans = self._accumulates_rotation[self.mode], self._accumulates_translation[self.mode]
        self.rot_acc = self.rot_acc + (pend & is_rot).float() * (w * axis_prev).sum(-1) * dt
        self.trans_acc = self.trans_acc + (pend & is_trans).float() * (v * axis_prev).sum(-1) * dt

    def _drop(self, dist, elapsed_steps):
        """Drop (DESIGN §6): every link farther than ``drop_threshold`` from the object; a grasp can
        only drop what it lifted (before the lift phase the object rests on the table)."""
        drop = dist.min(dim=-1).values > self.cfg["drop_threshold"]
        lift_after = self.cfg["grasp"]["lift_after"]
        grasp_lifting = (elapsed_steps >= lift_after) if lift_after is not None else torch.zeros_like(drop)
        drop = drop & (~self._lifts[self.mode] | grasp_lifting)
        self.ever_dropped = self.ever_dropped | drop
        return drop

    def _advance_targets(self, cur: F.Relational, pend):
        """The next targets and task axis, once per control step. After a drop they hold still: a
        lost object's pose no longer defines where the hand should go (Tracked hand targets would
        chase it; measured: the wrist reference jumped and slammed the hand at 11 m/s in a relocate
        episode without termination)."""
        axis = F.task_axis(self.mode, cur, self.final_x_or)
        init = self.init_rel.clone()
        init.x_or = init.x_or + self.lift
        new_t = F.update_targets(self.mode, cur, init, self.final_x_or, self.final_q_or, axis, self.motion,
                                 skill=self.static_skill)
        self.targets = new_t.where(pend & ~self.ever_dropped, self.targets)
        self.axis = torch.where(pend[:, None], axis, self.axis)
        self.prev_rel = cur.where(pend, self.prev_rel)
        self.cur_rel = cur
        self._pending = torch.zeros_like(pend)

    def _success(self, m: Dict[str, torch.Tensor], skill):
        """Success of each env's skill (DESIGN §6), never after a drop: every skill's registered test
        (``Skill.success``, unicross/success.py) on this step's measurements, each env taking its
        skill's. Returns (success, contact, lifted, pos_err, rot_err)."""
        contact = m["force"] > self.cfg["contact_force_threshold"]
        lifted = (m["obj_p"][:, 2] - self.obj_z0) > self.cfg["grasp"]["lift_success"]
        fx, fq = pose_mul(self.root_p, self.root_q, self.final_x_or, self.final_q_or)
        pos_err = torch.linalg.norm(m["obj_p"] - fx, dim=-1)
        rot_err = quat_angle(m["obj_q"], fq)
        meas = dict(contact=contact, lifted=lifted, pos_err=pos_err, rot_err=rot_err, rot_acc=self.rot_acc,
                    trans_acc=self.trans_acc)
        success_by_skill = torch.stack([test(meas, self.cfg["success"]) for test in self._success_tests], dim=-1)
        success = success_by_skill.gather(1, skill[:, None])[:, 0] & ~self.ever_dropped
        return success, contact, lifted, pos_err, rot_err

    def _observation_parts(self, m: Dict[str, torch.Tensor], cur: F.Relational, contact, force_c):
        """The observation's parts with the ablations applied (``_obs_parts``; the noise on joint
        readings is added when observed, since it is drawn after this math) and the measurements as
        measured (``_measured``: recordings, renders)."""
        ab = self.cfg["ablation"]
        obs_contact, obs_force = contact.float(), force_c
        obs_vec = m["link_vec"].reshape(self.num_envs, -1)
        if ab["no_contact"]:
            obs_contact, obs_force = torch.zeros_like(obs_contact), torch.zeros_like(obs_force)
        if ab["no_distance"]:
            obs_vec = torch.zeros_like(obs_vec)
        goal = F.goal_features(self.mode, self.axis, cur, self.targets, zero_target=ab["no_target_obs"])
        self._obs_parts = dict(qpos=m["qpos"], contact=obs_contact, force=obs_force, distance=obs_vec, goal=goal)
        self._measured = dict(qpos=m["qpos"], contact=contact, force=force_c, vec=m["link_vec"])
