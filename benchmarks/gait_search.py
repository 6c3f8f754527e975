"""Search for an open-loop finger gait that does an in-hand mode: is there a scripted motion to start PPO from?

Translate z+ has a physical reference (opening the fingers slides the object out; README "Reward
audit"), and PPO started from it (`model.init_reference`) gives the shipped expert. Rotation and
translate z- have none. This script samples periodic finger motions and measures what they do
to a grasped object, in the task itself (grasp-state starts, random wrist orientation):

    finger f's joints (abduction, MCP, PIP = DIP) follow q0 + bias + amplitude * sin(2 pi t / T + phase),
    with the distal joints shifted by a loop phase (a closed path in joint space), T in 6..36 steps

25 numbers in [-1, 1] per gait (6 per finger and the period), the wrist holding still. Each gait
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

Episodes run in two spawned worker processes, one env per object each.
"""
from __future__ import annotations

import argparse
import gzip
import json
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
NPAR = 6 * 4 + 1
_ENVS = {}


def gait_targets(p, t: int, q0):
    """Finger targets of gait ``p`` ([25] in [-1, 1]) at control step ``t`` from the start command ``q0``."""
    period = 6 + 30 * (p[24] + 1) / 2
    q = q0.clone()
    for f in range(4):
        a_abd, a_mcp, a_dis, ph, loop, bias = (float(v) for v in p[6 * f: 6 * f + 6])
        th = 2 * math.pi * t / period + math.pi * ph
        j = 4 * f
        q[j] += 0.3 * a_abd * math.sin(th)
        q[j + 1] += 0.5 * a_mcp * math.sin(th) + 0.2 * bias
        d = 0.5 * a_dis * math.sin(th + math.pi * loop) + 0.2 * bias
        q[j + 2] += d
        q[j + 3] += d
    return q


def _env(job):
    key = (job["skill"], job["axis"], job["objects"], job["limit"], job["oi"], job["randomize"])
    if key not in _ENVS:
        import gymnasium as gym
        import unicross  # noqa: F401  (registers the tasks)
        from unicross.config import load_config
        from unicross.objects import get_object_set
        from unicross.registry import skill as skill_entry
        from unicross.rl.ppo import env_kwargs_for
        kw = env_kwargs_for(job["skill"], job["axis"], "allegro", load_config("ppo", None)["env"])
        kw.pop("object_limit", None)
        kw.pop("reconfiguration_freq", None)
        kw["randomize"] = job["randomize"]
        obj = get_object_set(job["objects"], limit=job["limit"])[job["oi"]]
        _ENVS[key] = gym.make(skill_entry(job["skill"]).env_id, obs_mode="state", sim_backend="physx_cpu",
                              render_backend="none", num_envs=1, **{**kw, "objects": [obj]})
    return _ENVS[key].unwrapped


def episode(job) -> list:
    """[rotation x, y, z (rad), displacement x, y, z (m), dropped, steps] of one gait episode."""
    import torch
    torch.set_num_threads(1)
    u = _env(job)
    u.reset(seed=job["seed"])
    p = torch.as_tensor(job["p"], dtype=torch.float32)
    p[:24] *= job["amplitude"]
    if job["finger"] is not None:  # one finger moves, the others keep only their bias (tightening or loosening)
        for f in range(4):
            if f != job["finger"]:
                p[6 * f: 6 * f + 3] = 0.0
    q0 = u.command[0, 6:].clone()
    x0 = u.cur_rel.x_oh[0].clone()
    rot = torch.zeros(3)
    dropped, steps = False, 0
    for t in range(job["steps"]):
        a = torch.zeros(1, u.action_scale.shape[0])
        a[0, 6:] = ((gait_targets(p, t + 1, q0) - u.command[0, 6:]) / u.action_scale[6:]).clamp(-1, 1)
        _, _, term, trunc, _ = u.step(a)
        steps += 1
        if bool(term[0]) or bool(u.ever_dropped[0]):
            dropped = True
            break
        rot += u.obj_angvel_h[0] * u.control_dt
        if bool(trunc[0]):
            break
    return rot.tolist() + (u.cur_rel.x_oh[0] - x0).tolist() + [float(dropped), steps]


def evaluate(pool, gaits, args, n_obj, first: int = 0):
    from unicross.seeding import trial_seed
    jobs = [dict(p=p.tolist(), oi=oi, seed=trial_seed(0, oi, k), skill=args.skill, axis=args.axis,
                 objects=args.objects, limit=args.limit, randomize=not args.no_randomize, steps=args.steps,
                 amplitude=args.amplitude, finger=(first + i) % 4 if args.one_finger else None)
            for i, p in enumerate(gaits) for oi in range(n_obj) for k in range(args.seeds)]
    return np.array(pool.map(episode, jobs, chunksize=1)).reshape(len(gaits), n_obj * args.seeds, 8)


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
    ap.add_argument("--init", default=None, help="--refine: start from the best gait of this log (same score)")
    ap.add_argument("--refine", default=None, help="cross-entropy search for motion along / about this axis (x+ ... z-)")
    ap.add_argument("--generations", type=int, default=10)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=None)
    ap.add_argument("--summary", nargs="+", default=None)
    args = ap.parse_args()
    if args.summary:
        return summary(args.summary)
    if args.out is None:
        ap.error("--out is required")
    args.axis = args.axis or ("z-" if args.skill == "translate" else "x+")
    args.objects = args.objects or ("train-elongated" if args.skill == "translate" else "train-wrappable")
    from multiprocessing import get_context
    from unicross.objects import get_object_set
    n_obj = len(get_object_set(args.objects, limit=args.limit))
    rng = np.random.default_rng(args.seed)
    meta = {k: v for k, v in vars(args).items() if k not in ("summary", "out")}
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with get_context("spawn").Pool(2) as pool, open(args.out, "a") as log:
        if args.refine is None:
            for i in range(0, args.candidates, 8):
                gaits = rng.uniform(-1, 1, size=(8, NPAR))
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

        def scores(res):  # per gait: mean over its episodes, a drop -1
            return np.where(res[:, :, 6] > 0, -1.0, (sign * res[:, :, col] / unit).clip(-2, 2)).mean(1)

        mu, sig, pop = np.zeros(NPAR), np.full(NPAR, 0.35), 16
        if args.init:
            rows = [json.loads(line) for line in (gzip.open if args.init.endswith(".gz") else open)(args.init, "rt")]
            s0 = scores(np.array([r["r"] for r in rows]))
            mu = np.array(rows[int(np.argmax(s0))]["p"])
            print(f"starting from the best gait of {args.init} (score {s0.max():.3f})", flush=True)
        for g in range(args.generations):
            gaits = np.clip(mu + sig * rng.standard_normal((pop, NPAR)), -1, 1)
            gaits[0] = mu
            res = evaluate(pool, gaits, args, n_obj)
            score = scores(res)
            elite = np.argsort(-score)[:pop // 4]
            mu, sig = gaits[elite].mean(0), np.maximum(gaits[elite].std(0), 0.05)
            for p, r, s in zip(gaits, res, score):
                log.write(json.dumps(dict(meta=meta, generation=g, p=p.tolist(), r=r.tolist(), score=float(s))) + "\n")
            log.flush()
            print(f"generation {g}: best score {score.max():.3f} (the mean gait {score[0]:.3f}), "
                  f"its {'rotation' if args.skill == 'rotate' else 'displacement'} "
                  f"{np.round(res[elite[0], :, col], 3).tolist()}, dropped {res[elite[0], :, 6].mean():.0%}", flush=True)


if __name__ == "__main__":
    main()
