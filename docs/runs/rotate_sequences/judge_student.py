"""rule.txt step 6: the student distilled on the new rotate x+ expert against the shipped student, cell by cell
(docs/runs/student_ft_1202b/seed_cells.py outputs: the report's test cells and the long horizon).

    python docs/runs/rotate_sequences/judge_student.py docs/runs/rotate_sequences/student_cells_seed0.json

Passes iff its rotate x+ cell is within 5 points of the new expert's (x+/clone_s0/report_test.json, the same 100
trials) and no other mode or long-horizon cell is more than 5 points below the shipped student's
(../translate_zm_reference/thickness/student_cells_seed0.json). The comparison is thickness/judge.py's.
"""
import importlib.util
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
THICKNESS = os.path.join(HERE, "..", "translate_zm_reference", "thickness")
_spec = importlib.util.spec_from_file_location("thickness_judge", os.path.join(THICKNESS, "judge.py"))
_mod = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_mod)  # under its own name: it imports a module named judge itself
judge = _mod.judge

if __name__ == "__main__":
    ok = judge(sys.argv[1], os.path.join(THICKNESS, "student_cells_seed0.json"),
               os.path.join(HERE, "x+", "clone_s0", "report_test.json"), "rotate", "rotate_x+")
    print(f"step 6: {'PASSED' if ok else 'FAILED'}")
    sys.exit(0 if ok else 1)
