"""The three --progress clones of the stopping y- gait on the 120 held-out trials, against the clone of the same gait
without the input (one seed) and against the three no-stop clones (seed by seed), paired by trial (Newcombe's
interval and the exact McNemar p of docs/runs/paper_protocol/paired.py). Run from the repository root:

    python docs/runs/nostop/progress_input/summary.py
"""
import json
import sys

sys.path.insert(0, "docs/runs/paper_protocol")
from paired import mcnemar_exact, newcombe_paired, paired_cells  # noqa: E402

from unicross.metrics import wilson_interval as wilson  # noqa: E402


def load(path):
    """Held-out trials of a gait_clone.py run by (object, axis, trial, seed)."""
    return {(t["object"], t.get("axis"), t["trial"], t.get("seed")): t for t in json.load(open(path))["trials"]}


def compare(runs, others, name):
    """Pairs run i's trials with others[i]'s and prints the pooled rates and their difference."""
    a, b, c, d = paired_cells((t["success"], o[k]["success"]) for r, o in zip(runs, others) for k, t in r.items())
    n = a + b + c + d
    lo, hi = newcombe_paired(a, b, c, d)
    wl, wh = wilson(a + b, n)
    print(f"{a + b} of {n} ({100 * (a + b) / n:.1f}% [{100 * wl:.1f}-{100 * wh:.1f}]) against {name}: {a + c}; "
          f"{100 * (b - c) / n:+.1f} points [{100 * lo:+.1f}, {100 * hi:+.1f}], {b} won, {c} lost, "
          f"p = {mcnemar_exact(b, c):.3g}")


runs = [load(f"docs/runs/nostop/progress_input/clone_s{s}/heldout.json") for s in range(3)]
for i, r in enumerate(runs):
    k = sum(bool(t["success"]) for t in r.values())
    dropped = sum(bool(t.get("dropped")) for t in r.values())
    short = sum(1 for t in r.values() if not t["success"] and not t.get("dropped"))
    print(f"seed {i}: {k} of {len(r)} ({100 * k / len(r):.1f}%), {dropped} dropped, {short} held short of pi/2")
control = load("docs/runs/gait_clone/phase_rounds8/r8_ym_phase_searched/heldout.json")
compare(runs, [control] * len(runs), "the stopping gait's clone without the input (one seed, repeated: descriptive)")
nostop = [load(f"docs/runs/nostop/{d}/heldout.json") for d in ("clone_y-_shipped", "clone_y-_s1", "clone_y-_s2")]
compare(runs, nostop, "the no-stop clones, seed by seed")
