"""The report's rotate x+ test cell (docs/results.md's trials: PaperReport(limit=10, trials=3, min_trials=100, seed=0))
for an x+ checkpoint, as the report would show it for an expert.

    python docs/runs/xp_clone_drift/expert_cell.py CHECKPOINT OUT.json
"""
import json
import sys

from unicross.report import PaperReport

if __name__ == "__main__":
    spec, out_path = sys.argv[1], sys.argv[2]
    rep = PaperReport(hand="allegro", limit=10, trials=3, workers=1, seed=0, min_trials=100)
    cell = rep.evaluate("rotate_x+", spec, "test")
    print(cell)
    json.dump(dict(checkpoint=spec, cell=cell, summary=rep.summaries[("rotate_x+", spec, "test", False)]),
              open(out_path, "w"), indent=1, default=float)
