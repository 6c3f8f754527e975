"""Search for an open-loop finger gait that does an in-hand mode: is there a scripted motion to start PPO from?

Translate z+ has a physical reference (opening the fingers slides the object out; README "Reward
audit"), and PPO started from it (`model.init_reference`) gives the shipped expert. Rotation and
translate z- have none. This script samples periodic finger motions and measures what they do
to a grasped object, in the task itself (grasp-state starts, random wrist orientation):

    finger f's joints (abduction, MCP, PIP = DIP) follow q0 + bias + amplitude * sin(2 pi t / T + phase),
    with the distal joints shifted by a loop phase (a closed path in joint space), T in 6..36 steps

6 numbers in [-1, 1] per finger and the period (25 for Allegro; ``--hand`` another hand, its fingers' joints
as :func:`unicross.gaits.gait_layout` reads them), the wrist holding still. Each gait
runs on the first ``--limit`` objects per group of ``--objects`` x ``--seeds`` starts (the
audit's seeds) for ``--steps`` control steps or until the object drops; per episode it records
the object's accumulated rotation (the integral of its angular velocity in the hand frame: what
the rotate success test accumulates, about all three axes) and displacement in the hand frame.

    python benchmarks/gait_search.py --skill rotate --candidates 168 --amplitude 0.6 --no-randomize \
        --limit 2 --out docs/runs/gait_search/rotate_norand.jsonl
    python benchmarks/gait_search.py --skill translate --axis z- --steps 64 --candidates 168 --amplitude 0.6 \
        --no-randomize --limit 2 --out docs/runs/gait_search/translate_zm_norand.jsonl
    python benchmarks/gait_search.py --summary docs/runs/gait_search/*.jsonl.gz

``--one-finger`` keeps three fingers still (each at its own bias, e.g. tightened) and moves one:
a ratchet that might turn the object a little per cycle without loosening the grasp.
``--refine AXIS`` (e.g. ``z+``) runs a cross-entropy search from the zero gait instead, scoring each
episode by its accumulated rotation about AXIS in units of the success angle (rotate; capped at 2)
or its displacement along AXIS in units of the success distance (translate; capped at 2), a drop
as -1 (``--init FILE``: start from the best gait of a log instead):

    python benchmarks/gait_search.py --skill translate --axis z- --refine z- --steps 64 --amplitude 0.6 \
        --no-randomize --limit 2 --generations 30 --out docs/runs/gait_search/translate_zm_refine.jsonl

``--hold`` (with ``--refine``) scores what the rotate protocol counts: the gait stops for good once
the object has turned past the success angle about the axis (the fingers hold their targets; read
from the task's state) and the episode runs on to ``--steps`` (400: the protocol's); an episode
scores 1 for a success (passed, never dropped), half its turn in success angles otherwise, -0.5 for
a drop. With ``--init`` the first generation is the 16 logged gaits that turned the object furthest
about the axis; the search goes on from the best of them. ``--no-stop`` scores the same success while the
gait keeps cycling after it (no privileged stop: the gait a network can copy, ``benchmarks/gait_clone.py``).
``--select N`` re-runs the N best
distinct gaits on ``--select-seeds`` new starts per object and logs their success rate: the gait
that ``unicross eval --policy gait:LOG`` runs (:mod:`unicross.gaits`). The shipped rotate gaits:

    python benchmarks/gait_search.py --skill rotate --axis x+ --refine x+ --hold \
        --init docs/runs/gait_search/rotate_norand.jsonl.gz docs/runs/gait_search/rotate_one_finger_norand.jsonl.gz \
        --steps 400 --amplitude 0.6 --no-randomize --limit 2 --generations 8 --sigma 0.2 --select 6 \
        --out docs/runs/gait_search/rotate_x+_hold.jsonl

``--init-reversed`` starts from the logged gaits run backwards in time (their rotations negated):
the y- gaits, reversed, gave y+ the gait it ships (section "Scripted rotation gaits" of the README):

    python benchmarks/gait_search.py --skill rotate --axis y+ --refine y+ --hold --init-reversed \
        --init docs/runs/gait_search/rotate_y-_hold.jsonl.gz docs/runs/gait_search/rotate_y-_hold2.jsonl.gz \
        --steps 400 --amplitude 0.6 --no-randomize --limit 4 --generations 6 --sigma 0.15 --select 6 \
        --select-seeds 4 --out docs/runs/gait_search/rotate_y+_reversed.jsonl

``--sample K`` (with ``--refine``) runs each generation's gaits on K objects drawn anew from the ``--limit`` objects
per group, one new start each, instead of the same objects x ``--seeds`` starts every generation: the searches
above saw 8 objects, and the z+ gait they found turns 25.8% of 120 trials on 40 training objects, as on test
objects, against 62.5% in its selection on those 8 (README "Scripted rotation gaits"). The selection then runs on
every one of the ``--limit`` objects per group x ``--select-seeds`` new starts:

    python benchmarks/gait_search.py --skill rotate --axis z+ --refine z+ --hold \
        --init docs/runs/gait_search/rotate_z+_hold.jsonl.gz docs/runs/gait_search/rotate_z+_hold2.jsonl.gz \
        --steps 400 --amplitude 0.6 --no-randomize --limit 20 --sample 24 --generations 8 --sigma 0.15 \
        --select 6 --select-seeds 2 --out docs/runs/gait_search/rotate_z+_sampled.jsonl

``--grasps PATH`` starts the episodes from another grasp-state dataset (default: the shipped one, the grasp
expert's), e.g. ``configs/grasps/allegro_scripted.pt`` (docs/runs/gait_search/thumb_grasps/).

Episodes run in two spawned worker processes, one env per object each.
"""
from __future__ import annotations

import argparse
import functools
import gzip
import json
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from unicross.gaits import gait_targets, layout_of, phase_cycle, phase_offsets  # noqa: E402
from unicross.config import parse_sim_overrides  # noqa: E402
_ENVS = {}


@functools.lru_cache(maxsize=None)
def _objects(skill: str, name: str, limit: int, hand: str, grasps=None) -> list:
    """The first ``limit`` objects per group of set ``name`` that ``skill``'s protocol runs for ``hand``
    (:func:`unicross.evaluation.protocol_objects`: its categories, with a grasp state; every Allegro training
    object has one), read once per process."""
    from unicross.evaluation import protocol_objects
    from unicross.objects import get_object_set
    return protocol_objects(skill, get_object_set(name, limit=limit), hand, grasps)[0]


def _env(job):
    key = (job["hand"], job["skill"], job["axis"], job["objects"], job["limit"], job["oi"], job["randomize"], job["grasps"],
           job["sim"])
    if key not in _ENVS:
        import gymnasium as gym
        import unicross  # noqa: F401  (registers the tasks)
        from unicross.config import load_config
        from unicross.registry import skill as skill_entry
        from unicross.rl.ppo import env_kwargs_for
        kw = env_kwargs_for(job["skill"], job["axis"], job["hand"], load_config("ppo", None)["env"])
        kw.pop("object_limit", None)
        kw.pop("reconfiguration_freq", None)
        kw["randomize"] = job["randomize"]
        if job["grasps"] is not None:
            kw["grasp_dataset"] = job["grasps"]
        if job["sim"]:  # physics other than configs/task.yaml's (--sim)
            kw["config"] = dict(kw.get("config") or {}, sim=dict(job["sim"]))
        obj = _objects(job["skill"], job["objects"], job["limit"], job["hand"], job["grasps"])[job["oi"]]
        _ENVS[key] = gym.make(skill_entry(job["skill"]).env_id, obs_mode="state", sim_backend="physx_cpu",
                              render_backend="none", num_envs=1, **{**kw, "objects": [obj]})
    return _ENVS[key].unwrapped


def episode(job) -> list:
    """[rotation x, y, z (rad), displacement x, y, z (m), dropped, steps, exceeded] of one gait episode.

    With ``job["hold"]`` = (component, sign, threshold) the gait stops for good once the motion about
    or along that signed axis exceeds the threshold (the fingers hold their targets from then on) and
    the episode runs on to ``steps``: the protocol's "exceeded, never dropped" (``exceeded`` = 1); with
    ``job["no_stop"]`` the gait goes on cycling after that (``exceeded`` is still recorded)."""
    import torch
    torch.set_num_threads(1)
    u = _env(job)
    u.reset(seed=job["seed"])
    layout = layout_of(job["hand"])
    p = torch.as_tensor(job["p"], dtype=torch.float32)
    p[:-1] *= job["amplitude"]
    if job["finger"] is not None:  # one finger moves, the others keep only their bias (tightening or loosening)
        for f in range(len(layout.fingers)):
            if f != job["finger"]:
                p[6 * f: 6 * f + 3] = 0.0
    q0 = u.command[0, 6:].clone()
    x0 = u.cur_rel.x_oh[0].clone()
    phase = job.get("tracking", "clock") == "phase"
    if phase:  # the cycle as unicross.gaits.make_gait_policy samples it (8 times a control step)
        taus, cycle = phase_cycle(p, 8, layout)
    rot = torch.zeros(3)
    dropped, steps, exceeded = False, 0, False
    for t in range(job["steps"]):
        a = torch.zeros(1, u.action_scale.shape[0])
        if not exceeded or job.get("no_stop"):
            if phase:
                target = q0 + phase_offsets(p, taus, cycle, u.command[:, 6:] - q0, job["lookahead"], layout)[0]
            else:
                target = gait_targets(p, t + 1, q0, layout)
            a[0, 6:] = ((target - u.command[0, 6:]) / u.action_scale[6:]).clamp(-1, 1)
        _, _, term, trunc, _ = u.step(a)
        steps += 1
        if bool(term[0]) or bool(u.ever_dropped[0]):
            dropped = True
            break
        rot += u.obj_angvel_h[0] * u.control_dt
        if job.get("hold") is not None:
            comp, sign, thr = job["hold"]
            motion = rot if comp < 3 else u.cur_rel.x_oh[0] - x0
            exceeded |= bool(sign * motion[comp % 3] > thr)
        if bool(trunc[0]):
            break
    return rot.tolist() + (u.cur_rel.x_oh[0] - x0).tolist() + [float(dropped), steps, float(exceeded)]


def evaluate(pool, gaits, args, n_obj, first: int = 0, hold=None, seeds=None, pairs=None):
    """[gaits, episodes, 9] of every gait on every object x start (``seeds``: the starts' indices,
    default ``range(args.seeds)``), or on the given (object index, start index) ``pairs``."""
    from unicross.seeding import trial_seed
    seeds = list(range(args.seeds)) if seeds is None else list(seeds)
    pairs = [(oi, k) for oi in range(n_obj) for k in seeds] if pairs is None else list(pairs)
    n_fingers = len(layout_of(args.hand).fingers)
    jobs = [dict(p=p.tolist(), oi=oi, seed=trial_seed(0, oi, k), hand=args.hand, skill=args.skill, axis=args.axis,
                 objects=args.objects, limit=args.limit, randomize=not args.no_randomize, steps=args.steps,
                 amplitude=args.amplitude, finger=(first + i) % n_fingers if args.one_finger else None, hold=hold,
                 grasps=args.grasps, tracking=args.tracking, lookahead=args.lookahead, no_stop=args.no_stop,
                 sim=args.sim_pairs)
            for i, p in enumerate(gaits) for oi, k in pairs]
    return np.array(pool.map(episode, jobs, chunksize=1)).reshape(len(gaits), len(pairs), 9)


def sampled_pairs(rng, n_obj: int, sample: int, generation: int) -> list:
    """``--sample``: the (object index, start index) pairs of one generation: ``sample`` distinct objects of the
    ``n_obj``, drawn anew each generation, each from a start no generation or selection uses again (start index
    1000 + generation). Every gait of the generation runs on the same pairs (common random numbers)."""
    objs = rng.choice(n_obj, size=min(sample, n_obj), replace=False)
    return [(int(oi), 1000 + generation) for oi in sorted(objs)]


def init_gaits(paths, amplitude: float, reverse: bool = False, hand: str = "allegro"):
    """(gaits [n, npar] as this search's parameters, their logged results [n, episodes, 8]) of the rows of
    earlier logs: a one-finger row gets its still fingers' amplitudes zeroed, and every row is rescaled
    from its log's ``--amplitude`` to ``amplitude`` (clipped to [-1, 1]), so it moves the fingers as logged.
    ``reverse``: each gait run backwards in time (:func:`unicross.gaits.reverse_gait`) and its logged
    rotation and displacement negated (what a kinematic motion run backwards would do; the first
    generation tests it). The reversal acts on this search's parameters, which ``--amplitude`` scales
    phases included, so with an amplitude below 1 the gait runs backwards up to a time shift common
    to all fingers (the same motion from another start)."""
    from unicross.gaits import gait_hand, read_log, reverse_gait
    ps, rs = [], []
    for path in paths:
        for row in read_log(path):
            if gait_hand(row) != hand:
                raise ValueError(f"{path}: a log of gaits for hand {gait_hand(row)!r}, this search is for {hand!r}")
            p = np.array(row["p"], dtype=float)
            finger = row.get("finger")
            if finger is not None:
                for f in range(len(p) // 6):
                    if f != finger:
                        p[6 * f: 6 * f + 3] = 0.0
            p[:-1] = (p[:-1] * row.get("meta", {}).get("amplitude", 1.0) / amplitude).clip(-1, 1)
            r = np.array(row["r"])[:, :8]
            if reverse:
                p = reverse_gait(p).double().numpy()
                r[:, :6] = -r[:, :6]
            ps.append(p)
            rs.append(r)
    n_ep = min(r.shape[0] for r in rs)
    return np.array(ps), np.array([r[:n_ep] for r in rs])


def summary(paths):
    """Per file: drop rate, drop-free gaits, and per signed axis the gaits' best share of episodes that
    reach half the rotate angle (0.785 rad) or the translate distance (5 cm) without a drop."""
    for path in paths:
        with (gzip.open(path, "rt") if path.endswith(".gz") else open(path)) as f:
            rows = [json.loads(line) for line in f]
        r = np.array([row["r"] for row in rows])
        head = rows[0].get("meta", {})
        drop = r[:, :, 6]
        print(f"{path}: {len(rows)} gaits x {r.shape[1]} episodes, {head}")
        print(f"  episodes dropped {drop.mean():.1%}; gaits with no drop {(drop.max(1) == 0).sum()}")
        for c, name in enumerate("xyz"):
            for sign in (1, -1):
                rot, disp = sign * r[:, :, c], sign * r[:, :, 3 + c]
                ok_rot = ((rot > math.pi / 4) & (drop == 0)).mean(1)
                ok_disp = ((disp > 0.05) & (drop == 0)).mean(1)
                print(f"  {name}{'+' if sign > 0 else '-'}: best gait rotates >= 0.785 rad in {ok_rot.max():.0%} of "
                      f"episodes (no drop), moves >= 5 cm in {ok_disp.max():.0%}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--hand", default="allegro", help="the hand (its fingers: unicross.gaits.gait_layout)")
    ap.add_argument("--skill", default="rotate", choices=["rotate", "translate"])
    ap.add_argument("--axis", default=None, help="the env's axis (rotation is measured about all three)")
    ap.add_argument("--objects", default=None, help="default: the skill's training set")
    ap.add_argument("--limit", type=int, default=1, help="objects per (category, type) group")
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--candidates", type=int, default=160)
    ap.add_argument("--amplitude", type=float, default=1.0, help="scales amplitudes and bias")
    ap.add_argument("--one-finger", action="store_true",
                    help="gait i moves finger i mod 4 only (index, middle, ring, thumb); the others keep their bias")
    ap.add_argument("--no-randomize", action="store_true", help="the evaluation's conditions (default: training's)")
    ap.add_argument("--init", nargs="+", default=None,
                    help="--refine: start from the best gait of these logs (same score); with --hold the first "
                         "generation is the 16 logged gaits that moved the object furthest")
    ap.add_argument("--init-reversed", action="store_true",
                    help="--init: the logged gaits run backwards in time (a gait for y- as a start for y+)")
    ap.add_argument("--refine", default=None, help="cross-entropy search for motion along / about this axis (x+ ... z-)")
    ap.add_argument("--generations", type=int, default=10)
    ap.add_argument("--sigma", type=float, default=0.35, help="--refine: the search's starting spread")
    ap.add_argument("--select", type=int, default=0,
                    help="--refine --hold: at the end, evaluate the N best distinct gaits on --select-seeds new starts "
                         "per object and log their success (what `--policy gait:LOG` picks)")
    ap.add_argument("--select-seeds", type=int, default=4)
    ap.add_argument("--sample", type=int, default=0,
                    help="--refine: each generation runs its gaits on this many objects drawn anew from the --limit "
                         "objects per group, one new start each (default 0: every object x --seeds starts, the same "
                         "episodes every generation, which a search can fit)")
    ap.add_argument("--hold", action="store_true",
                    help="--refine: the gait stops once the motion exceeds the success threshold, the fingers hold "
                         "to --steps; score = the protocol's success (exceeded, never dropped)")
    ap.add_argument("--no-stop", action="store_true",
                    help="--hold: score the protocol's success as --hold does, but the gait never stops: it keeps "
                         "cycling for all --steps (no privileged read of the object's motion), as a policy that sees "
                         "only the observation would; logged in the rows' meta, which the gait then runs with (stop=0)")
    ap.add_argument("--grasps", default=None,
                    help="grasp-state dataset the episodes start from (default: the shipped one, the grasp expert's)")
    ap.add_argument("--tracking", default="clock", choices=["clock", "phase"],
                    help="how each gait is run and scored (unicross.gaits.make_gait_policy): clock, as searched so far, "
                         "or phase (the target --lookahead steps past the cycle's point nearest the joint command, a "
                         "function of the state); logged in the rows' meta, which the gait then runs with")
    ap.add_argument("--lookahead", type=float, default=1.5, help="--tracking phase: control steps ahead on the cycle")
    ap.add_argument("--sim", action="append", metavar="KEY=VALUE",
                    help="physics other than configs/task.yaml's sim section (repeatable), e.g. "
                         "solver_position_iterations=8 (the default before 2026-12-04); logged in the rows' meta, which the gait then runs under")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=None)
    ap.add_argument("--summary", nargs="+", default=None)
    args = ap.parse_args()
    if args.summary:
        return summary(args.summary)
    if args.out is None:
        ap.error("--out is required")
    if args.no_stop and not args.hold:
        ap.error("--no-stop scores the protocol's success: it needs --hold (and --refine)")
    try:  # a bad --sim fails here, before any simulation; the jobs carry it as hashable pairs
        args.sim_pairs = tuple(sorted(parse_sim_overrides(args.sim).items()))
    except ValueError as e:
        ap.error(str(e))
    args.axis = args.axis or ("z-" if args.skill == "translate" else "x+")
    args.objects = args.objects or ("train-elongated" if args.skill == "translate" else "train-wrappable")
    from multiprocessing import get_context
    n_obj = len(_objects(args.skill, args.objects, args.limit, args.hand, args.grasps))
    npar = layout_of(args.hand).npar
    rng = np.random.default_rng(args.seed)
    meta = {k: v for k, v in vars(args).items() if k not in ("summary", "out", "sim_pairs")}
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with get_context("spawn").Pool(2) as pool, open(args.out, "a") as log:
        if args.refine is None:
            for i in range(0, args.candidates, 8):
                gaits = rng.uniform(-1, 1, size=(8, npar))
                t0 = time.time()
                res = evaluate(pool, gaits, args, n_obj, first=i)
                for j, (p, r) in enumerate(zip(gaits, res)):
                    finger = (i + j) % 4 if args.one_finger else None
                    log.write(json.dumps(dict(meta=meta, p=p.tolist(), finger=finger, r=r.tolist())) + "\n")
                log.flush()
                print(f"gaits {i + 8}/{args.candidates} ({time.time() - t0:.0f} s): dropped {res[:, :, 6].mean():.0%}",
                      flush=True)
            return
        comp, sign = "xyz".index(args.refine[0]), 1.0 if args.refine[1] == "+" else -1.0
        from unicross.config import load_config
        sc = load_config("task")["success"]
        # accumulated rotation (columns 0-2) in success angles, or displacement (3-5) in success distances
        col, unit = (comp, sc["rotate_angle"]) if args.skill == "rotate" else (3 + comp, sc["translate_dist"])

        hold = (col, sign, unit) if args.hold else None

        def scores(res):  # per gait: mean over its episodes, a drop -1
            return np.where(res[:, :, 6] > 0, -1.0, (sign * res[:, :, col] / unit).clip(-2, 2)).mean(1)

        def hold_scores(res):  # --hold: a success 1 (exceeded, never dropped), else half the motion, a drop -0.5
            dropped, ok = res[:, :, 6] > 0, res[:, :, 8] > 0
            partial = 0.5 * (sign * res[:, :, col] / unit).clip(-1, 1)
            return np.where(dropped, -0.5, np.where(ok, 1.0, partial)).mean(1)

        mu, sig, pop = np.zeros(npar), np.full(npar, args.sigma), 16
        first = None
        if args.init and hold:  # the first generation: the logged gaits that moved the object furthest,
            ps, rs = init_gaits(args.init, args.amplitude, args.init_reversed, args.hand)  # drops ignored (holding might have prevented them)
            reach = (sign * rs[:, :, col] / unit).clip(-1, 1).mean(1)
            first = ps[np.argsort(-reach)[:pop]]
            print(f"first generation: the {pop} gaits of {len(ps)} in {args.init} that moved the object furthest "
                  f"(mean reach {np.sort(reach)[-pop:].mean():.2f} success units)", flush=True)
        elif args.init:
            ps, rs = init_gaits(args.init, args.amplitude, args.init_reversed, args.hand)
            s0 = scores(rs)
            mu = ps[int(np.argmax(s0))]
            print(f"starting from the best gait of {args.init} (score {s0.max():.3f})", flush=True)
        for g in range(args.generations):
            gaits = np.clip(mu + sig * rng.standard_normal((pop, npar)), -1, 1)
            gaits[0] = mu
            if g == 0 and first is not None:
                gaits = first
            pairs = sampled_pairs(rng, n_obj, args.sample, g) if args.sample else None
            res = evaluate(pool, gaits, args, n_obj, hold=hold, pairs=pairs)
            score = hold_scores(res) if hold else scores(res)
            elite = np.argsort(-score)[:pop // 4]
            mu, sig = gaits[elite].mean(0), np.maximum(gaits[elite].std(0), 0.05)
            if g == 0 and first is not None:  # unrelated gaits: their mean is none of them; go on from the best
                mu, sig = gaits[elite[0]], np.full(npar, args.sigma)
            for p, r, s in zip(gaits, res, score):
                log.write(json.dumps(dict(meta=meta, generation=g, p=p.tolist(), r=r.tolist(), score=float(s),
                                          **({"pairs": pairs} if pairs else {}))) + "\n")
            log.flush()
            print(f"generation {g}: best score {score.max():.3f} (the mean gait {score[0]:.3f}), "
                  f"its {'rotation' if args.skill == 'rotate' else 'displacement'} "
                  f"{np.round(res[elite[0], :, col], 3).tolist()}, dropped {res[elite[0], :, 6].mean():.0%}"
                  + (f", succeeded {(res[elite[0], :, 8] * (1 - res[elite[0], :, 6])).mean():.0%}" if hold else ""),
                  flush=True)
        if hold and args.select:  # the best distinct gaits on new starts: the choice of gait is not the luck of 8 episodes
            rows = [json.loads(line) for line in open(args.out)]
            rows = [r for r in rows if "score" in r and not r.get("selection")
                    and r.get("meta", {}).get("refine") == args.refine]
            rows = sorted({tuple(r["p"]): r for r in rows}.values(), key=lambda r: -r["score"])[:args.select]
            cand = np.array([r["p"] for r in rows])
            res = evaluate(pool, cand, args, n_obj, hold=hold, seeds=range(args.seeds, args.seeds + args.select_seeds))
            ok = ((res[:, :, 8] > 0) & (res[:, :, 6] == 0)).mean(1)
            for p, r, row, s in zip(cand, res, rows, ok):
                log.write(json.dumps(dict(meta=meta, selection=True, p=p.tolist(), r=r.tolist(), score=row["score"],
                                          success=float(s))) + "\n")
            log.flush()
            print(f"selection on {res.shape[1]} new starts: success {np.round(ok, 3).tolist()} "
                  f"(search scores {[round(r['score'], 3) for r in rows]})", flush=True)


if __name__ == "__main__":
    main()
