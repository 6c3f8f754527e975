"""The report's long-horizon cells (``PaperReport(limit=10, trials=3, min_trials=100)``'s chains: docs/results.md's
are evaluation seed 0) under other evaluation seeds: the same objects, other initial states and goals. Used by screen
K (rule.txt K1, K2), whose long-horizon bars and cells pool evaluation seeds 0-3.

    python docs/runs/student_l1/chain_seeds.py OUT.json POLICY [--seeds SEED ...]

POLICY is a checkpoint or shipped name (``allegro/student``). Default seeds 1 2 3. OUT.json maps chain -> seed ->
cell, successes, n (the chain's overall success: every phase done).
"""
import argparse
import json

from rotate_seeds import report_at  # this folder (the script's own directory is on sys.path)
from unicross.evaluation import resolve_policy


def chain_cells(spec, seeds):
    """{chain: {seed: dict(cell, successes, n)}} for ``spec``'s long horizon under each evaluation seed."""
    policy = resolve_policy(spec, "allegro")[0]
    out = {}
    for seed in seeds:
        rep = report_at(seed)
        print("\n".join(rep.chain("policy", policy)), flush=True)
        for chain, s in rep.chain_summaries["policy"]["summary"].items():
            o = s["overall"]
            out.setdefault(chain, {})[seed] = dict(cell=o["sr"], successes=o["successes"], n=o["n"])
            print(spec, chain, seed, o["successes"], "of", o["n"], flush=True)
    return out


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("out")
    p.add_argument("policy")
    p.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3])
    a = p.parse_args()
    cells = chain_cells(a.policy, a.seeds)
    json.dump(dict(policy=a.policy, seeds=a.seeds, cells=cells), open(a.out, "w"), indent=1, default=float)
