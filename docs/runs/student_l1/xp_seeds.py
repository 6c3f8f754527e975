"""rule.txt diagnostic X (58th session; informs, judges nothing): the report's rotate x+ test cell (the same 20
objects and 100 trials per cell as docs/results.md, ``PaperReport(limit=10, trials=3, min_trials=100)``) under
evaluation seeds 1, 2, 3 instead of 0, i.e. 300 other initial states, for the shipped x+ expert and screen G's three
students. It measures how far the expert's seed-0 cell (24, the bar's base) stands from its rate on other trials.

    python docs/runs/student_l1/xp_seeds.py OUT.json
"""
import json
import sys

from rotate_seeds import seed_cells

D = "docs/runs/student_l1"
POLICIES = ["allegro/rotate_x+"] + [f"{D}/student_l1_rep3_w10ship_s{s}.pt" for s in (1, 2, 3)]

if __name__ == "__main__":
    out = {spec: seed_cells(spec, ["rotate_x+"], (1, 2, 3))["rotate_x+"] for spec in POLICIES}
    json.dump(out, open(sys.argv[1], "w"), indent=1, default=float)
