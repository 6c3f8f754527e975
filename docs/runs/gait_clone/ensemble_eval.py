"""Mean action of several clone networks, rotate protocol held out. Usage: python docs/runs/gait_clone/ensemble_eval.py AXIS LIMIT CKPT [CKPT...]
(test objects, first LIMIT per group x 3 trials, seed 0: the held-out cell of the clones' evaluations)"""
import sys

import torch

import unicross  # noqa: F401  (registers the tasks)
from unicross import evaluation as E
from unicross.objects import get_object_set
from unicross.rl.policy_io import load_policy, policy_fn
torch.set_num_threads(1)
axis, limit, paths = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
fns = [policy_fn(load_policy(p)[0].module[0].module) for p in paths]
def pol(obs, u):
    return torch.stack([f(obs, u) for f in fns]).mean(0)
objs = get_object_set("test", limit=limit)
trials = E.run_protocol("rotate", pol, objs, trials_per_object=3, seed=0, axes=[axis], progress=False)
n, ok = len(trials), sum(t["success"] for t in trials)
print(paths, f"{ok}/{n} = {100*ok/n:.1f}%, drops {sum(t['dropped'] for t in trials)}", flush=True)
