"""rule.txt step 6: the student distilled on the new rotate x+ expert against the shipped student, cell by cell
(docs/runs/student_ft_1202b/seed_cells.py outputs: the report's test cells and the long horizon).

    python docs/runs/rotate_sequences/judge_student.py docs/runs/rotate_sequences/student_cells_seed0.json

Passes iff its rotate x+ cell is within 5 points of the new expert's (x+/clone_s0/report_test.json, the same 100
trials) and no other mode or long-horizon cell is more than 5 points below the shipped student's
(../translate_zm_reference/thickness/student_cells_seed0.json).
"""
import os
import sys

from unicross.evaluation import read_results

HERE = os.path.dirname(os.path.abspath(__file__))
SHIPPED = os.path.join(HERE, "..", "translate_zm_reference", "thickness", "student_cells_seed0.json")
sys.path.insert(0, os.path.join(HERE, "..", "student_yplus_repeat"))
from judge import counts as cells  # noqa: E402  (the cells of a seed_cells.py output: (successes, n) by name)


def main():
    new, old = cells(sys.argv[1]), cells(SHIPPED)
    expert = read_results(os.path.join(HERE, "x+", "clone_s0", "report_test.json"))["summaries"]["rotate"]
    ok = True
    print(f"{'cell':20s} {'new student':>14s} {'shipped student':>16s}  bar")
    for k, (s, n) in new.items():
        sr, old_sr = 100.0 * s / n, 100.0 * old[k][0] / old[k][1]
        bar = expert["sr"] - 5.0 if k == "rotate_x+" else old_sr - 5.0
        passed = sr >= bar - 1e-9
        ok &= passed
        print(f"{k:20s} {sr:6.1f} ({s:>3d}/{n}) {old_sr:7.1f} ({old[k][0]:>3d}/{old[k][1]})  >= {bar:5.1f} "
              f"{'ok' if passed else 'MISSED'}{'  (the expert: %.1f)' % expert['sr'] if k == 'rotate_x+' else ''}")
    print(f"step 6: {'PASSED' if ok else 'FAILED'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
