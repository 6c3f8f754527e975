"""The report's unseen-object cells (translate z+, translate z-, grasp) for several student policies.

    python docs/runs/student10_relay_s0_ft/unseen/unseen_cells.py allegro/student \
        docs/runs/student10_relay_s{0,1,2}_ft/policy.pt docs/runs/student10_relay_s{0,2,1}/policy.pt

Each cell is ``PaperReport.evaluate`` with the report's defaults (first 10 objects per group, 3 trials per object
raised to 100 per cell, seed 0, 2 workers), so ``allegro/student`` reproduces `docs/results.md`'s cells. Writes
``unseen_cells.json`` beside this file (the committed one merges two runs: the first five policies, then
``allegro/student`` again and ``docs/runs/student10_relay_s{2,1}/policy.pt``; the student's cells were the same in both).
"""
import json
import sys
from pathlib import Path

from unicross.report import PaperReport


def main(policies):
    report = PaperReport(workers=2, log=lambda s: None)
    out = {}
    for spec in policies:
        for mode in ("translate_z+", "translate_z-", "grasp"):
            out[f"{spec} {mode}"] = cell = report.evaluate(mode, spec, "unseen")
            print(spec, mode, cell, flush=True)
    (Path(__file__).parent / "unseen_cells.json").write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main(sys.argv[1:])
