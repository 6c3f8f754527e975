"""The student's test cells of the report for one candidate: the ten modes on held-out `test` objects and the long
horizon (the same trials as docs/results.md: `PaperReport(limit=10, trials=3, min_trials=100, seed=0)`), for the
other seeds of this stage, which report and do not choose (rule.txt).

    python docs/runs/student_ft_1202b/seed_cells.py CHECKPOINT OUT.json

Writes every cell's summary and prints the test successes summed over the ten modes and the long-horizon overall
successes (the "test" and "long horizon" parts of clause (w), comparable with sum_cells.py on a report).
"""
import json
import sys

from unicross import formulation as F
from unicross.evaluation import resolve_policy
from unicross.report import PaperReport

if __name__ == "__main__":
    spec, out_path = sys.argv[1], sys.argv[2]
    rep = PaperReport(hand="allegro", limit=10, trials=3, workers=2, seed=0, min_trials=100)
    out = {"checkpoint": spec, "test": {}}
    for mode in F.MODES:
        cell = rep.evaluate(mode, spec, "test")
        out["test"][mode] = dict(cell=cell, summary=rep.summaries[(mode, spec, "test", False)])
        print(mode, cell, flush=True)
    print("\n".join(rep.chain("student", resolve_policy(spec, "allegro")[0])), flush=True)
    out["long_horizon"] = rep.chain_summaries["student"]
    out["test_successes"] = sum(c["summary"]["successes"] for c in out["test"].values())
    out["long_horizon_successes"] = sum(c["overall"]["successes"] for c in out["long_horizon"]["summary"].values())
    json.dump(out, open(out_path, "w"), indent=1, default=float)
    print(json.dumps({k: out[k] for k in ("test_successes", "long_horizon_successes")}))
