"""One ManiSkill task class for all UniCross skills; skills differ only by data (their mode).

The class owns the episode loop: validation before any simulation, episode start, ``step`` (action
-> drive targets -> physics with the object forces -> ``evaluate()``), observation and reward.
Its parts live next to it, one file each: the scene and per-env constants (``tasks/scene.py``),
the start-state samplers and ``reset_task_state`` (``tasks/starts.py``), the per-step tensor math
that ``evaluate()`` runs (``tasks/step_math.py``) and the task state's save/restore
(``tasks/state.py``). Skill classes in ``tasks/skills.py`` only choose modes and default object sets;
what a skill is lives in ``unicross/registry.py``.

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
from typing import Any, Optional, Sequence

import numpy as np
import torch
from gymnasium import spaces
from gymnasium.vector.utils import batch_space
from mani_skill import logger
from mani_skill.envs.sapien_env import BaseEnv
from mani_skill.utils import common
from mani_skill.utils.structs.pose import Pose

from unicross import formulation as F
from unicross import registry as R
from unicross.compiling import compile_enabled, compile_method
from unicross.config import freeze, load_config
from unicross.grasps import GraspSet, default_grasp_path
from unicross.objects import resolve_objects
from unicross.observations import obs_layout, observe, resolve as resolve_observation, unflatten
from unicross.robots.hand import HandSpec, load_hand, register_hand_agent
from unicross.tasks.scene import TaskScene
from unicross.tasks.starts import EpisodeStarts
from unicross.tasks.state import TaskStateIO
from unicross.tasks.step_math import StepMath

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


def pair_walk(per_mode: Sequence[Sequence[int]], mode_ids: Sequence[int], order: str) -> list[tuple[int, int]]:
    """The (object, mode) pairs in the order a task's envs take them: from a cursor that starts at a
    seeded random place and moves on by the number of envs at every scene rebuild (``TaskScene``).
    ``per_mode[k]``: the indices of the objects valid for mode ``mode_ids[k]``.

    A CPU worker (one env) walks a few hundred consecutive pairs in a run, so the order decides what
    it trains on. ``sequential`` (the default, what every shipped checkpoint was trained with): objects
    in the set's order, modes round-robin until each mode's list ends; a window then holds one shape
    group (the sets list boxes before cylinders), and after the in-hand modes' shorter lists end only
    grasp and relocate. ``balanced``: round ``r`` holds one pair of every mode, the mode's object at
    place ``r`` of a fixed shuffle of its objects (a shorter list is cycled), so every window of
    consecutive pairs has each mode equally often and a spread of its objects over the set's
    categories and shapes (measured in a DAgger fine-tuning stage, two seeds: README "Pair walk").
    """
    lists = [list(lst) for lst in per_mode]
    if order == "sequential":
        return [(lst[r], mi) for r in range(max(map(len, lists), default=0)) for lst, mi in zip(lists, mode_ids)
                if r < len(lst)]
    if order != "balanced":
        raise ValueError(f"pair_order must be 'balanced' or 'sequential', not {order!r}")
    rng = np.random.RandomState(0)  # fixed: the same walk in every process; the cursor's start is seeded
    shuffled = [[lst[i] for i in rng.permutation(len(lst))] for lst in lists]
    return [(lst[r % len(lst)], mi) for r in range(max(map(len, lists), default=0))
            for lst, mi in zip(shuffled, mode_ids) if lst]


def _map_tensors(obs, fn):
    if torch.is_tensor(obs):
        return fn(obs)
    if isinstance(obs, dict):
        return {k: _map_tensors(v, fn) for k, v in obs.items()}
    return obs


class UniCrossEnv(TaskScene, EpisodeStarts, StepMath, TaskStateIO, BaseEnv):
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
                 randomize: Optional[bool] = None, compile_math: Optional[bool] = None, robot_uids=None,
                 **kwargs):
        # compile_math: compile the step math (None: the UNICROSS_COMPILE switch). False for an env that
        # never steps (the SAPIEN renderer's replay), which would otherwise compile it at its first reset.
        # ---- validate everything before any simulation starts
        backend = str(kwargs.get("sim_backend", "auto")).split(":")[0]
        gpu = backend in ("gpu", "cuda", "physx_cuda") or (backend == "auto" and int(kwargs.get("num_envs", 1)) > 1)
        if gpu and (kwargs.get("reconfiguration_freq") or 0) > 0:
            raise ValueError("reconfiguration_freq must be 0 on the GPU backend (ManiSkill cannot rebuild the "
                             "scene at a partial reset; the objects spread over the sub-scenes instead)")
        if kwargs.get("control_mode") not in (None, "pd_joint_pos"):
            raise ValueError(f"UniCross tasks have one control mode, 'pd_joint_pos' (normalised residual joint "
                             f"targets, see formulation.map_action), not {kwargs['control_mode']!r}: pass "
                             f"control_mode='pd_joint_pos' (ManiSkill's PPO baseline: --control_mode pd_joint_pos)")
        self._compiled = compile_enabled() if compile_math is None else bool(compile_math)  # read once per env
        self._step_math = compile_method(self, self._step_math_eager, cpu=not gpu, enabled=self._compiled)
        self._command_math = compile_method(self, self._command_math_eager, cpu=not gpu, enabled=self._compiled)
        self.hand_spec: HandSpec = load_hand(hand)
        if hand_overrides:
            import dataclasses
            self.hand_spec = dataclasses.replace(self.hand_spec, **hand_overrides)
        self.cfg = load_config("task", config)
        if randomize is not None:
            self.cfg["randomization"]["enabled"] = bool(randomize)
        self.cfg = freeze(self.cfg)  # fixed from here: the compiled step math reads it once
        self.reward_cfg = freeze(load_config("reward", reward_config))
        self._obs_terms = resolve_observation(self.cfg["observation"])
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
        # valid (object, mode) pairs: the object's category is one of its skill's (see the registry);
        # the order envs walk them in is ``pair_walk`` (task.yaml: pair_order)
        per_mode = [[oi for oi, o in enumerate(objs) if o.category in R.skill_of_mode(m).categories] for m in modes]
        if not any(per_mode):
            raise ValueError(f"no object of the given set fits modes {list(modes)} "
                             f"(rotate needs wrappable objects, translate elongated ones)")
        self.modes_used = modes
        skills = {F.mode_skill(m) for m in modes}
        self.static_skill = skills.pop() if len(skills) == 1 else None  # lets target updates skip other rules
        self.grasps: Optional[GraspSet] = None
        missing: list[str] = []  # objects of in-hand modes without a grasp: they only serve the grasp mode
        in_hand = lambda mode: not R.skill_of_mode(mode).starts_on_table  # noqa: E731  (starts from a grasp)
        if any(in_hand(m) for m in modes):
            if isinstance(grasp_dataset, GraspSet):
                path, self.grasps = "<in memory>", grasp_dataset
            else:
                path = grasp_dataset or default_grasp_path(self.hand_spec.name)
                self.grasps = GraspSet.load(path)
            if self.grasps.hand != self.hand_spec.name:
                raise ValueError(f"grasp dataset {path} is for hand {self.grasps.hand!r}, not {self.hand_spec.name!r}")
            have = {n for n, c in self.grasps.counts().items() if c > 0}
            needed = {self.object_names[oi] for m, lst in zip(modes, per_mode) if in_hand(m) for oi in lst}
            missing = sorted(needed - have)
            if missing and len(missing) == len(needed):
                raise ValueError(f"grasp dataset {path} has no grasps for the {len(missing)} object(s) of "
                                 f"this set, e.g. {missing[:3]}; build them with `unicross grasps --objects <set>`")
            if missing:
                logger.warning(f"{len(missing)} object(s) have no grasp in {path} and are left out of the "
                               f"in-hand modes, e.g. {missing[:3]}")
        self._pairs = pair_walk(per_mode, [F.MODES.index(m) for m in modes], self.cfg["pair_order"])
        if missing:
            gone = set(missing)
            self._pairs = [(oi, mi) for oi, mi in self._pairs
                           if not in_hand(F.MODES[mi]) or self.object_names[oi] not in gone]
        register_hand_agent(self.hand_spec)
        super().__init__(*args, robot_uids=self.hand_spec.uid, **kwargs)
        n = self.hand_spec.dof
        self.single_action_space = spaces.Box(-1.0, 1.0, (n,), dtype=np.float32)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        # the thin step (``step``): state observations and a dense reward, as training uses
        self._thin_step = self._obs_mode in ("state", "state_dict") and \
            self._reward_mode in ("dense", "normalized_dense")
        self._obs_layout = obs_layout(observe(self, self._obs_terms))  # ManiSkill's __init__ has reset
        _freeze_heap_once()


    # ------------------------------------------------------------------ episode start
    def _initialize_episode(self, env_idx: torch.Tensor, options: dict):
        dev, spec = self.device, self.hand_spec
        b = len(env_idx)
        # a seeded reset replays its episode exactly; an unseeded one continues the task generator,
        # so every episode draws a new start, perturbation and noise sequence
        if self._seeded_reset and options.get("seed_generator", True):
            self._gen.manual_seed(int(self._episode_seed[0]))
        g = self._gen
        hand_p, hand_q, obj_p, obj_q, fq = self._grasp_start(env_idx)
        ft, mq = fq, None  # finger targets; recorded coupled-joint positions of a restored grasp
        if self.grasps is not None:
            hand_p, hand_q, obj_p, obj_q, fq, ft, mq = self._in_hand_start(env_idx, hand_p, hand_q, obj_p, obj_q, fq)
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
        self.reset_task_state(env_idx, hand_p, hand_q, obj_p, obj_q, fq, self._draws_goal_pose[self.mode[env_idx]])
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
        """Write the PD targets of all driven joints of every env (``_drive_targets()`` unless given,
        [N, driven joints]): one write on GPU, raw joints on CPU. On the GPU the write goes to PhysX's
        target buffer directly: ManiSkill's ``set_joint_drive_targets`` keeps only the rows of the envs
        being reset while a reset runs, which full-batch targets (a partial reset to recorded states
        through ``set_state_dict``) would not fit."""
        targets = self._drive_targets() if targets is None else targets
        if self.gpu_sim_enabled:
            gx, gy = self.agent.robot.get_joint_target_indices(self._drive_idx)
            self.scene.px.cuda_articulation_target_qpos.torch()[gx, gy] = targets
            self.scene.px.gpu_apply_articulation_target_position()
        else:
            for joint, target in zip(self._cpu_joints, targets[0].tolist()):
                joint.set_drive_target(target)

    # ------------------------------------------------------------------ stepping
    def step(self, action):
        """One control step. With the ``state`` or ``state_dict`` observation and a dense reward (what
        training and evaluation use) the step is thin: ManiSkill's substeps and hooks (``_step_action``) and ``get_info()`` run as
        in ``BaseEnv.step``, and the compiled step math already holds the flat observation, the
        reward sum, termination and the non-finite check (``StepMath._step_outputs``), so ManiSkill's
        generic observation/reward assembly and flattening are skipped (equal results, tested; a
        ``state_dict`` observation is views into the flat one).
        Other observation and reward modes go through ``BaseEnv.step``."""
        a = action if isinstance(action, torch.Tensor) and action.device == self.device else \
            common.to_tensor(action, device=self.device)
        if a.ndim == 1:
            a = a[None]
        if a.shape != (self.num_envs, self.hand_spec.dof):
            raise ValueError(f"action must have shape ({self.num_envs}, {self.hand_spec.dof}), got {tuple(a.shape)}")
        a = a.float()
        # NaN or inf anywhere makes the sum non-finite; on the CPU a Python sum of the values costs about half
        # of a float64 tensor sum (~7 against ~14-16 us inside the step loop, after the physics cooled the caches)
        total = float(a.sum(dtype=torch.float64)) if self.gpu_sim_enabled else sum(a.reshape(-1).tolist())
        if not math.isfinite(total):
            raise ValueError("action contains NaN or inf")
        targets, forces = self._command_math(a, self.elapsed_steps, *self._draw_perturbation())
        self._apply_command(targets)
        self._forces = None if forces is None else forces if self.gpu_sim_enabled else list(forces[:, 0].numpy())
        self._pending = torch.ones_like(self._pending)  # evaluate() advances targets once per step
        self._stepped = True
        if self._thin_step:
            self._step_action(None)  # drive targets are set; ManiSkill runs the substeps and hooks
            self._elapsed_steps.add_(self._one_step)  # a made tensor: ~3 us less than wrapping the Python 1
            info = self.get_info()
            obs, reward, terminated, truncated = self._step_out
            if self._obs_mode == "state_dict":
                obs = dict(agent=self._get_obs_agent(), extra=unflatten(obs, self._obs_layout))
            self._last_obs = obs
            return obs, reward, terminated, truncated, info
        obs, reward, _, _, info = super().step(None)
        _, _, terminated, truncated = self._step_out
        if bool(info["nonfinite"].any()):  # zeroed (a physics blow-up never reaches a learner)
            bad = info["nonfinite"]
            reward = torch.where(bad, torch.zeros_like(reward), reward) if torch.is_tensor(reward) else reward
            obs = _map_tensors(obs, lambda x: torch.nan_to_num(x, nan=0.0, posinf=0.0, neginf=0.0))
        return obs, reward, terminated, truncated, info

    def _draw_perturbation(self):
        """The random draws of this control step's object perturbation (``StepMath._object_forces``
        turns them into forces inside the compiled command math): standard normals [k, N, 3] and
        uniforms [k, N, 1], or ``(None, None)`` when the perturbation is off."""
        rc = self.cfg["randomization"]
        if not (rc["enabled"] and rc["perturb_scale"] > 0):
            return None, None
        k, n = self._sim_steps_per_control, self.num_envs
        return (torch.randn(k, n, 3, generator=self._gen, device=self.device),
                torch.rand(k, n, 1, generator=self._gen, device=self.device))

    def _before_control_step(self):
        """The substeps of this control step apply ``self._forces`` (set by ``step`` from the
        command math) one by one."""
        self._substep = 0

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


    def evaluate(self) -> dict:
        # random draws stay outside the compiled math; the noise is drawn at every evaluation
        noise = self._draw_obs_noise(self.num_envs) if self._obs_noise_on else self.obs_noise
        info, self._step_out = self._step_math(*self._read(), self.elapsed_steps, noise)
        return info


    # ------------------------------------------------------------------ observation
    def _get_obs_agent(self):
        return dict()

    def _get_obs_extra(self, info: dict):
        return observe(self, self._obs_terms)

    # ------------------------------------------------------------------ reward
    def compute_dense_reward(self, obs: Any, action: torch.Tensor, info: dict):
        return self.dense_reward(info)

    def compute_normalized_dense_reward(self, obs: Any, action: torch.Tensor, info: dict):
        return self.compute_dense_reward(obs, action, info)


