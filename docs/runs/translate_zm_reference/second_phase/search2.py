"""Cross-entropy search for a second phase of a translate finger sequence (rule.txt; README section 1).

A candidate is the base sequence unchanged plus, per finger, a rate pair (``FINGER:K`` whole finger, ``FINGER:2`` its
two distal joints; rad per control step along the closing direction, negative opens) active from the first step at
which the trigger finger's most distal joint command reaches THETA (``unicross.sequences``' state trigger, which the
observation shows). Scored per episode as ``../../translate_hands/zm_sharpa/search.py`` scores: 1 for a success, 0 for
a drop, else 0.2 * min(translation / 5 cm, 1), on the first 8 training objects per group x 2 starts (generation g:
seed 100 + g); the next generation's mean and spread are those of the best quarter. Then ``--select K`` runs the K best
distinct candidates and the base alone on the first 20 training objects per group x 2 starts, seed 500.

    python search2.py BASE_SPEC_FILE OUTDIR [--generations 6 --population 12 --sigma 0.03 --theta 1.5 --select 6]
"""
import argparse
import json
import multiprocessing as mp
import os

import numpy as np

FINGERS = ["index:4", "middle:4", "ring:4", "thumb:4"]


def spec_of(base, x, trigger, theta):
    terms = [base]
    for i, f in enumerate(FINGERS):
        name, k = f.split(":")
        if abs(x[2 * i]) >= 0.002:
            terms.append(f"{name}:{k}:{x[2 * i]:.3f}:@{trigger}:{theta}")
        if abs(x[2 * i + 1]) >= 0.002:
            terms.append(f"{name}:2:{x[2 * i + 1]:.3f}:@{trigger}:{theta}")
    return "+".join(terms)


def evaluate(job):
    spec, seed, limit, trials = job
    import torch

    import unicross  # noqa: F401  (registers the tasks)
    from unicross import evaluation as E
    from unicross.objects import get_object_set
    from unicross.sequences import make_sequence_policy
    torch.set_num_threads(1)
    tr = E.run_protocol("translate", make_sequence_policy(spec), get_object_set("train", limit=limit),
                        trials_per_object=trials, seed=seed, axes=["z-"], progress=False)
    score = float(np.mean([1.0 if t["success"] else (0.0 if t["dropped"] else
                                                     0.2 * min(max(t["translation_cm"], 0) / 5, 1)) for t in tr]))
    return score, sum(t["success"] for t in tr), sum(t["dropped"] for t in tr), len(tr)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("base")
    ap.add_argument("outdir")
    ap.add_argument("--generations", type=int, default=6)
    ap.add_argument("--population", type=int, default=12)
    ap.add_argument("--sigma", type=float, default=0.03)
    ap.add_argument("--theta", type=float, default=1.5)
    ap.add_argument("--trigger", default="index")
    ap.add_argument("--select", type=int, default=6)
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args()
    base = open(a.base).read().strip()
    os.makedirs(a.outdir, exist_ok=True)
    rng = np.random.default_rng(0)
    mu, sigma = np.zeros(2 * len(FINGERS)), np.full(2 * len(FINGERS), a.sigma)
    path = os.path.join(a.outdir, "search.jsonl")
    rows = [json.loads(line) for line in open(path)] if os.path.exists(path) else []
    pool = mp.get_context("spawn").Pool(a.workers)
    with open(path, "a") as log:
        for g in range(a.generations):
            xs = [mu] + [np.clip(mu + sigma * rng.standard_normal(mu.shape), -0.1, 0.1) for _ in range(a.population - 1)]
            done = {r["spec"]: r for r in rows if r["gen"] == g}
            specs = [spec_of(base, x, a.trigger, a.theta) for x in xs]
            todo = [s for s in specs if s not in done]
            for s, (score, ok, drops, n) in zip(todo, pool.map(evaluate, [(s, 100 + g, 8, 2) for s in todo])):
                r = {"gen": g, "score": score, "successes": ok, "drops": drops, "n": n, "spec": s,
                     "x": list(map(float, xs[specs.index(s)]))}
                done[s] = r
                rows.append(r)
                log.write(json.dumps(r) + "\n")
                log.flush()
            res = sorted((done[s] for s in specs), key=lambda r: -r["score"])
            elite = np.array([r["x"] for r in res[:max(2, a.population // 4)]])
            mu, sigma = elite.mean(0), np.maximum(elite.std(0), 0.005)
            print(f"gen {g}: best {res[0]['score']:.3f} ({res[0]['successes']}/{res[0]['n']}, drops {res[0]['drops']}) "
                  f"mean {np.mean([r['score'] for r in res]):.3f} | {res[0]['spec'][len(base) + 1:]}", flush=True)
    seen, best = set(), []
    for r in sorted(rows, key=lambda r: -r["score"]):
        if r["spec"] not in seen:
            seen.add(r["spec"])
            best.append(r)
    cands = [(r["spec"], r["score"]) for r in best[:a.select]] + [(base, None)]
    sel = pool.map(evaluate, [(s, 500, 20, 2) for s, _ in cands])
    with open(os.path.join(a.outdir, "selection.jsonl"), "w") as f:
        for (s, sc), (score, ok, drops, n) in zip(cands, sel):
            f.write(json.dumps({"spec": s, "search_score": sc, "successes": ok, "drops": drops, "n": n}) + "\n")
            print(f"selection {ok}/{n} drops {drops} | search score {sc} | {s[len(base) + 1:] or 'base alone'}", flush=True)


if __name__ == "__main__":
    main()
