"""Clause (s) of docs/runs/student_ft_1202/rule.txt: the report's own rotate y-, z+, z- test cells for a candidate
student (the same trials as docs/results.md). Usage: python screen.py CHECKPOINT OUT.json"""
import json, sys
from unicross.report import PaperReport
if __name__ == "__main__":
    spec = sys.argv[1]
    rep = PaperReport(hand="allegro", limit=10, trials=3, workers=2, seed=0, min_trials=100)
    out = {}
    for mode in ("rotate_y-", "rotate_z+", "rotate_z-"):
        cell = rep.evaluate(mode, spec, "test")
        out[mode] = dict(cell=cell, summary=rep.summaries[(mode, spec, "test", False)])
        print(mode, cell, flush=True)
    json.dump(out, open(sys.argv[2], "w"), indent=1, default=float)
