"""rule.txt step 3: three seeds' report cells (seed_cells.py outputs) pooled, against the issue's "within 5 points of its
expert" per mode and the shipped student's long horizon - 5.

    python docs/runs/student_xp_drift/judge3.py student_cells_s0.json student_cells_s1.json student_cells_s2.json
    python docs/runs/student_xp_drift/judge3.py --expert rotate_x+=CELL.json cells_s0.json ...   # another x+ expert

``--expert MODE=FILE`` replaces that mode's expert cell by FILE's (docs/runs/xp_clone_drift/expert_cell.py's output).

The experts' cells are docs/results.md's (50th session), copied into EXPERT below; the shipped student's long horizon is
read from docs/runs/translate_zm_reference/thickness/student_cells_seed0.json (the cells docs/results.md shows for it).
"""
import json
import os
import re
import sys

from unicross.metrics import wilson_interval

HERE = os.path.dirname(os.path.abspath(__file__))
RUNS = os.path.join(HERE, "..")
# the shipped experts' test cells in docs/results.md (success rates, %)
EXPERT = {"grasp": 100.0, "relocate": 100.0, "rotate_x+": 24.0, "rotate_x-": 8.0, "rotate_y+": 43.0,
          "rotate_y-": 53.0, "rotate_z+": 55.0, "rotate_z-": 1.0, "translate_z+": 98.0, "translate_z-": 87.0}


def pooled(files):
    cells = [json.load(open(f)) for f in files]
    out = {}
    for mode in EXPERT:
        k = sum(c["test"][mode]["summary"]["successes"] for c in cells)
        n = sum(c["test"][mode]["summary"]["n"] for c in cells)
        out[mode] = (k, n)
    for kind in ("Gr. + Re. + Trans.", "Gr. + Re. + Rot."):
        k = sum(c["long_horizon"]["summary"][kind]["overall"]["successes"] for c in cells)
        n = sum(c["long_horizon"]["summary"][kind]["overall"]["n"] for c in cells)
        out[kind] = (k, n)
    return out, cells


if __name__ == "__main__":
    shipped = json.load(open(os.path.join(RUNS, "translate_zm_reference", "thickness", "student_cells_seed0.json")))
    args = sys.argv[1:]
    while args and args[0] == "--expert":
        mode, path = args[1].split("=", 1)
        if mode not in EXPERT:
            sys.exit(f"--expert: unknown mode {mode!r} (one of {', '.join(EXPERT)})")
        EXPERT[mode] = json.load(open(path))["summary"]["sr"]
        print(f"{mode}: the expert's cell is {path}'s {EXPERT[mode]:g}")
        args = args[2:]
    pool, cells = pooled(args)
    ok = True
    # a column per file, named by the seed in its name (``..._s3.json``, ``..._seed3.json``), else by its position
    seeds = [re.search(r"_s(?:eed)?(\d+)\.json$", f) for f in args]
    names = [f"seed {m.group(1)}" if m else f"file {i + 1}" for i, m in enumerate(seeds)]
    print("| cell | " + " | ".join(names) + " | pooled [95% CI] | bar | |")
    print("|---|" + "---|" * len(cells) + "---|---|---|")
    for name, (k, n) in pool.items():
        sr = 100 * k / n
        lo, hi = (100 * x for x in wilson_interval(k, n))
        if name in EXPERT:
            bar = EXPERT[name] - 5
            per = [c["test"][name]["summary"]["sr"] for c in cells]
        else:
            bar = shipped["long_horizon"]["summary"][name]["overall"]["sr"] - 5
            per = [c["long_horizon"]["summary"][name]["overall"]["sr"] for c in cells]
        good = sr >= bar - 1e-9
        ok &= good
        print(f"| {name} | " + " | ".join(f"{p:.1f}" for p in per) + f" | {sr:.1f} [{lo:.1f}-{hi:.1f}] (n={n}) | "
              f">= {bar:g} | {'ok' if good else 'MISSED'} |")
    print(f"rule step 3: {'PASSED' if ok else 'FAILED'}")
    sys.exit(0 if ok else 1)
