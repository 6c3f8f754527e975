"""The paper's evaluation protocols (§4.2, 4.5) as functions over a policy and an object set.

Each protocol resets a task per (object, trial[, axis]) with a seed derived from ``seed``, rolls
the policy out for the protocol's number of steps, records the trajectory (object pose in the
hand frame and in the world, drop flags) and scores it with :mod:`unicross.metrics`:

  grasp      25 table poses per object, 75 steps, the wrist rises after step 50;
             success = lifted (>= 5 cm) and never dropped
  relocate   25 grasp states per object, final pose offsets x, y U[-0.1, 0.1] m, z U[0.2, 0.4] m,
             roll/pitch/yaw U[-0.75, 0.75] rad, 75 steps; PE (cm) / AE (rad) over the last 25 steps
             of non-dropped trials; success = final errors within 3 cm and 0.15 rad, never dropped
  rotate     25 grasp states x 6 axes, random world wrist orientation, 400 steps;
             success = accumulated rotation about the axis exceeded pi/2, never dropped;
             Rot. = mean accumulated rotation (rad) of non-dropped trials
  translate  25 grasp states x 2 directions, 50 steps; success = displacement exceeded 5 cm,
             never dropped; Trans. = mean displacement (cm) of non-dropped trials
  --disturb  adds a constant force of random direction and magnitude U[0, 10 m g] on the object
             for the whole episode (grasp: while lifting)

The protocol settings (trials per object, disturbance scale, PE/AE window) are in
``configs/eval.yaml``; steps, axes and object categories per protocol in :mod:`unicross.registry`.

Policies: a checkpoint path, ``zero`` (no action), ``random``, ``scripted-relocate`` (the
paper's naive relocation baseline) or ``reference[@FRACTION]`` (the mode's physical reference,
where one is known: translate z+ opens the fingers, z- curls the index finger) or ``gait:LOG`` / ``gait:<hand>/<mode>`` (the best finger
gait of a ``benchmarks/gait_search.py`` log or a shipped one, run until the mode's threshold is
passed, then holding: :mod:`unicross.gaits`). Same seed and policy give identical results.
"""
from __future__ import annotations

import gzip
import json
import logging
from pathlib import Path
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import gymnasium as gym
import torch
from tqdm import tqdm

from unicross import formulation as F
from unicross import metrics as M
from unicross import registry as R
from unicross.seeding import trial_seed
from unicross.config import load_config
from unicross.geometry import pose_inv, pose_mul, quat_to_euler_xyz
from unicross.objects import ObjectSpec

logger = logging.getLogger(__name__)

EVAL_CFG = load_config("eval")  # protocol settings (configs/eval.yaml)
PROTOCOLS = R.SKILL_NAMES  # one protocol per skill (its steps, axes, env and objects: unicross.registry)

PolicyFn = Callable[[dict, object], torch.Tensor]


def _axes(protocol: str) -> List[Optional[str]]:
    """The axes a protocol runs (``[None]`` for a skill without axes)."""
    return list(R.skill(protocol).axes) or [None]


# ----------------------------------------------------------------------------- policies
def zero_policy(obs, u) -> torch.Tensor:
    return torch.zeros(u.num_envs, u.hand_spec.dof, device=u.device)


def make_random_policy(seed: int) -> PolicyFn:
    """Uniform random actions; the stream restarts at each episode from ``seed`` and the episode's
    seed, so a trial's actions do not depend on the trials run before it (or on sharding)."""
    g = torch.Generator()

    def policy(obs, u):
        if int(u.elapsed_steps[0]) == 0:
            g.manual_seed(trial_seed(seed, trial=int(u._episode_seed[0])))
        return (torch.rand(u.num_envs, u.hand_spec.dof, generator=g) * 2 - 1).to(u.device)
    return policy


def tightened_fingers_action(u, tighten: float = 0.1, base: Optional[torch.Tensor] = None) -> torch.Tensor:
    """Action [N, dof] that drives the fingers to ``base`` (default: their grasp pose ``finger_q0``)
    closed by at most ``tighten`` rad along the hand's closing direction (wrist residual zero: the
    wrist follows its reference)."""
    from unicross.scripted_grasp import closing_direction
    a = torch.zeros(u.num_envs, u.hand_spec.dof, device=u.device)
    delta = closing_direction(u.hand_spec).to(u.device) * tighten  # at most `tighten` rad
    q_des = torch.clamp((u.finger_q0 if base is None else base) + delta, u.q_lower[6:], u.q_upper[6:])
    a[:, 6:] = (q_des - u.command[:, 6:]) / u.action_scale[6:]
    return a.clamp(-1.0, 1.0)


def scripted_relocate_policy(obs, u, tighten: float = 0.1) -> torch.Tensor:
    """The paper's naive relocation baseline: tighten the fingers of the grasp slightly and drive
    the wrist (PD, through the action interface) to the pose that realises the final object pose
    with the object-in-hand pose fixed at its start value."""
    a = tightened_fingers_action(u, tighten)
    scale = u.action_scale
    init = u.init_rel
    ip, iq = pose_inv(init.x_oh, init.q_oh)
    hx, hq = pose_mul(u.final_x_or, u.final_q_or, ip, iq)
    q_wrist = torch.cat([hx, quat_to_euler_xyz(hq)], dim=-1)
    ref = F.wrist_reference(u.targets)
    a[:, :6] = (q_wrist - ref) / scale[:6]
    return a.clamp(-1.0, 1.0)


def make_scripted_grasp_policy() -> PolicyFn:
    """The scripted grasp synthesiser as a policy (descend, close, lift, hold); restarts at each reset."""
    from unicross.scripted_grasp import ScriptedGrasp
    state = {}

    def policy(obs, u):
        if int(u.elapsed_steps[0]) == 0 or state.get("env") is not u:
            state["env"], state["script"] = u, ScriptedGrasp(u)
        return state["script"]()
    return policy


def make_reference_policy(fraction: float = 1.0) -> PolicyFn:
    """The mode's physical reference (:data:`unicross.audit.PHYSICAL_REFERENCES`; translate z+:
    opening the fingers, z-: curling the index finger) at ``fraction`` of its rate: a constant scripted action, the bar beyond
    the zero action that an expert of that mode should beat."""
    from unicross.audit import reference_action
    from unicross.registry import mode_axis
    cache = {}

    def policy(obs, u):
        key = (id(u), int(u.mode[0]))
        if key not in cache:
            m = F.MODES[key[1]]
            cache[key] = reference_action(F.mode_skill(m), mode_axis(m), u.hand_spec, fraction).to(u.device)
        return cache[key].expand(u.num_envs, -1).clone()
    return policy


def expert_specs(source: str, hand: str) -> Dict[str, str]:
    """mode -> checkpoint of one expert per mode: ``source`` a folder laid out as ``unicross distill
    --experts`` reads it (``<mode>/checkpoint.pt``), or a hand's name for its shipped checkpoints."""
    from unicross.rl.policy_io import SHIPPED_DIR
    if source == hand:
        missing = [m for m in F.MODES if not (SHIPPED_DIR / hand / f"{m}.pt").exists()]
        if missing:
            raise FileNotFoundError(f"policy experts:{hand}: no shipped checkpoint for mode(s) {missing} "
                                    f"under {SHIPPED_DIR / hand}")
        return {m: f"{hand}/{m}" for m in F.MODES}
    if not Path(source).is_dir():
        raise FileNotFoundError(f"policy experts:{source}: neither a folder of <mode>/checkpoint.pt nor the hand "
                                f"{hand!r} (experts:{hand} takes its shipped checkpoints)")
    from unicross.rl.dagger import expert_paths
    return {m: str(p) for m, p in expert_paths(source).items()}


def make_experts_policy(source: str, hand: str, seed: int = 0) -> Tuple[PolicyFn, dict]:
    """The per-mode experts as one policy: each env is acted on by the expert of its current mode
    (the task's ``mode``, which the goal's one-hot shows the networks), so a long-horizon chain
    switches expert at each phase boundary: the teachers' side of the student's chain. Experts made
    under other physics than ``configs/task.yaml``'s run under it; experts made under different physics
    are refused."""
    specs = expert_specs(source, hand)
    loaded = {m: resolve_policy(s, hand, seed) for m, s in specs.items()}  # each checked against the hand
    for m, (_, desc) in loaded.items():
        trained = R.trained_mode(desc.get("skill"), desc.get("axis"))
        if trained != m:
            raise ValueError(f"policy experts:{source}: {specs[m]} was trained for mode {trained!r}, not {m!r}")
    sims = {json.dumps(desc.get("sim") or {}, sort_keys=True) for _, desc in loaded.values()}
    if len(sims) > 1:  # one env (one physics) serves every mode's expert
        raise ValueError(f"policy experts:{source}: the experts were made under different physics "
                         f"({sorted(sims)}); one evaluation runs them under one")
    policies = {F.MODES.index(m): fn for m, (fn, _) in loaded.items()}

    def policy(obs, u):
        mode = u.mode
        out = None
        for i in torch.unique(mode).tolist():
            a = policies[i](obs, u)
            out = a if out is None else torch.where((mode == i)[:, None], a, out)
        return out
    desc = dict(kind="experts", source=source, experts=specs)
    sim = json.loads(sims.pop())
    if sim:  # made under other physics than configs/task.yaml's: they run under it
        desc["sim"] = sim
    return policy, desc


def reference_fraction(spec: str) -> Optional[float]:
    """``reference`` -> 1.0, ``reference@0.75`` -> 0.75, anything else -> None."""
    if spec != "reference" and not spec.startswith("reference@"):
        return None
    try:
        f = float(spec.split("@", 1)[1]) if "@" in spec else 1.0
    except ValueError:
        raise ValueError(f"policy {spec!r}: write reference or reference@FRACTION, e.g. reference@0.75") from None
    if not f > 0:
        raise ValueError(f"policy {spec!r}: the fraction of the reference's rate must be > 0")
    return f


def resolve_policy(spec: str, hand: str, seed: int = 0):
    """(policy_fn, description). Checkpoints are checked against the hand before any simulation."""
    if (f := reference_fraction(spec)) is not None:
        return make_reference_policy(f), dict(kind="reference", fraction=f)
    if spec == "zero":
        return zero_policy, dict(kind="zero")
    if spec == "random":
        return make_random_policy(seed), dict(kind="random")
    if spec == "scripted-relocate":
        return scripted_relocate_policy, dict(kind="scripted-relocate")
    if spec == "scripted-grasp":
        return make_scripted_grasp_policy(), dict(kind="scripted-grasp")
    if spec.startswith("seq:"):
        from unicross.robots.hand import load_hand
        from unicross.sequences import check_sequence, make_sequence_policy
        seq = spec[len("seq:"):]
        check_sequence(seq, load_hand(hand))  # a malformed sequence or a finger the hand lacks fails here
        return make_sequence_policy(seq), dict(kind="sequence", sequence=seq)
    if spec.startswith("experts:"):
        return make_experts_policy(spec[len("experts:"):], hand, seed)
    if spec.startswith("gait:"):
        from unicross.gaits import gait_hand, gait_mode, make_gait_policy
        path = spec[len("gait:"):]
        policy = make_gait_policy(path)  # a missing file or a gait of the wrong length fails here, before any simulation
        if gait_hand(policy.gait_row) != hand:
            raise ValueError(f"policy {spec!r} is a gait for hand {gait_hand(policy.gait_row)!r}, not {hand!r}")
        desc = dict(kind="gait", path=path, mode=gait_mode(policy.gait_row), gait=policy.gait_row["p"],
                    meta=policy.gait_row.get("meta", {}))
        if desc["meta"].get("sim"):  # searched under other physics (gait_search.py --sim): runs under its own
            from unicross.config import parse_sim_overrides
            desc["sim"] = parse_sim_overrides(desc["meta"]["sim"])
        return policy, desc
    from unicross.rl.policy_io import base_policy_of, load_policy, policy_fn
    from unicross.robots.hand import load_hand
    policy, ck = load_policy(spec)
    spec_h = load_hand(hand)
    if ck["hand"] != hand:
        raise ValueError(f"checkpoint {spec} was trained for hand {ck['hand']!r}, not {hand!r}")
    L = len(spec_h.contact_links)
    expected = dict(hand=2 * spec_h.dof, object=5 * L, goal=F.GOAL_DIM)
    if dict(ck["obs_dims"]) != expected or ck["n_act"] != spec_h.dof:
        raise ValueError(f"checkpoint {spec} expects observation {ck['obs_dims']} / action {ck['n_act']}, "
                         f"hand {hand!r} gives {expected} / {spec_h.dof}")
    task_config = (ck.get("env_kwargs") or {}).get("config") or {}
    base = base_policy_of(ck)  # a residual policy acts on top of its gait (refused for another hand above)
    desc = dict(kind="checkpoint", path=str(spec), skill=ck.get("skill"), axis=ck.get("axis"),
                git_commit=ck.get("git_commit"), ablation=task_config.get("ablation", {}))
    if task_config.get("sim"):  # trained under other physics than configs/task.yaml's
        desc["sim"] = dict(task_config["sim"])
    if base is not None:
        desc["base_policy"] = base
    return policy_fn(policy.module[0].module, base), desc


# ----------------------------------------------------------------------------- one protocol
def _env_for(protocol: str, axis: Optional[str], obj: ObjectSpec, hand: str, disturb: bool, randomize: bool,
             grasp_dataset, original: bool, ablation: Optional[dict] = None, sim: Optional[dict] = None):
    sk = R.skill(protocol)
    cfg = dict(episode_length={protocol: sk.protocol_steps})
    if sim:  # physics other than configs/task.yaml's (unicross eval --sim)
        cfg["sim"] = dict(sim)
    if ablation:  # a policy trained without some inputs is evaluated with the same switches
        cfg["ablation"] = dict(ablation)
    if disturb:
        cfg["disturbance"] = dict(max_scale=EVAL_CFG["disturbance_scale"])
    if original and protocol == "grasp":
        cfg["table"] = False  # GraspXL's setting: no table
    if original and sk.axes:
        cfg["in_hand_orientation"] = "palm_up"  # RotateIt / in-hand translation: palm up, wrist fixed
    kw = dict(obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none", hand=hand, objects=[obj],
              randomize=randomize, config=cfg, **sk.env_kwargs(axis))
    if protocol != "grasp" and grasp_dataset is not None:
        kw["grasp_dataset"] = grasp_dataset
    return gym.make(sk.env_id, **kw)


def protocol_objects(protocol: str, objects: Sequence[ObjectSpec], hand: str = "allegro", grasp_dataset=None):
    """The objects of ``objects`` that ``protocol`` evaluates, and the grasp dataset it starts from:
    the skill's categories, and for the in-hand protocols only objects with a grasp state (a warning
    names the others). Raises ``ValueError`` when none is left."""
    sk = R.skill(protocol)
    objs = [o for o in objects if o.category in sk.categories]
    if not objs:
        raise ValueError(f"no {' or '.join(sk.categories)} object in the set for protocol {protocol!r}")
    if protocol != "grasp":  # in-hand protocols start from grasps: objects without one cannot be evaluated
        from unicross.grasps import GraspSet, default_grasp_path
        gs = grasp_dataset if isinstance(grasp_dataset, GraspSet) else \
            GraspSet.load(grasp_dataset or default_grasp_path(hand))
        grasp_dataset = gs  # loaded once for all the protocol's envs
        have = {n for n, c in gs.counts().items() if c > 0}
        lacking = [o.name for o in objs if o.name not in have]
        if len(lacking) == len(objs):
            raise ValueError(f"the grasp dataset has no grasp of any {protocol} object ({lacking[:3]}...); "
                             f"build them with `unicross grasps --hand {hand} --objects <set>`")
        if lacking:
            logger.warning(f"{protocol}: {len(lacking)} object(s) without a grasp are not evaluated: {lacking}")
            objs = [o for o in objs if o.name in have]
    return objs, grasp_dataset


def run_protocol(protocol: str, policy: PolicyFn, objects: Sequence[ObjectSpec], hand: str = "allegro",
                 trials_per_object: int = EVAL_CFG["trials_per_object"], seed: int = 0, disturb: bool = False, randomize: bool = False,
                 grasp_dataset=None, original: bool = False, progress: bool = True,
                 videos: int = 0, video_dir=None, ablation: Optional[dict] = None,
                 axes: Optional[Sequence[str]] = None, shard: Optional[Tuple[int, int]] = None,
                 sim: Optional[dict] = None) -> List[dict]:
    """All trials of one protocol; returns one dict per trial. The first ``videos`` trials are
    recorded as trajectory files (and rendered to mp4) in ``video_dir``. ``sim`` overrides the
    physics of ``configs/task.yaml`` (its ``sim`` section). ``axes`` restricts
    rotate/translate to some of the protocol's axes (default: all). ``shard=(i, n)`` runs only the
    objects whose index is i modulo n; every trial is seeded from its object's index in the whole
    list, so n shards together give exactly the trials of one unsharded run."""
    if protocol not in PROTOCOLS:
        raise ValueError(f"unknown protocol {protocol!r}; valid: {list(PROTOCOLS)}")
    sk = R.skill(protocol)
    all_axes = _axes(protocol)
    bad = [a for a in (axes or []) if a not in all_axes]
    if bad:
        raise ValueError(f"axes {bad} are not axes of protocol {protocol!r}: {all_axes}")
    axes = list(axes) if axes else all_axes
    objs, grasp_dataset = protocol_objects(protocol, objects, hand, grasp_dataset)
    steps = sk.protocol_steps
    trials = []
    mine = [oi for oi in range(len(objs)) if shard is None or oi % shard[1] == shard[0]]
    total = len(mine) * len(axes) * trials_per_object
    bar = tqdm(total=total, desc=f"eval {protocol}", disable=not progress)
    for oi in mine:
        obj = objs[oi]
        for axis in axes:
            env = _env_for(protocol, axis, obj, hand, disturb, randomize, grasp_dataset, original, ablation, sim)
            u = env.unwrapped
            axis_vec = F.MODE_AXES[F.mode_index(protocol, axis)]
            for k in range(trials_per_object):
                seed_k = trial_seed(seed, oi, k, axis=all_axes.index(axis))
                obs, info = u.reset(seed=seed_k)
                rec = None
                if len(trials) < videos:
                    from unicross.trajectory import TrajectoryRecorder
                    rec = TrajectoryRecorder(u, task_id=sk.env_id)
                    rec.record(protocol)
                x_oh, q_oh, p_w, q_w, drop = [u.cur_rel.x_oh.clone()], [u.cur_rel.q_oh.clone()], [], [], []
                goal_p, goal_q = pose_mul(u.root_p, u.root_q, u.final_x_or, u.final_q_or)
                for t in range(steps):
                    a = policy(obs, u)
                    if original and sk.axes:
                        a[:, :6] = 0.0  # fixed wrist
                    obs, _, term, _, info = u.step(a)
                    x_oh.append(u.cur_rel.x_oh.clone())
                    q_oh.append(u.cur_rel.q_oh.clone())
                    pos, quat = u.sensor.poses()
                    p_w.append(pos[:, -1].clone())
                    q_w.append(quat[:, -1].clone())
                    drop.append(info["drop"].clone())
                    if rec is not None:
                        rec.record(protocol)
                    if bool(term.all()):
                        break
                if rec is not None:
                    _save_video(rec, video_dir, f"{protocol}_{obj.name}_{axis or 'na'}_{k}")
                trials.append(_score(protocol, obj, axis, k, seed_k, axis_vec.to(u.device),
                                     torch.stack(x_oh, 1), torch.stack(q_oh, 1), torch.stack(p_w, 1),
                                     torch.stack(q_w, 1), torch.stack(drop, 1), goal_p, goal_q, info, u))
                bar.update(1)
            env.close()
    bar.close()
    return trials


def merge_shards(protocol: str, objects: Sequence[ObjectSpec], parts: Sequence[List[dict]]) -> List[dict]:
    """The trials of shards of one :func:`run_protocol` call, in the order one unsharded call gives."""
    order = {o.name: i for i, o in enumerate(objects)}
    return sorted((t for part in parts for t in part),
                  key=lambda t: (order[t["object"]], _axes(protocol).index(t["axis"]), t["trial"]))


def _protocol_shard(spec: str, hand: str, policy_seed: int, protocol: str, objects, kwargs: dict, shard) -> List[dict]:
    torch.set_num_threads(1)
    policy, desc = resolve_policy(spec, hand, seed=policy_seed)
    return run_protocol(protocol, policy, objects, hand=hand, shard=shard, progress=False, **_own_physics(kwargs, desc))


def _own_physics(kwargs: dict, desc: dict) -> dict:
    """``kwargs`` of :func:`run_protocol`, with the physics a policy was made under (its description's ``sim``)
    where the caller named none."""
    return dict(kwargs, sim=desc.get("sim")) if kwargs.get("sim") is None else kwargs


def run_protocol_workers(protocol: str, spec: str, objects: Sequence[ObjectSpec], hand: str = "allegro",
                         workers: int = 1, seed: int = 0, **kwargs) -> List[dict]:
    """:func:`run_protocol` for the policy named by ``spec`` (as ``unicross eval --policy``), split
    over ``workers`` spawned processes (objects i mod n). Trials are seeded per object and trial,
    so the result is the same for any number of workers (tested). Without ``sim``, a checkpoint
    made under other physics (its ``env_kwargs`` config's ``sim``) runs under its own."""
    if workers <= 1:
        policy, desc = resolve_policy(spec, hand, seed=seed)
        return run_protocol(protocol, policy, objects, hand=hand, seed=seed, **_own_physics(kwargs, desc))
    if kwargs.get("videos"):
        raise ValueError("--videos records the first trials of one process: use --workers 1")
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor
    kwargs = {k: v for k, v in kwargs.items() if k not in ("progress", "video_dir")}
    print(f"eval {protocol}: {len(objects)} objects on {workers} worker processes ...", flush=True)
    with ProcessPoolExecutor(workers, mp_context=mp.get_context("spawn")) as ex:
        futures = [ex.submit(_protocol_shard, spec, hand, seed, protocol, list(objects), dict(kwargs, seed=seed),
                             (i, workers)) for i in range(workers)]
        parts = [f.result() for f in futures]
    return merge_shards(protocol, objects, parts)


def _save_video(rec, video_dir, name: str) -> None:
    from unicross.render import RenderUnavailable, render
    d = Path(video_dir or ".")
    traj = rec.save(d / f"{name}.npz")
    try:
        render(traj, d / f"{name}.mp4", progress=False)
    except RenderUnavailable as e:  # keep the trajectory; say once why there is no video
        print(f"video skipped ({e}); render later with `unicross render {traj} --out {name}.mp4`")


def _score(protocol, obj, axis, k, seed, axis_vec, x_oh, q_oh, p_w, q_w, drop, goal_p, goal_q, info, u) -> dict:
    dropped = bool(M.ever(drop)[0])
    row = dict(object=obj.name, category=obj.category, shape=obj.shape, axis=axis, trial=k, seed=seed,
               steps=int(drop.shape[1]), dropped=dropped)
    if protocol == "grasp":
        lifted = bool(((p_w[:, -1, 2] - u.obj_z0) > u.cfg["grasp"]["lift_success"])[0])
        row.update(lifted=lifted, success=lifted and not dropped)
    elif protocol == "relocate":
        pe, ae = M.pose_errors(p_w, q_w, goal_p, goal_q, window=EVAL_CFG["pose_error_window"])
        pe_end, ae_end = M.pose_errors(p_w, q_w, goal_p, goal_q, window=1)
        sc = u.cfg["success"]
        ok = bool(pe_end[0] < sc["relocate_pos"]) and bool(ae_end[0] < sc["relocate_rot"])
        row.update(pe_cm=100 * float(pe[0]), ae_rad=float(ae[0]), success=ok and not dropped)
    elif protocol == "rotate":
        series = M.rotation_series(q_oh, axis_vec)
        row.update(rotation_rad=float(series[0, -1]),
                   success=bool(M.exceeded(series, u.cfg["success"]["rotate_angle"])[0]) and not dropped)
    else:
        series = M.translation_series(x_oh, axis_vec)
        row.update(translation_cm=100 * float(series[0, -1]),
                   success=bool(M.exceeded(series, u.cfg["success"]["translate_dist"])[0]) and not dropped)
    return row


# ----------------------------------------------------------------------------- summaries and tables
def read_results(path) -> dict:
    """A ``unicross eval`` result file, as written (``.json``) or as committed (``.json.gz``)."""
    raw = Path(path).read_bytes()
    r = json.loads(gzip.decompress(raw) if str(path).endswith(".gz") else raw)
    if "summaries" not in r:
        raise ValueError(f"{path} is not a `unicross eval` result")
    return r


def summarize(protocol: str, trials: List[dict]) -> dict:
    succ = torch.tensor([t["success"] for t in trials], dtype=torch.bool)
    kept = torch.tensor([not t["dropped"] for t in trials], dtype=torch.bool)
    out = dict(M.success_summary(succ), non_dropped=int(kept.sum()))
    if protocol == "relocate":
        out["pe_cm"] = M.mean_over(torch.tensor([t["pe_cm"] for t in trials]), kept)
        out["ae_rad"] = M.mean_over(torch.tensor([t["ae_rad"] for t in trials]), kept)
    if protocol == "rotate":
        out["rot_rad"] = M.mean_over(torch.tensor([t["rotation_rad"] for t in trials]), kept)
    if protocol == "translate":
        out["trans_cm"] = M.mean_over(torch.tensor([t["translation_cm"] for t in trials]), kept)
    return out


COLUMNS = ["Grasp SR", "Relocate SR", "PE", "AE", "Rotate SR", "Rot.", "Translate SR", "Trans."]


def table_row(summaries: Dict[str, dict]) -> List[str]:
    def sr(p):
        s = summaries.get(p)
        return "--" if s is None else f"{s['sr']:.1f} [{s['ci95'][0]:.0f}-{s['ci95'][1]:.0f}] (n={s['n']})"

    def val(p, k, fmt):
        s = summaries.get(p)
        return "--" if s is None or s.get(k) is None or s[k] != s[k] else fmt.format(s[k])
    return [sr("grasp"), sr("relocate"), val("relocate", "pe_cm", "{:.2f}"), val("relocate", "ae_rad", "{:.4f}"),
            sr("rotate"), val("rotate", "rot_rad", "{:.2f}"), sr("translate"), val("translate", "trans_cm", "{:.1f}")]


def markdown_table(rows: Dict[str, Dict[str, dict]]) -> str:
    """rows: label -> {protocol: summary}. Paper layout; SR cells carry the 95% Wilson interval and n."""
    lines = ["| Setting | " + " | ".join(COLUMNS) + " |", "|---|" + "---|" * len(COLUMNS)]
    for label, summ in rows.items():
        lines.append(f"| {label} | " + " | ".join(table_row(summ)) + " |")
    return "\n".join(lines)


# ----------------------------------------------------------------------------- long horizon
def run_chain(policy: PolicyFn, objects: Sequence[ObjectSpec], sequence: Optional[str] = None,
              hand: str = "allegro", trials_per_object: int = EVAL_CFG["trials_per_object"], seed: int = 0, randomize: bool = False,
              progress: bool = True, videos: int = 0, video_dir=None, sim: Optional[dict] = None) -> List[dict]:
    """Long-horizon protocol: grasp -> relocate -> in-hand from random table poses in one episode.

    ``sequence`` None: the paper's protocol (wrappable objects: rotate about a random axis;
    elongated: translate along a random direction); otherwise e.g. 'grasp,relocate,rotate:x+', run
    on the objects that can do every phase (the others are left out; none raises before any
    simulation). ``sim``: physics other than ``configs/task.yaml``'s ``sim`` section, as :func:`run_protocol`."""
    from unicross.tasks.chain import objects_for_chain, parse_sequence
    if sequence is not None:
        objects = objects_for_chain(objects, parse_sequence(sequence))
    rng = torch.Generator().manual_seed(seed)
    trials = []
    bar = tqdm(total=len(objects) * trials_per_object, desc="eval chain", disable=not progress)
    for oi, obj in enumerate(objects):
        for k in range(trials_per_object):
            if sequence is None:
                skill = "rotate" if obj.category == "wrappable" else "translate"
                axes = R.skill(skill).axes
                seq = f"grasp,relocate,{skill}:{axes[int(torch.randint(len(axes), (1,), generator=rng))]}"
            else:
                seq = sequence
            modes = parse_sequence(seq)
            env = gym.make("UniCross-Chain-v1", obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none",
                           hand=hand, objects=[obj], randomize=randomize, sequence=modes,
                           config=dict(sim=dict(sim)) if sim else None)
            u = env.unwrapped
            seed_k = trial_seed(seed, oi, k)
            obs, info = u.reset(seed=seed_k)
            rec = None
            if len(trials) < videos:
                from unicross.trajectory import TrajectoryRecorder
                rec = TrajectoryRecorder(u, task_id="UniCross-Chain-v1")
                rec.record(f"phase 1/{len(modes)}")
            phase_of_drop = None
            for t in range(u.phase_ends[-1]):
                obs, _, term, trunc, info = u.step(policy(obs, u))
                if rec is not None:
                    rec.record(f"phase {int(u.phase[0]) + 1}/{len(modes)}")
                if bool(term.all()):
                    phase_of_drop = int(u.phase[0])
                    break
            ps = u.phase_success[0].tolist()
            trials.append(dict(object=obj.name, category=obj.category, sequence=modes, trial=k, seed=seed_k,
                               phase_success=ps, overall=all(ps), dropped_in_phase=phase_of_drop,
                               steps=int(u.elapsed_steps[0])))
            if rec is not None:
                _save_video(rec, video_dir, f"chain_{obj.name}_{k}")
            env.close()
            bar.update(1)
    bar.close()
    return trials


def summarize_chain(trials: List[dict]) -> Dict[str, dict]:
    """Per sequence kind (Gr.+Re.+Rot. / Gr.+Re.+Trans.): per-phase and overall SR."""
    groups: Dict[str, List[dict]] = {}
    for t in trials:
        kind = " + ".join(R.skill_of_mode(m).short_name for m in t["sequence"])
        groups.setdefault(kind, []).append(t)
    out = {}
    for kind, ts in groups.items():
        ps = torch.tensor([t["phase_success"] for t in ts], dtype=torch.bool)
        # a phase counts only if every phase before it succeeded (the chain continues from it)
        reached = torch.cumprod(ps.int(), dim=1).bool()
        out[kind] = dict(phases=[M.success_summary(reached[:, i]) for i in range(ps.shape[1])],
                         per_phase=[M.success_summary(ps[:, i]) for i in range(ps.shape[1])],
                         overall=M.success_summary(ps.all(dim=1)), n=len(ts))
    return out


def chain_last_phase_by_mode(trials: List[dict]) -> Dict[str, dict]:
    """Success of the last (in-hand) phase per mode over every trial of that mode, e.g. a
    Gr.+Re.+Trans. table split into translate_z+ and translate_z-."""
    by: Dict[str, List[bool]] = {}
    for t in trials:
        by.setdefault(t["sequence"][-1], []).append(bool(t["phase_success"][-1]))
    return {m: M.success_summary(torch.tensor(v, dtype=torch.bool)) for m, v in sorted(by.items())}


def sr_cell(s: dict) -> str:
    """A success summary as 'SR [lo-hi] (n=N)' (the chain tables' cell)."""
    return f"{s['sr']:.1f} [{s['ci95'][0]:.0f}-{s['ci95'][1]:.0f}] (n={s['n']})"


def chain_table(summary: Dict[str, dict]) -> str:
    lines = ["| Sequence | Grasp SR | Relocate SR | In-hand SR | Overall SR |", "|---|---|---|---|---|"]
    for kind, s in summary.items():
        cells = [sr_cell(p) for p in s["per_phase"][:3]] + [sr_cell(s["overall"])]
        lines.append(f"| {kind} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
