"""Which disturbed trials does the zero action drop? Drops against the disturbance's magnitude and direction.

Runs the zero action under ``--disturb`` on the screen's 2,000 trials (every fifth test object, 25 trials each, seeded
as the full runs: ``docs/runs/relocate_zero/fifth.py``), records each trial's constant force (|F| / (m g), and the
cosine of its angle with gravity) at the first step, and prints the drop rate by force magnitude:

    python docs/runs/relocate_dist/force_vs_drop.py OUT.json
"""
import json
import multiprocessing as mp
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "relocate_zero"))
from fifth import SHARDS, run_shard  # noqa: E402


def _shard(shard):
    """The zero action's disturbed trials of one shard, each with its force."""
    from unicross.evaluation import zero_policy
    forces = []

    def policy(obs, u):
        if int(u.elapsed_steps.max()) == 0:
            f = u.disturb[0]
            mg = float(u.obj_mass[0]) * u._gravity
            forces.append(dict(scale=float(f.norm()) / mg, cos_down=float(-f[2] / f.norm().clamp_min(1e-9))))
        return zero_policy(obs, u)
    trials = run_shard(policy, True, shard)
    assert len(trials) == len(forces)
    return [dict(t, **f) for t, f in zip(trials, forces)]


if __name__ == "__main__":
    with ProcessPoolExecutor(len(SHARDS), mp_context=mp.get_context("spawn")) as ex:
        trials = [t for part in ex.map(_shard, SHARDS) for t in part]
    json.dump(dict(policy="zero", disturb=True, objects="test, index 0 mod 5", trials=trials), open(sys.argv[1], "w"),
              indent=1, default=float)
    print(f"zero action --disturb: {sum(t['success'] for t in trials)} of {len(trials)}")
    print("| |F| / (m g) | trials | dropped | held off the target |\n|---|---|---|---|")
    for lo in range(0, 10, 2):
        sel = [t for t in trials if lo <= t["scale"] < lo + 2]
        print(f"| {lo}-{lo + 2} | {len(sel)} | {sum(t['dropped'] for t in sel)} | "
              f"{sum(not t['success'] and not t['dropped'] for t in sel)} |")
    drops = [t for t in trials if t["dropped"]]
    if drops:
        print(f"dropped trials: |F|/(m g) {min(t['scale'] for t in drops):.1f}-{max(t['scale'] for t in drops):.1f}, "
              f"mean cos(F, down) {sum(t['cos_down'] for t in drops) / len(drops):+.2f} "
              f"(all trials {sum(t['cos_down'] for t in trials) / len(trials):+.2f})")
