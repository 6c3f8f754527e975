"""The task's scene and its per-env constants (part of :class:`unicross.tasks.base.UniCrossEnv`).

:class:`TaskScene` builds the table, the floating hand and one object per parallel env (its mass and
friction drawn when the scene is built), binds the hand's joints, contact links, PD gains and mimic
couplings after every (re)configuration, and allocates the task state's buffers.
"""
from __future__ import annotations


import numpy as np
import sapien
import torch
from mani_skill.utils.structs.actor import Actor
from mani_skill.utils.structs.types import GPUMemoryConfig, SimConfig

from unicross import formulation as F
from unicross import registry as R
from unicross.geometry import (
    SHAPE_BOX, SHAPE_CYLINDER, SHAPE_MESH, SHAPE_PRISM, SHAPE_SPHERE,
)
from unicross.rewards import RewardTerms
from unicross.robots.hand import HAND_FRAME_LINK
from unicross.sensing import HandObjectSensor
from unicross.success import get as success_test


CATEGORY_ID = {"wrappable": 0, "elongated": 1}


class TaskScene:
    """Scene building and per-env constants of the UniCross task (a mixin of ``UniCrossEnv``)."""

    @property
    def _default_sim_config(self):
        s = self.cfg["sim"]
        n = self.num_envs  # GPU contact buffers grow with the batch (ManiSkill's in-hand tasks size them so)
        gpu_memory = GPUMemoryConfig(max_rigid_contact_count=n * max(1024, n) * 8,
                                     max_rigid_patch_count=n * max(1024, n) * 2, found_lost_pairs_capacity=2 ** 26)
        return SimConfig(sim_freq=s["sim_freq"], control_freq=s["control_freq"], gpu_memory_config=gpu_memory,
                         scene_config=dict(contact_offset=s["contact_offset"],
                                           solver_position_iterations=s["solver_position_iterations"],
                                           solver_velocity_iterations=s["solver_velocity_iterations"]))

    @property
    def _default_human_render_camera_configs(self):
        """``render_camera``, the camera ``unicross render --renderer sapien`` moves each frame (ManiSkill
        creates it only when the scene can render)."""
        from mani_skill.sensors.camera import CameraConfig
        from mani_skill.utils import sapien_utils
        pose = sapien_utils.look_at(eye=[0.45, 0.45, 0.55], target=[0.0, 0.0, 0.2])
        return CameraConfig("render_camera", pose=pose, width=512, height=512, fov=1.0, near=0.01, far=10.0)

    @property
    def control_dt(self) -> float:
        return 1.0 / self._control_freq

    def _load_agent(self, options: dict):
        super()._load_agent(options, sapien.Pose(p=[0.0, 0.0, 1.0]))

    def _load_scene(self, options: dict):
        can_render = self.scene.can_render()
        if self.cfg["table"]:
            b = self.scene.create_actor_builder()
            b.add_box_collision(half_size=[0.6, 0.6, 0.025])
            if can_render:
                b.add_box_visual(half_size=[0.6, 0.6, 0.025],
                                 material=sapien.render.RenderMaterial(base_color=[0.6, 0.5, 0.4, 1]))
            b.initial_pose = sapien.Pose(p=[0, 0, -0.025])
            self.table = b.build_static(name="table")
        rng = self._batched_episode_rng[0]
        # envs take consecutive pairs from a cursor that starts at a seeded random place (again at
        # every seeded reset) and moves on at every rebuild, so parallel envs and reconfigurations
        # cover the pairs uniformly
        if not hasattr(self, "_pair_cursor") or getattr(self, "_seeded_reset", False):
            self._pair_cursor = int(rng.randint(len(self._pairs)))
        pairs = [self._pairs[(self._pair_cursor + i) % len(self._pairs)] for i in range(self.num_envs)]
        self._pair_cursor += self.num_envs
        rcfg = self.cfg["randomization"]
        dr = rcfg["enabled"]
        masses = rng.uniform(*rcfg["mass"], size=self.num_envs) if dr else np.full(self.num_envs, 0.02)
        frictions = rng.uniform(*rcfg["friction"], size=self.num_envs) if dr else np.full(self.num_envs, 1.0)
        actors = []
        for i, (oi, _) in enumerate(pairs):
            spec = self.object_specs[oi]
            mat = sapien.physx.PhysxMaterial(float(frictions[i]), float(frictions[i]), 0.0)
            b = self.scene.create_actor_builder()
            spec.add_to_builder(b, density=float(masses[i]) / spec.volume(), material=mat, can_render=can_render)
            b.set_scene_idxs([i])
            b.initial_pose = sapien.Pose(p=[0, 0, 0.5])  # one pose for all: each env is its own (sub-)scene
            actors.append(b.build(name=f"object-{i}"))
            self.remove_from_state_dict_registry(actors[-1])
            for link in self.agent.robot.links:  # friction applies to hand and object alike
                for shape in link._objs[i].collision_shapes:
                    shape.physical_material = mat
        self.obj = Actor.merge(actors, name="object")
        self.add_to_state_dict_registry(self.obj)  # one [N, 13] entry "object" (as pick_single_ycb.py)
        dev = self.device
        self.obj_index = torch.tensor([p[0] for p in pairs], device=dev)
        self.mode = torch.tensor([p[1] for p in pairs], device=dev)
        self.obj_mass = torch.tensor(masses, dtype=torch.float32, device=dev)
        self.obj_friction = torch.tensor(frictions, dtype=torch.float32, device=dev)
        specs = [self.object_specs[p[0]] for p in pairs]
        self.env_objects = specs
        self.obj_shape = torch.tensor([s.shape_type for s in specs], device=dev)
        self.shape_kinds = frozenset(s.shape_type for s in specs)
        self.obj_params = torch.tensor(np.stack([s.params for s in specs]), device=dev)
        self.obj_category = torch.tensor([CATEGORY_ID[s.category] for s in specs], device=dev)
        self.obj_rest_height = torch.tensor([[s.half_height_on_table(False), s.half_height_on_table(True)]
                                             for s in specs], dtype=torch.float32, device=dev)
        self.obj_can_stand = torch.tensor([s.category == "wrappable" and s.shape != "sphere" for s in specs], device=dev)
        meshes = [s for s in specs if s.shape == "mesh"]
        self.obj_tris = None
        if meshes:
            tri = [np.asarray(s.trimesh().triangles, dtype=np.float32) if s.shape == "mesh"
                   else np.zeros((1, 3, 3), np.float32) for s in specs]
            fmax = max(len(t) for t in tri)
            tri = [np.concatenate([t, np.repeat(t[:1], fmax - len(t), 0)]) for t in tri]
            self.obj_tris = torch.tensor(np.stack(tri), device=dev)
        # the closest-point formulas to evaluate: eagerly only the kinds present; compiled, every kind
        # (selected per env in the fused graph), so one graph serves every object the process builds
        self._closest_kinds = self.shape_kinds if not self._compiled else \
            frozenset({SHAPE_BOX, SHAPE_CYLINDER, SHAPE_SPHERE, SHAPE_PRISM} | ({SHAPE_MESH} if meshes else set()))

    def _after_reconfigure(self, options: dict):
        spec, robot, dev = self.hand_spec, self.agent.robot, self.device
        names = [j.name for j in robot.active_joints]
        self._qidx = torch.tensor([names.index(j) for j in spec.joint_names], device=dev)
        all_lim = robot.get_qlimits()[0].to(dev)
        lim = all_lim[self._qidx]
        self.q_lower, self.q_upper = lim[:, 0].clone(), lim[:, 1].clone()
        self.action_scale = torch.tensor(spec.action_scales(), device=dev)
        links = {l.name: l for l in robot.links}
        missing = [n for n in spec.contact_links if n not in links]
        if missing:
            raise ValueError(f"hand {spec.name!r}: contact links {missing} not in the URDF")
        self.contact_links = [links[n] for n in spec.contact_links]
        probe = []
        for l in self.contact_links:  # distance vectors start at the centre of the link's collision shapes
            shapes = l._objs[0].collision_shapes
            probe.append(np.mean([s.local_pose.p for s in shapes], axis=0) if shapes else np.zeros(3))
        self.link_probe = torch.tensor(np.array(probe), dtype=torch.float32, device=dev)
        self.sensor = HandObjectSensor(self.scene, links[HAND_FRAME_LINK], self.contact_links, self.obj)
        gains = self.agent.finger_gains
        self._finger_pd = tuple(torch.tensor([gains[j][k] for j in spec.finger_joints], device=dev)
                                for k in range(3))
        # mimic followers: drive target = multiplier * target(leader) + offset, within limits
        mimic = spec.resolved_mimic()
        self._midx = torch.tensor([names.index(f) for f, *_ in mimic], dtype=torch.long, device=dev)
        self._mimic_src = torch.tensor([6 + spec.finger_joints.index(m) for _, m, _, _ in mimic],
                                       dtype=torch.long, device=dev)
        self._mimic_k = torch.tensor([k for *_, k, _ in mimic], device=dev)
        self._mimic_o = torch.tensor([o for *_, o in mimic], device=dev)
        self._mimic_lim = all_lim[self._midx]
        self._drive_idx = torch.cat([self._qidx, self._midx])
        self.episode_length = torch.tensor([self.cfg["episode_length"][F.mode_skill(m)] for m in F.MODES], device=dev)
        self.rewards = RewardTerms(self.reward_cfg, dev, self.cfg["ablation"]["no_track_reward"])
        # per-mode flags of the registry (how each skill's episodes run), indexed by self.mode
        self._starts_on_table = F.mode_flag("starts_on_table").to(dev)
        self._wrist_where_grasped = F.mode_flag("wrist_where_grasped").to(dev)
        self._lifts = F.mode_flag("lifts").to(dev)
        self._draws_goal_pose = F.mode_flag("draws_goal_pose").to(dev)
        self._accumulates_rotation = F.mode_flag("accumulates", "rotation").to(dev)
        self._accumulates_translation = F.mode_flag("accumulates", "translation").to(dev)
        self._success_tests = [success_test(s.success) for s in R.SKILLS.values()]  # in skill order
        self.motion = F.MotionParams(dt=self.control_dt, **self.cfg["motion"])
        self._speed_cap = torch.tensor([self.cfg["motion"][R.skill_of_mode(m).speed] for m in F.MODES], device=dev)
        self._gravity = float(abs(self.sim_config.scene_config.gravity[2]))  # m/s^2 (disturbance magnitudes)
        self._world_up = torch.tensor([0.0, 0.0, 1.0], device=dev)
        rc = self.cfg["randomization"]
        wp, wr = rc["wrist_obs_noise"]
        self._obs_noise_scale = torch.tensor([wp] * 3 + [wr] * 3 + [rc["joint_obs_noise"]] * (spec.dof - 6),
                                             device=dev) * float(rc["enabled"])
        self._obs_noise_on = bool(self._obs_noise_scale.abs().sum() > 0)
        if not self.gpu_sim_enabled:  # raw PhysX joints in hand-spec order (CPU: one env)
            art = robot._objs[0]
            self._cpu_joints = [art.active_joints[i] for i in self._drive_idx.tolist()]
        self._alloc_buffers()

    def _alloc_buffers(self):
        n, dev, dof = self.num_envs, self.device, self.hand_spec.dof
        z3, z4 = torch.zeros(n, 3, device=dev), torch.zeros(n, 4, device=dev)
        ident = z4.clone()
        ident[:, 0] = 1
        rel = lambda: F.Relational(x_oh=z3, q_oh=ident, x_or=z3, q_or=ident, x_hr=z3, q_hr=ident)
        self.root_p, self.root_q = z3.clone(), ident.clone()
        self.init_rel, self.targets, self.prev_rel, self.cur_rel = rel(), rel(), rel(), rel()
        self.final_x_or, self.final_q_or = z3.clone(), ident.clone()
        self.axis = z3.clone()
        self.command = torch.zeros(n, dof, device=dev)
        self.finger_q0 = torch.zeros(n, dof - 6, device=dev)
        self.rot_acc = torch.zeros(n, device=dev)
        self.trans_acc = torch.zeros(n, device=dev)
        self.success_paid = torch.zeros(n, device=dev)  # the success reward term's sum over the episode
        self.ever_dropped = torch.zeros(n, dtype=torch.bool, device=dev)
        self.obj_z0 = torch.zeros(n, device=dev)
        self.lift = z3.clone()
        self.perturb = z3.clone()
        self.disturb = z3.clone()
        self._forces = None  # this control step's object forces per substep (set by step())
        self.obs_noise = torch.zeros(n, dof, device=dev)
        self.obj_vel_h = z3.clone()
        self.obj_angvel_h = z3.clone()
        self.hand_vel = z3.clone()
        self.hand_angvel = z3.clone()
        self._pending = torch.zeros(n, dtype=torch.bool, device=dev)
        self._one_step = torch.ones((), dtype=torch.int32, device=dev)  # elapsed_steps' increment, made once
        self._stepped = False
        self.link_force = torch.zeros(n, len(self.contact_links), device=dev)
        self._gen = torch.Generator(device=dev)
        self._gen.manual_seed(int(self._episode_seed[0]))
