"""The report's rotate test cells (``PaperReport(limit=10, trials=3, min_trials=100)``: docs/results.md's cells are
evaluation seed 0) under other evaluation seeds: the same objects, other initial states and goals. Used by
diagnostic X (xp_seeds.py) and screen I (rule.txt I1, I2), whose rotate bars and cells pool evaluation seeds 0-3.

    python docs/runs/student_l1/rotate_seeds.py OUT.json POLICY [--modes MODE ...] [--seeds SEED ...]

POLICY is a checkpoint or shipped name (``allegro/student``), or ``experts`` for each mode's shipped expert
(``allegro/<mode>``). Defaults: the six rotate modes, seeds 1 2 3. OUT.json maps mode -> seed -> cell, successes, n.
"""
import argparse
import json

from unicross import formulation as F
from unicross.report import PaperReport

ROTATE = [m for m in F.MODES if m.startswith("rotate_")]


def report_at(seed, workers=2):
    """The report's protocol (docs/results.md's cells: ``PaperReport(limit=10, trials=3, min_trials=100)``) under
    evaluation seed ``seed``."""
    return PaperReport(hand="allegro", limit=10, trials=3, workers=workers, seed=seed, min_trials=100)


def seed_cells(spec, modes, seeds, workers=2):
    """{mode: {seed: dict(cell, successes, n)}} for ``spec`` (``experts``: ``allegro/<mode>`` per mode)."""
    out = {}
    for mode in modes:
        policy = f"allegro/{mode}" if spec == "experts" else spec
        for seed in seeds:
            rep = report_at(seed, workers)
            cell = rep.evaluate(mode, policy, "test")
            s = rep.summaries[(mode, policy, "test", False)]
            out.setdefault(mode, {})[seed] = dict(cell=cell, successes=s["successes"], n=s["n"])
            print(policy, mode, seed, cell, flush=True)
    return out


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("out")
    p.add_argument("policy")
    p.add_argument("--modes", nargs="+", default=ROTATE, choices=F.MODES)
    p.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3])
    a = p.parse_args()
    cells = seed_cells(a.policy, a.modes, a.seeds)
    json.dump(dict(policy=a.policy, seeds=a.seeds, cells=cells), open(a.out, "w"), indent=1, default=float)
