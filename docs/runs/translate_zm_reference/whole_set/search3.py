"""Cross-entropy search of the whole two-phase translate z- sequence on starts drawn from every training stick (rule.txt).

A candidate is 16 rates (rad per control step, negative opens): per finger (index, middle, ring, thumb) a whole-finger
rate (``FINGER:4``) and a two-distal-joint rate (``FINGER:2``), once from the episode's start (phase 1) and once from the
first step at which the index's most distal joint command reaches 1.5 rad (phase 2, a state trigger the observation
shows; ``unicross.sequences``). The start is the shipped expert's sequence (``../second_phase/chosen.txt``).

Unlike ``../second_phase/search2.py`` (the first 8 training objects per group, the same 32 starts in every generation),
each generation draws ``--per-group`` boxes and as many cylinders of the 200 training sticks anew x ``--starts`` starts,
the same starts for every candidate of that generation: the full test protocol (every test stick) is what the shipped sequence misses.
Score per episode as search2.py: 1 for a success, 0 for a drop, else 0.2 * min(translation / 5 cm, 1).
Then ``--select K``: the K best distinct candidates and the start alone on every training stick x ``--select-starts``
starts (seed 500).

    python search3.py ../second_phase/chosen.txt OUTDIR [--generations 6 --population 16 --select 6]   # rule.txt 1-2
    python search3.py ../second_phase/chosen.txt OUTDIR --generations 8 --per-group 24 --sigma1 0.004 \
        --sigma2 0.008 --select-starts 2                                                             # rule.txt 6
    python search3.py ../second_phase/chosen.txt OUTDIR --max-width 0.049 --generations 8 --per-group 12 --starts 4 \
        --sigma1 0.006 --sigma2 0.010 --select-starts 4                                 # ../thickness/rule.txt 1-2
"""
import argparse
import json
import multiprocessing as mp
import os

import numpy as np

FINGERS = ["index", "middle", "ring", "thumb"]
TRIGGER = "@index:1.5"


def params_of(spec):
    """The 16 rates of a two-phase sequence written in this file's terms (others raise)."""
    x = np.zeros(16)
    for term in spec.split("+"):
        f, k, rate, start, end = term.split(":")
        phase = 1 if start.startswith("@") else 0
        x[8 * phase + 2 * FINGERS.index(f) + (k == "2")] += float(rate)
    return x


def spec_of(x):
    terms = []
    for phase, window in ((0, "0:1000"), (1, TRIGGER)):
        for i, f in enumerate(FINGERS):
            for j, k in enumerate(("4", "2")):
                r = x[8 * phase + 2 * i + j]
                if abs(r) >= 0.002:
                    terms.append(f"{f}:{k}:{r:.3f}:{window}")
    return "+".join(terms)


def evaluate(job):
    spec, seed, names, trials = job
    import torch

    import unicross  # noqa: F401  (registers the tasks)
    from unicross import evaluation as E
    from unicross.objects import get_object_set
    from unicross.sequences import make_sequence_policy
    torch.set_num_threads(1)
    names = set(names)
    objs = [o for o in get_object_set("train") if o.name in names]
    tr = E.run_protocol("translate", make_sequence_policy(spec), objs, trials_per_object=trials, seed=seed,
                        axes=["z-"], progress=False)
    score = float(np.mean([1.0 if t["success"] else (0.0 if t["dropped"] else
                                                     0.2 * min(max(t["translation_cm"], 0) / 5, 1)) for t in tr]))
    return score, sum(t["success"] for t in tr), sum(t["dropped"] for t in tr), len(tr)


def sticks(max_width=None):
    """The training sticks, or with ``max_width`` those whose smaller cross-section width (m) is under it."""
    from unicross.objects import get_object_set
    return [o.name for o in get_object_set("train") if o.category == "elongated"
            and (max_width is None or min(o.dims[1:]) < max_width)]


def run(pool, spec, seed, names, trials, workers):
    parts = pool.map(evaluate, [(spec, seed, names[i::workers], trials) for i in range(workers)])
    n = sum(p[3] for p in parts)
    return (sum(p[0] * p[3] for p in parts) / n, sum(p[1] for p in parts), sum(p[2] for p in parts), n)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("start")
    ap.add_argument("outdir")
    ap.add_argument("--generations", type=int, default=6)
    ap.add_argument("--population", type=int, default=16)
    ap.add_argument("--sigma1", type=float, default=0.008, help="starting spread of the phase-1 rates")
    ap.add_argument("--sigma2", type=float, default=0.012, help="starting spread of the phase-2 rates")
    ap.add_argument("--per-group", type=int, default=12, help="sticks drawn per group (box, cylinder) per generation")
    ap.add_argument("--starts", type=int, default=2, help="starts per drawn stick")
    ap.add_argument("--select", type=int, default=6)
    ap.add_argument("--select-starts", type=int, default=1, help="starts per training stick in the selection")
    ap.add_argument("--max-width", type=float, default=None,
                    help="search and select on the sticks thinner than this (m, smaller cross-section width) only")
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args()
    start = open(a.start).read().strip()
    os.makedirs(a.outdir, exist_ok=True)
    rng = np.random.default_rng(0)
    mu = params_of(start)
    sigma = np.array([a.sigma1] * 8 + [a.sigma2] * 8)
    all_sticks = sticks(a.max_width)
    boxes = [s for s in all_sticks if "-box-" in s]
    cyls = [s for s in all_sticks if "-cylinder-" in s]
    path = os.path.join(a.outdir, "search.jsonl")
    rows = [json.loads(line) for line in open(path)] if os.path.exists(path) else []
    pool = mp.get_context("spawn").Pool(a.workers)
    with open(path, "a") as log:
        for g in range(a.generations):
            names = (list(rng.choice(boxes, a.per_group, replace=False))
                     + list(rng.choice(cyls, a.per_group, replace=False)))
            xs = [mu] + [np.clip(mu + sigma * rng.standard_normal(mu.shape), -0.1, 0.1)
                         for _ in range(a.population - 1)]
            done = {r["spec"]: r for r in rows if r["gen"] == g}
            res = []
            for x in xs:
                spec = spec_of(x)
                if spec not in done:
                    score, ok, drops, n = run(pool, spec, 200 + g, names, a.starts, a.workers)
                    done[spec] = {"gen": g, "score": score, "successes": ok, "drops": drops, "n": n, "spec": spec,
                                  "x": list(map(float, x)), "objects": names}
                    rows.append(done[spec])
                    log.write(json.dumps(done[spec]) + "\n")
                    log.flush()
                res.append(done[spec])
            res.sort(key=lambda r: -r["score"])
            elite = np.array([r["x"] for r in res[:max(2, a.population // 4)]])
            mu, sigma = elite.mean(0), np.maximum(elite.std(0), 0.003)
            print(f"gen {g}: best {res[0]['score']:.3f} ({res[0]['successes']}/{res[0]['n']}, drops {res[0]['drops']}) "
                  f"mean {np.mean([r['score'] for r in res]):.3f} | {res[0]['spec']}",
                  flush=True)
    seen, best = {start}, []
    for r in sorted(rows, key=lambda r: -r["score"]):
        if r["spec"] not in seen:
            seen.add(r["spec"])
            best.append(r)
    cands = [(r["spec"], r["score"]) for r in best[:a.select]] + [(start, None)]
    with open(os.path.join(a.outdir, "selection.jsonl"), "w") as f:
        for s, sc in cands:
            score, ok, drops, n = run(pool, s, 500, all_sticks, a.select_starts, a.workers)
            f.write(json.dumps({"spec": s, "search_score": sc, "successes": ok, "drops": drops, "n": n}) + "\n")
            f.flush()
            print(f"selection {ok}/{n} drops {drops} | search score {sc} | {s if sc is not None else 'the start'}",
                  flush=True)


if __name__ == "__main__":
    main()
