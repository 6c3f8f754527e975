"""Cross-entropy search over constant-rate finger sequences (unicross.sequences) for a hand's translate mode.

Each candidate is one rate pair per finger: the whole finger's joints (``FINGER:K``, K its joint count)
move ``r_all`` rad per control step along the closing direction (negative opens) and its two distal joints
``r_distal`` more, for the whole episode: a constant action, which a network fitted to it can represent.
Each candidate runs ``unicross eval --policy seq:SPEC`` on the first 4 training objects per group x 2 starts
(16 episodes; generation g uses ``--seed 100+g``), scored per episode 1 for a success, 0 for a drop, else
0.2 * min(translation / 5 cm, 1); the next generation's mean and spread are those of the best quarter.

    python docs/runs/translate_hands/zm_sharpa/search.py sharpa_wave z- 6 12 \
        index:4,middle:4,ring:4,pinky:5,thumb:5 \
        0.017,0.019,0.015,-0.009,0.023,0.012,0.022,-0.007,-0.016,-0.017 OUTDIR --sigma 0.008

(2026-11-28: Sharpa Wave's search ran an earlier copy of this file with the same sampling, scoring and update and
the output folder fixed in the code, its log is ``search.jsonl``; MANO's (``../zm_mano/``) and Allegro's
(``docs/runs/translate_zm_reference/constant_rate_search/``) ran this file).
"""
import argparse
import hashlib
import json
import os
import subprocess

import numpy as np

ap = argparse.ArgumentParser()
ap.add_argument("hand")
ap.add_argument("axis")
ap.add_argument("generations", type=int)
ap.add_argument("population", type=int)
ap.add_argument("fingers", help="FINGER:K,... (K: the finger's joint count)")
ap.add_argument("init", help="initial mean: r_all,r_distal per finger")
ap.add_argument("outdir")
ap.add_argument("--sigma", type=float, default=0.012)
args = ap.parse_args()
fingers = args.fingers.split(",")
rng = np.random.default_rng(0)
mu = np.array([float(x) for x in args.init.split(",")])
sigma = np.full_like(mu, args.sigma)
os.makedirs(os.path.join(args.outdir, "runs"), exist_ok=True)
log = open(os.path.join(args.outdir, "search.jsonl"), "a")


def spec_of(x):
    terms = []
    for i, f in enumerate(fingers):
        name, k = f.split(":")
        if abs(x[2 * i]) >= 0.002:
            terms.append(f"{name}:{k}:{x[2 * i]:.3f}:0:1000")
        if abs(x[2 * i + 1]) >= 0.002:
            terms.append(f"{name}:2:{x[2 * i + 1]:.3f}:0:1000")
    return "+".join(terms) or "zero"


def run(spec, seed, limit=4, trials=2):
    h = hashlib.md5(f"{spec}{args.hand}{args.axis}{seed}{limit}{trials}".encode()).hexdigest()[:12]
    out = os.path.join(args.outdir, "runs", f"cem_{args.hand}_{h}.json")
    if not os.path.exists(out):
        subprocess.run(["unicross", "eval", "--policy", spec if spec == "zero" else "seq:" + spec, "--hand", args.hand,
                        "--protocol", "translate", "--axis", args.axis, "--objects", "train", "--limit", str(limit),
                        "--trials-per-object", str(trials), "--seed", str(seed), "--workers", "2", "--out", out],
                       capture_output=True, check=True)
    d = json.load(open(out))
    tr = d["trials"]["translate"]
    score = np.mean([1.0 if t["success"] else (0.0 if t["dropped"] else 0.2 * min(max(t["translation_cm"], 0) / 5, 1))
                     for t in tr])
    return score, d["summaries"]["translate"]["sr"], sum(t["dropped"] for t in tr)


for g in range(args.generations):
    xs = [mu] + [np.clip(mu + sigma * rng.standard_normal(mu.shape), -0.04, 0.06) for _ in range(args.population - 1)]
    res = []
    for x in xs:
        spec = spec_of(x)
        s, sr, dr = run(spec, seed=100 + g)
        res.append((s, sr, dr, x, spec))
        log.write(json.dumps({"gen": g, "score": s, "sr": sr, "drops": dr, "x": list(map(float, x)), "spec": spec}) + "\n")
        log.flush()
    res.sort(key=lambda r: -r[0])
    elite = np.array([r[3] for r in res[:max(2, args.population // 4)]])
    mu, sigma = elite.mean(0), np.maximum(elite.std(0), 0.003)
    print(f"gen {g}: best {res[0][0]:.3f} sr {res[0][1]:.1f} drops {res[0][2]} | {res[0][4]} | "
          f"mean-sr {np.mean([r[1] for r in res]):.1f}", flush=True)
print("final mu", spec_of(mu), flush=True)
