"""Finger sequences (``unicross.sequences``) that turn a held object about an axis: a structured screen, then a
cross-entropy search per axis.

Why sequences and not gaits: a sequence's action is a function of the joint command (its phase-2 trigger is a command
threshold, which the observation shows), and once its joints reach their limits the fingers stay still, so it stops
by itself. The translate z- clones copy their sequences almost exactly (80.8% of the full test protocol against their
teacher's 80.5%), where the rotate clones keep a third or less of their clock gaits' success
(``docs/record/rotation_gaits.md``).

A sequence ignores the observation, so one rollout scores all six axes: each episode runs the rotate protocol's
conditions (a start of the shipped grasp dataset, 400 steps, a drop ends it) and records the object's turn about x, y
and z of the hand frame. Score per episode and axis: 1 for a success (turned past pi/2 about the axis, never dropped),
0 for a drop, else 0.2 * clip(turn / (pi/2), 0, 1).

A candidate is 16 rates (rad per control step, negative opens): per finger (index, middle, ring, thumb) a whole-finger
rate (``FINGER:4``) and a two-distal-joint rate (``FINGER:2``), once from the episode's start (phase 1) and once from
the first step at which ``--trigger``'s most distal joint command reaches its threshold (phase 2).

    python search.py screen OUT            # the thumb against one other finger, both signs, three rates
    python search.py screen OUT --set pairs  # two fingers against each other; three against the thumb
    python search.py search OUT --axis x+  # cross-entropy from the screen's best for x+, then the selection
    python search.py select OUT --specs F  # each sequence of F on the selection's episodes, all six axes

``search``: ``--generations`` of ``--population`` candidates around the elite's mean (a quarter), the first generation
around the screen's best for the axis (sigma ``--sigma``); each generation draws ``--per-group`` boxes and as many
cylinders of the 200 wrappable training objects anew x ``--starts`` starts, the same for every candidate of that
generation. Then the ``--select`` best distinct candidates on the first ``--select-limit`` training objects per group
x ``--select-starts`` starts (seed 500), written to ``selection_AXIS.jsonl``. Commands run: ``README.md``.
"""
import argparse
import json
import math
import multiprocessing as mp
import os

import numpy as np

FINGERS = ["index", "middle", "ring", "thumb"]
AXES = ["x+", "x-", "y+", "y-", "z+", "z-"]


def spec_of(x, trigger):
    terms = []
    for phase, window in ((0, "0:1000"), (1, trigger)):
        for i, f in enumerate(FINGERS):
            for j, k in enumerate(("4", "2")):
                r = x[8 * phase + 2 * i + j]
                if abs(r) >= 0.002:
                    terms.append(f"{f}:{k}:{r:.3f}:{window}")
    return "+".join(terms) or "index:4:0.000:0:1"


def rollout(job):
    """Per episode of the sequence ``spec`` on training objects ``names`` x ``trials`` starts: (dropped, the largest
    turn reached about each of AXES, the final turn about each)."""
    spec, seed, names, trials = job
    import gymnasium as gym
    import torch

    import unicross  # noqa: F401  (registers the tasks)
    from unicross import metrics as M
    from unicross import registry as R
    from unicross.grasps import GraspSet, default_grasp_path
    from unicross.objects import get_object_set
    from unicross.seeding import trial_seed
    from unicross.sequences import make_sequence_policy
    torch.set_num_threads(1)
    sk = R.skill("rotate")
    gs = GraspSet.load(default_grasp_path("allegro"))
    train = [o.name for o in get_object_set("train")]  # an episode's seed: its object's index here, and its start
    objs = [o for o in get_object_set("train") if o.name in set(names)]
    axes = torch.tensor([R.axis_vector(a) for a in AXES], dtype=torch.float32)
    policy = make_sequence_policy(spec)
    out = []
    for obj in objs:
        env = gym.make(sk.env_id, obs_mode="state_dict", sim_backend="physx_cpu", render_backend="none",
                       hand="allegro", objects=[obj], randomize=False, grasp_dataset=gs,
                       config=dict(episode_length={"rotate": sk.protocol_steps}), **sk.env_kwargs("x+"))
        u = env.unwrapped
        for k in range(trials):
            obs, _ = u.reset(seed=trial_seed(seed, train.index(obj.name), k))
            q, dropped = [u.cur_rel.q_oh.clone()], False
            for _ in range(sk.protocol_steps):
                obs, _, term, _, info = u.step(policy(obs, u))
                q.append(u.cur_rel.q_oh.clone())
                dropped |= bool(info["drop"][0])
                if bool(term.all()):
                    break
            q = torch.stack(q, 1).expand(len(AXES), -1, 4)
            series = M.rotation_series(q, axes)  # [6, T]
            out.append((dropped, series.max(1).values.tolist(), series[:, -1].tolist()))
        env.close()
    return out


def scores(episodes, threshold=math.pi / 2):
    """Per axis of AXES: (mean score, successes, drops) of rollout()'s episodes."""
    res = []
    for i in range(len(AXES)):
        s = [0.0 if d else (1.0 if mx[i] > threshold else 0.2 * min(max(end[i], 0) / threshold, 1))
             for d, mx, end in episodes]
        res.append((float(np.mean(s)), sum(1 for d, mx, _ in episodes if not d and mx[i] > threshold),
                    sum(d for d, _, _ in episodes)))
    return res


def run(pool, spec, seed, names, trials, workers):
    parts = pool.map(rollout, [(spec, seed, names[i::workers], trials) for i in range(workers)])
    return [e for p in parts for e in p]


def screen_candidates(which="thumb"):
    """Screen candidates, phase 2 empty. ``thumb``: the thumb (whole finger or its two distal joints) against one
    other finger (the same), in opposite directions, both ways round, at 0.01, 0.02 and 0.04 rad a step
    (2 x 3 x 2 x 2 x 3 = 72). ``pairs``: two of index, middle and ring against each other the same way (3 x 4 x 2 x 2
    = 48, at 0.01 and 0.03), then the three together against the thumb (2 x 2 x 2 x 2 = 16)."""
    xs = []
    if which == "thumb":
        for r in (0.01, 0.02, 0.04):
            for sign in (1, -1):
                for tk in (0, 1):
                    for f in (0, 1, 2):
                        for fk in (0, 1):
                            x = np.zeros(16)
                            x[6 + tk] = sign * r
                            x[2 * f + fk] = -sign * r
                            xs.append(x)
        return xs
    for r in (0.01, 0.03):
        for sign in (1, -1):
            for f, g in ((0, 1), (0, 2), (1, 2)):
                for fk in (0, 1):
                    for gk in (0, 1):
                        x = np.zeros(16)
                        x[2 * f + fk] = sign * r
                        x[2 * g + gk] = -sign * r
                        xs.append(x)
        for sign in (1, -1):
            for fk in (0, 1):
                for tk in (0, 1):
                    x = np.zeros(16)
                    x[[fk, 2 + fk, 4 + fk]] = sign * r
                    x[6 + tk] = -sign * r
                    xs.append(x)
    return xs


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("what", choices=["screen", "search", "select"])
    ap.add_argument("--specs", help="select: a file of sequences, one per line")
    ap.add_argument("outdir")
    ap.add_argument("--axis", choices=AXES, help="search: the axis")
    ap.add_argument("--set", default="thumb", choices=["thumb", "pairs"], help="screen: which candidates")
    ap.add_argument("--trigger", default="@thumb:1.0", help="phase 2's start: @FINGER:THETA (rad, distal command)")
    ap.add_argument("--generations", type=int, default=6)
    ap.add_argument("--population", type=int, default=12)
    ap.add_argument("--sigma", type=float, default=0.01, help="the first generation's spread around the screen's best")
    ap.add_argument("--per-group", type=int, default=8, help="objects drawn per group (box, cylinder) per generation")
    ap.add_argument("--starts", type=int, default=2, help="starts per drawn object")
    ap.add_argument("--select", type=int, default=6)
    ap.add_argument("--select-limit", type=int, default=20, help="training objects per group in the selection")
    ap.add_argument("--select-starts", type=int, default=2, help="starts per object in the selection")
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args()
    if a.what == "search" and a.axis is None:
        ap.error("search needs --axis")
    os.makedirs(a.outdir, exist_ok=True)
    rng = np.random.default_rng(0)
    from unicross.objects import get_object_set
    objs = [o for o in get_object_set("train") if o.category == "wrappable"]
    boxes = [o.name for o in objs if o.shape == "box"]
    cyls = [o.name for o in objs if o.shape == "cylinder"]
    pool = mp.get_context("spawn").Pool(a.workers)
    screen_path = os.path.join(a.outdir, "screen.jsonl")
    if a.what == "screen":
        names = boxes[:a.per_group] + cyls[:a.per_group]
        done = {json.loads(line)["spec"] for line in open(screen_path)} if os.path.exists(screen_path) else set()
        with open(screen_path, "a") as log:
            for x in screen_candidates(a.set):
                spec = spec_of(x, a.trigger)
                if spec in done:
                    continue
                sc = scores(run(pool, spec, 100, names, a.starts, a.workers))
                log.write(json.dumps({"spec": spec, "x": list(map(float, x)), "objects": names,
                                      "axes": {ax: dict(score=s, successes=ok, drops=dr)
                                               for ax, (s, ok, dr) in zip(AXES, sc)}}) + "\n")
                log.flush()
                print(" ".join(f"{ax} {ok:2d}" for ax, (_, ok, _) in zip(AXES, sc)), f"drops {sc[0][2]:2d} | {spec}",
                      flush=True)
        return
    if a.what == "select":  # every spec of --specs on the selection's episodes, scored on all six axes
        sel = boxes[:a.select_limit] + cyls[:a.select_limit]
        specs = [line.strip() for line in open(a.specs) if line.strip()]
        path = os.path.join(a.outdir, "select_all.jsonl")
        done = {json.loads(line)["spec"] for line in open(path)} if os.path.exists(path) else set()
        with open(path, "a") as log:
            for spec in specs:
                if spec in done:
                    continue
                eps = run(pool, spec, 500, sel, a.select_starts, a.workers)
                sc = scores(eps)
                log.write(json.dumps({"spec": spec, "n": len(eps), "axes": {ax: dict(score=s, successes=ok, drops=dr)
                                      for ax, (s, ok, dr) in zip(AXES, sc)}}) + "\n")
                log.flush()
                print(" ".join(f"{ax} {ok:2d}" for ax, (_, ok, _) in zip(AXES, sc)),
                      f"drops {sc[0][2]:2d} of {len(eps)} | {spec}", flush=True)
        return
    ai = AXES.index(a.axis)
    screen = [json.loads(line) for line in open(screen_path)]
    start = max(screen, key=lambda r: r["axes"][a.axis]["score"])
    mu, sigma = np.array(start["x"]), np.full(16, a.sigma)
    path = os.path.join(a.outdir, f"search_{a.axis}.jsonl")
    rows = [json.loads(line) for line in open(path)] if os.path.exists(path) else []
    with open(path, "a") as log:
        for g in range(a.generations):
            names = (list(rng.choice(boxes, a.per_group, replace=False))
                     + list(rng.choice(cyls, a.per_group, replace=False)))
            xs = [mu] + [np.clip(mu + sigma * rng.standard_normal(16), -0.1, 0.1) for _ in range(a.population - 1)]
            done = {r["spec"]: r for r in rows if r["gen"] == g}
            res = []
            for x in xs:
                spec = spec_of(x, a.trigger)
                if spec not in done:
                    s, ok, dr = scores(run(pool, spec, 200 + g, names, a.starts, a.workers))[ai]
                    done[spec] = {"gen": g, "score": s, "successes": ok, "drops": dr, "n": 2 * a.per_group * a.starts,
                                  "spec": spec, "x": list(map(float, x)), "objects": names}
                    rows.append(done[spec])
                    log.write(json.dumps(done[spec]) + "\n")
                    log.flush()
                res.append(done[spec])
            res.sort(key=lambda r: -r["score"])
            elite = np.array([r["x"] for r in res[:max(2, len(res) // 4)]])
            mu, sigma = elite.mean(0), np.maximum(elite.std(0), 0.003)
            print(f"gen {g}: best {res[0]['score']:.3f} ({res[0]['successes']}/{res[0]['n']}, drops {res[0]['drops']}) "
                  f"mean {np.mean([r['score'] for r in res]):.3f} | {res[0]['spec']}", flush=True)
    seen, best = set(), []
    for r in sorted(rows + [dict(spec=start["spec"], score=None)], key=lambda r: -(r["score"] or 0)):
        if r["spec"] not in seen:
            seen.add(r["spec"])
            best.append(r)
    cands = best[:a.select] + ([] if any(r["spec"] == start["spec"] for r in best[:a.select])
                               else [dict(spec=start["spec"], score=None)])
    sel = boxes[:a.select_limit] + cyls[:a.select_limit]
    with open(os.path.join(a.outdir, f"selection_{a.axis}.jsonl"), "w") as f:
        for r in cands:
            eps = run(pool, r["spec"], 500, sel, a.select_starts, a.workers)
            s, ok, dr = scores(eps)[ai]
            f.write(json.dumps({"spec": r["spec"], "search_score": r["score"], "score": s, "successes": ok,
                                "drops": dr, "n": len(eps)}) + "\n")
            f.flush()
            print(f"selection {ok}/{len(eps)} drops {dr} | search score {r['score']} | {r['spec']}", flush=True)


if __name__ == "__main__":
    main()
