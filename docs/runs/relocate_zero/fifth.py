"""A relocate policy on every fifth test object, paired with the full-protocol runs. A screen, not the protocol.

Runs POLICY (anything ``unicross eval --policy`` takes) on the test objects of index 0 mod 5 (80 objects x 25 trials =
2,000; every trial is seeded from its object's index in the whole list, so it pairs trial by trial with the
full-protocol runs), then pairs the result with the zero action and the shipped expert on the same trials
(docs/runs/paper_protocol/relocate_full{,_zero}{,_disturb}.json.gz):

    python docs/runs/relocate_zero/fifth.py POLICY OUT.json [--disturb]

``squeeze.py`` and ``../relocate_dist/force_vs_drop.py`` run through the same functions. 2.5 min alone on the 2-core VM.
"""
import argparse
import json
import multiprocessing as mp
import sys
from concurrent.futures import ProcessPoolExecutor
from functools import partial
from pathlib import Path

import torch

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "docs/runs/paper_protocol"))
from paired import mcnemar_exact, newcombe_paired, paired_cells  # noqa: E402

SHARDS = [(0, 10), (5, 10)]  # objects 0 mod 10 and 5 mod 10: together index 0 mod 5, one process each


def run_shard(policy, disturb, shard):
    """Trials of one shard, in this process; ``policy`` is a ``--policy`` spec or a policy function."""
    torch.set_num_threads(1)
    from unicross.evaluation import resolve_policy, run_protocol
    from unicross.objects import get_object_set
    if isinstance(policy, str):
        policy, _ = resolve_policy(policy, "allegro")
    return run_protocol("relocate", policy, get_object_set("test"), disturb=disturb, seed=0, trials_per_object=25,
                        shard=shard, progress=False)


def run_fifth(policy, disturb: bool):
    """All 2,000 trials, on two processes."""
    with ProcessPoolExecutor(len(SHARDS), mp_context=mp.get_context("spawn")) as ex:
        parts = list(ex.map(partial(run_shard, policy, disturb), SHARDS))
    return [t for part in parts for t in part]


def report(trials, label: str, disturb: bool):
    """Prints the run's successes and its paired differences to the zero action and the expert on the same trials."""
    from unicross.evaluation import read_results
    key = lambda t: (t["object"], t["trial"])  # noqa: E731
    mine = {key(t): t for t in trials}
    suffix = "_disturb" if disturb else ""
    print(f"{label}{' --disturb' if disturb else ''}: "
          f"{sum(t['success'] for t in trials)} of {len(trials)} ({sum(t['dropped'] for t in trials)} dropped)")
    for name in (f"relocate_full_zero{suffix}", f"relocate_full{suffix}"):
        full = read_results(ROOT / f"docs/runs/paper_protocol/{name}.json.gz")["trials"]["relocate"]
        other = {key(t): t for t in full if key(t) in mine}
        assert len(other) == len(mine), name
        cells = paired_cells((t["success"], other[k]["success"]) for k, t in mine.items())
        lo, hi = newcombe_paired(*cells)
        n = len(mine)
        print(f"  against {name}: {100 * (cells[0] + cells[2]) / n:.1f}% there; this - it "
              f"{100 * (cells[1] - cells[2]) / n:+.1f} points [{100 * lo:+.1f}, {100 * hi:+.1f}], only this {cells[1]}, "
              f"only it {cells[2]}, p = {mcnemar_exact(cells[1], cells[2]):.2g}")


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("policy", help="as unicross eval --policy: a checkpoint, allegro/relocate, zero, ...")
    p.add_argument("out")
    p.add_argument("--disturb", action="store_true")
    a = p.parse_args()
    trials = run_fifth(a.policy, a.disturb)
    json.dump(dict(policy=a.policy, disturb=a.disturb, objects="test, index 0 mod 5", trials=trials),
              open(a.out, "w"), indent=1, default=float)
    report(trials, a.policy, a.disturb)
