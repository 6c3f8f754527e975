"""How far is each student from the rotate y+ expert, on the expert's states and on its own? A diagnosis of the y+
cell that every x+-heavy student stage loses (README, "Rotate y+ across the recipes"); it chooses nothing.

    python docs/runs/student_l1/yplus_labels.py ACTOR OUT.json --labellers A [B ...] [--objects test --limit 10 --trials 5]

ACTOR acts on the rotate protocol's y+ trials of the report's cell (test objects, the first 10 per group, 5 trials
each, as the report raises the cell to its 100 trials); every labeller answers the same observations, and the per-step
squared difference between its action and the actor's is averaged over the 16 finger joints (the wrist's six are left
out, as in docs/runs/student_xp_drift/drift.py), over all steps and over the first 50 (near the shared grasp starts,
before the actors' states part).
"""
import argparse
import json

import torch

import unicross.evaluation as E
from unicross.evaluation import protocol_objects, resolve_policy, run_protocol
from unicross.objects import get_object_set

p = argparse.ArgumentParser()
p.add_argument("actor")
p.add_argument("out")
p.add_argument("--labellers", nargs="+", required=True)
p.add_argument("--objects", default="test")
p.add_argument("--limit", type=int, default=10)
p.add_argument("--trials", type=int, default=5)
p.add_argument("--seed", type=int, default=0)
p.add_argument("--axis", default="y+")
args = p.parse_args()

act_fn, _ = resolve_policy(args.actor, "allegro")
labellers = {name: resolve_policy(name, "allegro")[0] for name in args.labellers}
FINGERS = slice(6, 22)
EARLY = 50
steps = []                  # per step of the current trial: {labeller: squared error over the fingers}


def policy(obs, u):
    a = act_fn(obs, u)
    with torch.no_grad():
        steps.append({k: float(((f(obs, u)[0, FINGERS] - a[0, FINGERS]) ** 2).mean()) for k, f in labellers.items()})
    return a


per_trial = []
_score = E._score


def score(*a, **k):
    out = _score(*a, **k)
    out["mse"] = {k: sum(s[k] for s in steps) / len(steps) for k in labellers}
    out["mse_early"] = {k: sum(s[k] for s in steps[:EARLY]) / len(steps[:EARLY]) for k in labellers}
    out["steps"] = len(steps)
    steps.clear()
    per_trial.append(out)
    return out


E._score = score
chosen, _ = protocol_objects("rotate", get_object_set(args.objects, limit=args.limit), "allegro")
run_protocol("rotate", policy, chosen, trials_per_object=args.trials, seed=args.seed, axes=[args.axis], progress=False)
n = len(per_trial)
summ = dict(actor=args.actor, axis=args.axis, objects=args.objects, limit=args.limit, trials=args.trials, seed=args.seed,
            n=n, successes=sum(t["success"] for t in per_trial), dropped=sum(t["dropped"] for t in per_trial),
            mse={k: sum(t["mse"][k] for t in per_trial) / n for k in labellers},
            mse_early={k: sum(t["mse_early"][k] for t in per_trial) / n for k in labellers})
json.dump(dict(summary=summ, trials=per_trial), open(args.out, "w"), indent=1)
print(json.dumps(summ, indent=1))
