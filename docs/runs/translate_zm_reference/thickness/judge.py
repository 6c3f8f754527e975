"""rule.txt step 6: the student distilled on the new translate z- expert against the shipped student, cell by cell
(seed_cells.py outputs: the report's test cells and the long horizon).

    python docs/runs/translate_zm_reference/thickness/judge.py docs/runs/translate_zm_reference/thickness/student_cells_seed0.json

Passes iff its translate z- cell is within 5 points of the new expert's (clone_s0/report_test.json, the same 100
trials) and no other mode or long-horizon cell is more than 5 points below the shipped student's
(../../student_yplus_repeat/cells_init_seed0.json, the cells of the student of 2026-12-05).
"""
import os
import sys

from unicross.evaluation import read_results

HERE = os.path.dirname(os.path.abspath(__file__))
STAGE = os.path.join(HERE, "..", "..", "student_yplus_repeat")
SHIPPED = os.path.join(STAGE, "cells_init_seed0.json")
sys.path.insert(0, STAGE)
from judge import counts as cells  # noqa: E402  (the cells of a seed_cells.py output: (successes, n) by name)


def judge(new_path, shipped_path, expert_path, skill, mode):
    """Print the cells of ``new_path`` against those of ``shipped_path`` (seed_cells.py outputs) and return whether
    every cell passes: ``mode`` within 5 points of the expert's cell (an eval JSON of ``skill``), every other cell no
    more than 5 points below the shipped student's."""
    new, old = cells(new_path), cells(shipped_path)
    expert = read_results(expert_path)["summaries"][skill]
    ok = True
    print(f"{'cell':20s} {'new student':>14s} {'shipped student':>16s}  bar")
    for k, (s, n) in new.items():
        sr, old_sr = 100.0 * s / n, 100.0 * old[k][0] / old[k][1]
        bar = expert["sr"] - 5.0 if k == mode else old_sr - 5.0
        passed = sr >= bar - 1e-9
        ok &= passed
        print(f"{k:20s} {sr:6.1f} ({s:>3d}/{n}) {old_sr:7.1f} ({old[k][0]:>3d}/{old[k][1]})  >= {bar:5.1f} "
              f"{'ok' if passed else 'MISSED'}{'  (the expert: %.1f)' % expert['sr'] if k == mode else ''}")
    return ok


def main():
    ok = judge(sys.argv[1], SHIPPED, os.path.join(HERE, "clone_s0", "report_test.json"), "translate", "translate_z-")
    print(f"step 6: {'PASSED' if ok else 'FAILED'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
