"""The report's test cells and long horizon (as docs/runs/student_ft_1202b/seed_cells.py) for a checkpoint whose finger
actions under BAND (action units) are zeroed at every step: a diagnostic of what a dead band costs the other modes.

    python docs/runs/student_xp_drift/deadband_cells.py CHECKPOINT BAND OUT.json [--modes M ...] [--chain]

One process (the wrapper lives in this process, so the report's workers are 1); split the modes over two calls to use
two cores. --chain also runs the long horizon.
"""
import argparse
import json

import torch

import unicross.evaluation as E
from band import zero_small_finger_actions
from unicross import formulation as F
from unicross.report import PaperReport

p = argparse.ArgumentParser()
p.add_argument("spec")
p.add_argument("band", type=float)
p.add_argument("out")
p.add_argument("--modes", nargs="*", default=list(F.MODES))
p.add_argument("--chain", action="store_true")
args = p.parse_args()
_resolve = E.resolve_policy


def banded(fn):
    return lambda obs, u: zero_small_finger_actions(fn(obs, u), args.band)


def resolve(spec, hand, seed=0):
    fn, desc = _resolve(spec, hand, seed=seed)
    return (banded(fn) if spec == args.spec else fn), dict(desc, deadband=args.band)


E.resolve_policy = resolve
torch.set_num_threads(1)
rep = PaperReport(hand="allegro", limit=10, trials=3, workers=1, seed=0, min_trials=100)
out = {"checkpoint": args.spec, "deadband": args.band, "test": {}}
for mode in args.modes:
    cell = rep.evaluate(mode, args.spec, "test")
    out["test"][mode] = dict(cell=cell, summary=rep.summaries[(mode, args.spec, "test", False)])
    print(mode, cell, flush=True)
if args.chain:
    print("\n".join(rep.chain("student", resolve(args.spec, "allegro")[0])), flush=True)
    out["long_horizon"] = rep.chain_summaries["student"]
json.dump(out, open(args.out, "w"), indent=1, default=float)
