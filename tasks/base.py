"""One ManiSkill task class for all UniCross skills; skills differ only by data (their mode).

The class owns the scene (table, floating hand, one object per parallel env), the per-step
measurements, the relational targets, observation, reward and ``evaluate()``. Skill classes in
``tasks/skills.py`` only choose modes and default object sets.

Per control step (``step``):
  1. the normalised action is mapped to joint targets with the current targets (formulation);
  2. physics runs 6 substeps (120 Hz sim, 20 Hz control) with the object perturbation force;
  3. ``evaluate()`` measures poses, contacts and distances once, computes the reward terms
     against the targets the action aimed at, then advances the targets (Tracked rules) and
     the accumulated rotation/translation. Observation and reward reuse this one evaluation.
"""
from __future__ import annotations

import gc
import math
from typing import Any, Dict, Optional, Sequence

import numpy as np
import sapien
import torch
from gymnasium import spaces
from gymnasium.vector.utils import batch_space
from mani_skill import logger
from mani_skill.envs.sapien_env import BaseEnv
from mani_skill.utils import common
from mani_skill.utils.structs.actor import Actor
from mani_skill.utils.structs.pose import Pose
from mani_skill.utils.structs.types import SimConfig

from unicross import formulation as F
from unicross import registry as R
from unicross.compiling import compile_enabled, maybe_compile
from unicross.config import load_config
from unicross.geometry import (
    SHAPE_BOX, SHAPE_CYLINDER, SHAPE_MESH, SHAPE_PRISM, SHAPE_SPHERE, closest_point_shapes, pose_mul, quat_apply, quat_from_axis_angle, quat_from_euler_xyz, quat_from_matrix,
    quat_angle, quat_inv, quat_mul, quat_positive, relative_pose,
)
from unicross.grasps import GraspSet, default_grasp_path
from unicross.objects import resolve_objects
from unicross.rewards import RewardTerms
from unicross.robots.hand import HAND_FRAME_LINK, HandSpec, load_hand, register_hand_agent
from unicross.sensing import HandObjectSensor
from unicross.success import get as success_test

_HEAP_FROZEN = False


def _freeze_heap_once() -> None:
    """``gc.freeze()`` once per process, after the first task is built: the objects alive then
    (imported libraries, the first scene) are never scanned by the cycle collector again.
    ManiSkill's ``_clear`` runs a full ``gc.collect()`` at every reconfiguration; with the heap
    frozen it costs ~2 µs instead of ~0.25 s (measured: reset with a scene rebuild 0.27 s -> 0.02 s
    on a CPU), which matters when CPU workers rebuild the scene every few episodes. Later scenes
    stay collectable; what the first scene holds in reference cycles is kept for the process."""
    global _HEAP_FROZEN
    if not _HEAP_FROZEN:
        gc.collect()
        gc.freeze()
        _HEAP_FROZEN = True


CATEGORY_ID = {"wrappable": 0, "elongated": 1}


def _tensors(obs):
    """The tensors of an observation (a tensor or nested dicts of tensors)."""
    if torch.is_tensor(obs):
        yield obs
    elif isinstance(obs, dict):
        for v in obs.values():
            yield from _tensors(v)


def _map_tensors(obs, fn):
    if torch.is_tensor(obs):
        return fn(obs)
    if isinstance(obs, dict):
        return {k: _map_tensors(v, fn) for k, v in obs.items()}
    return obs


def _random_quaternion(n: int, gen: torch.Generator, device) -> torch.Tensor:
    q = torch.randn(n, 4, generator=gen, device=device)
    return quat_positive(q / torch.linalg.norm(q, dim=-1, keepdim=True))


class UniCrossEnv(BaseEnv):
    """**Task Description:** a floating dexterous hand performs one of ten relational modes
    (grasp, relocate, rotate about ±x/±y/±z of the hand frame, translate along ±z of the hand
    frame) on a rigid object; all modes share observation, action and reward structure.

    **Randomizations:** object per env (from an object set), its mass U[0.002, 0.04] kg and the
    hand/object friction U[0.3, 3.0] (drawn when the scene is built), the object's table pose and
    the hand yaw (grasp), the grasp state, world wrist orientation and relocation target
    (relocate/rotate/translate), joint-observation noise U(-0.02, 0.02) rad and a decaying random
    perturbation force on the object.

    **Success Conditions:** grasp: object lifted >= 5 cm during the lift phase and never dropped;
    relocate: within 3 cm and 0.15 rad of the final pose, never dropped; rotate: accumulated
    rotation about the axis > pi/2, never dropped; translate: accumulated translation along the
    axis > 5 cm, never dropped. The episode terminates when the object drops.
    """

    SUPPORTED_OBS_MODES = ("state", "state_dict", "none")
    SUPPORTED_REWARD_MODES = ("dense", "sparse", "none")
    DEFAULT_OBJECTS = "train"
    DEFAULT_MODES: Sequence[str] = F.MODES
    _seeded_reset = True  # until the first reset says otherwise

    def __init__(self, *args, hand: str = "allegro", hand_overrides: Optional[dict] = None,
                 objects=None, object_limit: Optional[int] = None,
                 modes: Optional[Sequence[str]] = None, grasp_dataset: Optional[str] = None,
                 config: Optional[dict] = None, reward_config: Optional[dict] = None,
                 randomize: Optional[bool] = None, robot_uids=None, **kwargs):
        # ---- validate everything before any simulation starts
        self._compiled = compile_enabled()  # UNICROSS_COMPILE (unicross/compiling.py), read once per env
        self._step_math = maybe_compile(self._step_math_eager) if self._compiled else self._step_math_eager
        self._command_math = maybe_compile(self._command_math_eager) if self._compiled else self._command_math_eager
        self.hand_spec: HandSpec = load_hand(hand)
        if hand_overrides:
            import dataclasses
            self.hand_spec = dataclasses.replace(self.hand_spec, **hand_overrides)
        self.cfg = load_config("task", config)
        if randomize is not None:
            self.cfg["randomization"]["enabled"] = bool(randomize)
        self.reward_cfg = load_config("reward", reward_config)
        modes = tuple(modes or self.DEFAULT_MODES)
        bad = [m for m in modes if m not in F.MODES]
        if bad:
            raise ValueError(f"unknown mode(s) {bad}; valid modes: {list(F.MODES)}")
        objs = resolve_objects(self.DEFAULT_OBJECTS if objects is None else objects)
        if isinstance(objects, str) or objects is None:
            name = self.DEFAULT_OBJECTS if objects is None else objects
            if object_limit is not None:
                from unicross.objects import get_object_set
                objs = get_object_set(name, limit=object_limit)
        # grasp datasets name objects as listed (unscaled); the scene holds them at the hand's scale
        self.object_names = [o.name for o in objs]
        objs = [o.scaled(self.hand_spec.object_scale) for o in objs]
        self.object_specs = objs
        # valid (object, mode) pairs (the object's category is one of its skill's, see the registry),
        # interleaved round-robin over modes so that consecutive pairs (parallel envs, successive
        # rebuilds) spread over all modes
        per_mode = [[(oi, F.MODES.index(m)) for oi, o in enumerate(objs) if o.category in R.skill_of_mode(m).categories]
                    for m in modes]
        self._pairs = [lst[r] for r in range(max(map(len, per_mode), default=0)) for lst in per_mode if r < len(lst)]
        if not self._pairs:
            raise ValueError(f"no object of the given set fits modes {list(modes)} "
                             f"(rotate needs wrappable objects, translate elongated ones)")
        self.modes_used = modes
        skills = {F.mode_skill(m) for m in modes}
        self.static_skill = skills.pop() if len(skills) == 1 else None  # lets target updates skip other rules
        self.grasps: Optional[GraspSet] = None
        if any(F.mode_skill(m) != "grasp" for m in modes):
            if isinstance(grasp_dataset, GraspSet):
                path, self.grasps = "<in memory>", grasp_dataset
            else:
                path = grasp_dataset or default_grasp_path(self.hand_spec.name)
                self.grasps = GraspSet.load(path)
            if self.grasps.hand != self.hand_spec.name:
                raise ValueError(f"grasp dataset {path} is for hand {self.grasps.hand!r}, not {self.hand_spec.name!r}")
            have = {n for n, c in self.grasps.counts().items() if c > 0}
            needed = {self.object_names[oi] for oi, mi in self._pairs if F.mode_skill(F.MODES[mi]) != "grasp"}
            missing = sorted(needed - have)
            if missing and len(missing) == len(needed):
                raise ValueError(f"grasp dataset {path} has no grasps for the {len(missing)} object(s) of "
                                 f"this set, e.g. {missing[:3]}; build them with `unicross grasps --objects <set>`")
            if missing:  # a few objects the synthesiser could not grasp: they only serve the grasp mode
                logger.warning(f"{len(missing)} object(s) have no grasp in {path} and are left out of the "
                               f"in-hand modes, e.g. {missing[:3]}")
                self._pairs = [(oi, mi) for oi, mi in self._pairs
                               if F.mode_skill(F.MODES[mi]) == "grasp" or self.object_names[oi] in have]
        register_hand_agent(self.hand_spec)
        super().__init__(*args, robot_uids=self.hand_spec.uid, **kwargs)
        n = self.hand_spec.dof
        self.single_action_space = spaces.Box(-1.0, 1.0, (n,), dtype=np.float32)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        _freeze_heap_once()

    # ------------------------------------------------------------------ configuration
    @property
    def _default_sim_config(self):
        s = self.cfg["sim"]
        return SimConfig(sim_freq=s["sim_freq"], control_freq=s["control_freq"],
                         scene_config=dict(contact_offset=s["contact_offset"],
                                           solver_position_iterations=s["solver_position_iterations"],
                                           solver_velocity_iterations=s["solver_velocity_iterations"]))

    @property
    def control_dt(self) -> float:
        return 1.0 / self._control_freq

    def _load_agent(self, options: dict):
        super()._load_agent(options, sapien.Pose(p=[0.0, 0.0, 1.0]))

    # ------------------------------------------------------------------ scene
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
            b.initial_pose = sapien.Pose(p=[0.3 * i, 0, 0.5])
            actors.append(b.build(name=f"object-{i}"))
            for link in self.agent.robot.links:  # friction applies to hand and object alike
                for shape in link._objs[i].collision_shapes:
                    shape.physical_material = mat
        self.obj = Actor.merge(actors, name="object")
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
        self.ever_dropped = torch.zeros(n, dtype=torch.bool, device=dev)
        self.obj_z0 = torch.zeros(n, device=dev)
        self.lift = z3.clone()
        self.perturb = z3.clone()
        self.disturb = z3.clone()
        self.obs_noise = torch.zeros(n, dof, device=dev)
        self.obj_vel_h = z3.clone()
        self.obj_angvel_h = z3.clone()
        self.hand_vel = z3.clone()
        self.hand_angvel = z3.clone()
        self._pending = torch.zeros(n, dtype=torch.bool, device=dev)
        self._stepped = False
        self.link_force = torch.zeros(n, len(self.contact_links), device=dev)
        self._gen = torch.Generator(device=dev)
        self._gen.manual_seed(int(self._episode_seed[0]))

    # ------------------------------------------------------------------ episode start
    def _initialize_episode(self, env_idx: torch.Tensor, options: dict):
        dev, spec = self.device, self.hand_spec
        b = len(env_idx)
        # a seeded reset replays its episode exactly; an unseeded one continues the task generator,
        # so every episode draws a new start, perturbation and noise sequence
        if self._seeded_reset and options.get("seed_generator", True):
            self._gen.manual_seed(int(self._episode_seed[0]))
        g = self._gen
        skill = F.MODE_SKILL_ID.to(dev)[self.mode[env_idx]]
        hand_p, hand_q, obj_p, obj_q, fq = self._grasp_start(env_idx)
        ft, mq = fq, None  # finger targets; recorded coupled-joint positions of a restored grasp
        if self.grasps is not None:
            hand_p, hand_q, obj_p, obj_q, fq, ft, mq = self._in_hand_start(env_idx, skill, hand_p, hand_q,
                                                                          obj_p, obj_q, fq)
        # ---- apply to the simulation
        qpos = torch.zeros(b, spec.dof, device=dev)
        qpos[:, 6:] = fq
        art_q = self.articulation_qpos(qpos)
        if mq is not None:  # coupled joints where they were, not where the coupling would put them
            art_q[:, self._midx] = torch.where(mq[0], art_q[:, self._midx], mq[1])
        self.agent.robot.set_qpos(art_q)
        self.agent.robot.set_qvel(torch.zeros_like(art_q))
        self.agent.robot.set_root_pose(Pose.create_from_pq(hand_p, hand_q))
        self.obj.set_pose(Pose.create_from_pq(obj_p, obj_q))
        # ---- task state
        self.reset_task_state(env_idx, hand_p, hand_q, obj_p, obj_q, fq, skill == F.skill_id("relocate"))
        cmd = torch.zeros(b, spec.dof, device=dev)
        cmd[:, 6:] = ft
        self.command[env_idx] = cmd
        self.ever_dropped[env_idx] = False
        self.perturb[env_idx] = 0
        self.link_force[env_idx] = 0
        dmax = self.cfg["disturbance"]["max_scale"]
        if dmax > 0:  # constant force: random direction, magnitude U[0, dmax * m * g]
            direction = torch.nn.functional.normalize(torch.randn(b, 3, generator=g, device=dev), dim=-1)
            mag = torch.rand(b, generator=g, device=dev) * dmax * self.obj_mass[env_idx] * self._gravity
            self.disturb[env_idx] = direction * mag[:, None]
        self.obs_noise[env_idx] = self._draw_obs_noise(b)
        for t in (self.obj_vel_h, self.obj_angvel_h, self.hand_vel, self.hand_angvel):
            t[env_idx] = 0

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

    def _in_hand_start(self, env_idx, skill, hand_p, hand_q, obj_p, obj_q, fq):
        """In-hand start (relocate / rotate / translate; grasp envs keep the given start): a grasp
        state from the dataset, with the wrist where it was grasped for relocate and at
        ``in_hand_start_height`` in a random (or palm-up) orientation for rotate and translate.
        Returns hand and object poses, finger positions and targets, and the recorded coupled-joint
        positions (``(is_grasp, mimic_qpos)`` or None)."""
        dev, g, b = self.device, self._gen, len(env_idx)
        gs = self.grasps.sample(self.obj_index[env_idx], self.object_names, g)
        random_q = _random_quaternion(b, g, dev)
        if self.cfg["in_hand_orientation"] == "palm_up":  # palm normal (+x_h) up, random yaw
            psi = torch.rand(b, generator=g, device=dev) * 2 * math.pi
            xu = torch.tensor([0.0, 0.0, 1.0], device=dev).expand(b, 3)
            zu = torch.stack([torch.cos(psi), torch.sin(psi), torch.zeros_like(psi)], -1)
            random_q = quat_from_matrix(torch.stack([xu, torch.cross(zu, xu, dim=-1), zu], dim=-1))
        is_reloc = (skill == F.skill_id("relocate"))[:, None]
        world_q = torch.where(is_reloc, gs["wrist_pose"][:, 3:], random_q)
        inhand_p = torch.tensor([0.0, 0.0, self.cfg["in_hand_start_height"]], device=dev).expand(b, 3)
        world_p = torch.where(is_reloc, gs["wrist_pose"][:, :3], inhand_p)
        op, oq = pose_mul(world_p, world_q, gs["object_pose_hand"][:, :3], gs["object_pose_hand"][:, 3:])
        is_grasp = (skill == F.skill_id("grasp"))[:, None]
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
        self.obj_z0[env_idx] = obj_p[:, 2]
        self.lift[env_idx] = 0
        self._pending[env_idx] = True

    def _draw_obs_noise(self, n: int) -> torch.Tensor:
        """U(-1, 1) x per-joint noise scale: ``joint_obs_noise`` (rad) on finger joints,
        ``wrist_obs_noise`` (m, rad) on the virtual wrist joints."""
        u = torch.rand(n, self.hand_spec.dof, generator=self._gen, device=self.device) * 2 - 1
        return u * self._obs_noise_scale

    def reset(self, seed=None, options=None):
        self._seeded_reset = seed is not None
        if seed is not None and self.scene is not None and not self.gpu_sim_enabled and \
                (self.cfg["randomization"]["enabled"] or len(self._pairs) > self.num_envs):
            # a seeded reset replays its episode: the object and its mass and friction (drawn when
            # the scene is built) must come from the seed too, not from an earlier build or from
            # wherever the rebuild cursor stands (CPU: a rebuild costs ~0.02 s)
            options = dict(options or {})
            options.setdefault("reconfigure", True)
        obs, info = super().reset(seed=seed, options=options)
        # finger drive targets of a restored grasp (the controller reset set them to qpos)
        self._apply_command()
        return obs, info

    def _follow(self, q: torch.Tensor) -> torch.Tensor:
        """Mimic-follower values for actuated joint values ``q`` [B, dof] (spec order)."""
        lim = self._mimic_lim
        return torch.clamp(q[:, self._mimic_src] * self._mimic_k + self._mimic_o, lim[:, 0], lim[:, 1])

    def articulation_qpos(self, qpos: torch.Tensor) -> torch.Tensor:
        """Articulation-ordered joint positions from actuated ones [B, dof] (followers derived)."""
        art_q = torch.zeros(qpos.shape[0], self.agent.robot.max_dof, device=qpos.device)
        art_q[:, self._qidx] = qpos
        art_q[:, self._midx] = self._follow(qpos)
        return art_q

    def _drive_targets(self) -> torch.Tensor:
        """PD targets of all driven joints: the current command and its mimic followers."""
        return torch.cat([self.command, self._follow(self.command)], dim=-1)

    def _apply_command(self, targets: Optional[torch.Tensor] = None):
        """Write the PD targets of all driven joints (``_drive_targets()`` unless given): one write on
        GPU, raw joints on CPU."""
        targets = self._drive_targets() if targets is None else targets
        if self.gpu_sim_enabled:
            self.agent.robot.set_joint_drive_targets(targets, joint_indices=self._drive_idx)
            self.scene.px.gpu_apply_articulation_target_position()
        else:
            for joint, target in zip(self._cpu_joints, targets[0].tolist()):
                joint.set_drive_target(target)

    # ------------------------------------------------------------------ stepping
    def step(self, action):
        a = common.to_tensor(action, device=self.device)
        if a.ndim == 1:
            a = a[None]
        if a.shape != (self.num_envs, self.hand_spec.dof):
            raise ValueError(f"action must have shape ({self.num_envs}, {self.hand_spec.dof}), got {tuple(a.shape)}")
        a = a.float()
        if not torch.isfinite(a).all():
            raise ValueError("action contains NaN or inf")
        self._apply_command(self._command_math(a, self.elapsed_steps))
        self._pending = torch.ones_like(self._pending)  # evaluate() advances targets once per step
        self._stepped = True
        obs, reward, _, _, info = super().step(None)  # drive targets are set; ManiSkill runs the substeps
        terminated = info["fail"].clone() if self.cfg["terminate_on_drop"] else torch.zeros_like(info["fail"])
        truncated = self.elapsed_steps >= self.episode_length[self.mode]
        # a non-finite observation or reward (a physics blow-up) never reaches a learner: it is
        # zeroed, reported as info["nonfinite"], and the env's episode ends (truncated) to be reset
        bad = ~torch.isfinite(reward) if torch.is_tensor(reward) else torch.zeros_like(truncated)
        for x in _tensors(obs):
            bad = bad | ~torch.isfinite(x.reshape(self.num_envs, -1)).all(-1)
        info["nonfinite"] = bad
        if bool(bad.any()):
            reward = torch.where(bad, torch.zeros_like(reward), reward)
            obs = _map_tensors(obs, lambda x: torch.nan_to_num(x, nan=0.0, posinf=0.0, neginf=0.0))
            truncated = truncated | bad
        return obs, reward, terminated, truncated, info

    def _command_math_eager(self, a: torch.Tensor, elapsed_steps: torch.Tensor) -> torch.Tensor:
        """The normalised action [-1, 1] -> this step's joint command (``self.command``; the wrist
        reference is the target hand pose, raised during the grasp lift) -> the drive targets of all
        driven joints. Pure tensor math on the task state, compiled like ``_step_math_eager``."""
        a = a.clamp(-1.0, 1.0)
        ref = F.wrist_reference(self.targets)
        ref[:, :3] = ref[:, :3] + self._advance_lift(elapsed_steps)
        self.command = F.map_action(a, self.command, ref, self.action_scale, self.q_lower, self.q_upper,
                                    wrist_from_target=not self.cfg["ablation"]["no_target_action"])
        return self._drive_targets()

    def _advance_lift(self, elapsed_steps: torch.Tensor) -> torch.Tensor:
        """Grasp lift phase: the wrist reference (the Free current wrist pose) rises by
        ``lift_speed * dt`` per step after ``lift_after`` steps; ``self.lift`` accumulates the rise,
        which the Fixed object target follows. Returns this step's increment (root frame)."""
        lift_after = self.cfg["grasp"]["lift_after"]
        if lift_after is None or self.static_skill not in (None, "grasp"):
            return torch.zeros_like(self.lift)
        lifting = (self.mode == F.mode_index("grasp")) & (elapsed_steps >= lift_after)
        up_root = quat_apply(quat_inv(self.root_q), self._world_up.expand_as(self.lift))
        step = lifting[:, None].float() * up_root * self.cfg["grasp"]["lift_speed"] * self.control_dt
        self.lift = self.lift + step
        return step

    def _before_control_step(self):
        """This control step's external object forces for all substeps at once: the decaying random
        perturbation (domain randomisation) plus the constant disturbance of the robustness protocol
        (for grasp only while lifting)."""
        rc = self.cfg["randomization"]
        k, n = self._sim_steps_per_control, self.num_envs
        self._substep = 0
        self._forces = None
        forces = None
        if rc["enabled"] and rc["perturb_scale"] > 0:
            new = rc["perturb_scale"] * self.obj_mass[:, None] * torch.randn(k, n, 3, generator=self._gen, device=self.device)
            redraw = torch.rand(k, n, 1, generator=self._gen, device=self.device) < rc["perturb_prob"]
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
                active = ((self.mode != 0) | (self.elapsed_steps >= lift_after))[:, None]
            disturb = torch.where(active, self.disturb, torch.zeros_like(self.disturb))
            forces = disturb.expand(k, n, 3) if forces is None else forces + disturb
        if forces is not None:
            self._forces = forces if self.gpu_sim_enabled else list(forces[:, 0].numpy())

    def _before_simulation_step(self):
        if self._forces is not None:
            self.sensor.apply_object_force(self._forces[self._substep])
        self._substep += 1

    # ------------------------------------------------------------------ evaluation (single source of truth)
    def _read(self):
        """The step's reads from the simulator: tracked body poses, the links' contact forces with the
        object (only after a physics step; otherwise the last ones are kept), joint positions and
        velocities. Everything after the reads is tensor math (``_step_math``)."""
        pos, quat = self.sensor.poses()
        if self._stepped:
            self.link_force = torch.linalg.norm(self.sensor.contact_forces(), dim=-1)
            self._stepped = False
        robot = self.agent.robot
        return pos, quat, self.link_force, robot.get_qpos(), robot.get_qvel()

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

    def evaluate(self) -> dict:
        pend = self._pending
        info = self._step_math(*self._read(), self.elapsed_steps)
        if self._obs_noise_on:  # random draws stay outside the compiled math
            self.obs_noise = torch.where(pend[:, None], self._draw_obs_noise(self.num_envs), self.obs_noise)
        return info

    def _step_math_eager(self, pos, quat, force, qpos, qvel, elapsed_steps) -> dict:
        """Everything ``evaluate()`` computes from the step's reads: distances, relational poses,
        velocities, accumulated motion, drop, success, reward terms, the next targets and the
        observation parts. Pure tensor math on the task's state (no reads, no random draws), so it
        compiles to one graph (``UNICROSS_COMPILE``)."""
        m = self._measure(pos, quat, force, qpos, qvel)
        cur = F.relational_poses(self.root_p, self.root_q, m["hand_p"], m["hand_q"], m["obj_p"], m["obj_q"])
        pend = self._pending
        skill = F.MODE_SKILL_ID.to(self.device)[self.mode]
        axis_prev = self.axis
        goal_err_prev, goal_err = self._goal_errors(cur)
        self._advance_motion(cur, pend, skill, axis_prev)
        # reward compares against the targets the last action aimed at; Free targets = current
        reward_targets = F.with_free_as_current(self.mode, self.targets, cur)
        drop = self._drop(m["link_distance"], skill, elapsed_steps)
        self._advance_targets(cur, pend)
        success, contact, lifted, pos_err, rot_err = self._success(m, skill)
        force_c = m["force"].clamp(max=self.cfg["force_clip"])
        # motion along the axis the last action was asked to follow
        is_rot = skill == F.skill_id("rotate")
        speed = torch.where(is_rot, (self.obj_angvel_h * axis_prev).sum(-1), (self.obj_vel_h * axis_prev).sum(-1))
        meas = dict(link_distance=m["link_distance"], contact=contact, force_clipped=force_c, speed_along_axis=speed,
                    speed_cap=self._speed_cap[self.mode], relational=cur, reward_targets=reward_targets,
                    finger_qpos=m["qpos"][:, 6:], finger_qpos0=self.finger_q0, hand_lin_vel=self.hand_vel,
                    hand_ang_vel=self.hand_angvel, finger_torque=m["finger_torque"], drop=drop, success=success,
                    goal_err_prev=goal_err_prev, goal_err=goal_err)
        terms = self.rewards(self.mode, meas)
        self._observation_parts(m, cur, contact, force_c)
        info = dict(success=success, fail=drop, drop=drop, ever_dropped=self.ever_dropped.clone(),
                    lifted=lifted, relocate_pos_err=pos_err, relocate_rot_err=rot_err,
                    rotation=self.rot_acc.clone(), translation=self.trans_acc.clone(),
                    num_contacts=contact.sum(-1), mode=self.mode.clone())
        info.update({f"reward_{k}": v for k, v in terms.items()})
        return info

    def _goal_errors(self, cur: F.Relational):
        """The object's position (m) and angle (rad) error to its final root-frame pose before and
        after the step ([N, 2] each; ``r_progress``)."""
        prev = self.prev_rel
        before = torch.stack([torch.linalg.norm(prev.x_or - self.final_x_or, dim=-1),
                              quat_angle(prev.q_or, self.final_q_or)], dim=-1)
        after = torch.stack([torch.linalg.norm(cur.x_or - self.final_x_or, dim=-1),
                             quat_angle(cur.q_or, self.final_q_or)], dim=-1)
        return before, after

    def _advance_motion(self, cur: F.Relational, pend, skill, axis_prev):
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
        is_rot = skill == F.skill_id("rotate")
        is_trans = skill == F.skill_id("translate")
        self.rot_acc = self.rot_acc + (pend & is_rot).float() * (w * axis_prev).sum(-1) * dt
        self.trans_acc = self.trans_acc + (pend & is_trans).float() * (v * axis_prev).sum(-1) * dt

    def _drop(self, dist, skill, elapsed_steps):
        """Drop (DESIGN §6): every link farther than ``drop_threshold`` from the object; a grasp can
        only drop what it lifted (before the lift phase the object rests on the table)."""
        drop = dist.min(dim=-1).values > self.cfg["drop_threshold"]
        lift_after = self.cfg["grasp"]["lift_after"]
        grasp_lifting = (elapsed_steps >= lift_after) if lift_after is not None else torch.zeros_like(drop)
        drop = drop & ((skill != F.skill_id("grasp")) | grasp_lifting)
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

    # ------------------------------------------------------------------ observation
    def _get_obs_agent(self):
        return dict()

    def _get_obs_extra(self, info: dict):
        p = self._obs_parts
        hand = torch.cat([p["qpos"] + self.obs_noise, self.command], dim=-1)
        return dict(hand=hand, object=dict(contact=p["contact"], force=p["force"], distance=p["distance"]), goal=p["goal"])

    # ------------------------------------------------------------------ reward
    def compute_dense_reward(self, obs: Any, action: torch.Tensor, info: dict):
        return sum(info[f"reward_{k}"] for k in self.rewards.names)

    def compute_normalized_dense_reward(self, obs: Any, action: torch.Tensor, info: dict):
        return self.compute_dense_reward(obs, action, info)

    # ------------------------------------------------------------------ state (sim + task)
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
