"""Long-horizon JSONs (`unicross chain --out`) scored under both rules: "old" counts an in-hand phase once its motion
passed the threshold before any drop (the chain before commit 3a2f632); "new" also fails it when the object is dropped
later in that phase, as the per-skill protocol fails a trial that drops (the chain since 3a2f632). Overall success of
every phase, per sequence kind, with 95% Wilson intervals.

    python docs/runs/experts_chain/rescore.py FILE.json [...]
"""
import json
import sys
from collections import defaultdict

from unicross.metrics import wilson_interval



for f in sys.argv[1:]:
    T = json.load(open(f))["trials"]
    g = defaultdict(lambda: [0, 0, 0])
    for t in T:
        kind = "Rot" if t["sequence"][-1].startswith("rotate") else "Trans"
        last = len(t["sequence"]) - 1
        old = all(t["phase_success"])
        new = old and t["dropped_in_phase"] != last
        g[kind][0] += 1
        g[kind][1] += old
        g[kind][2] += new
    ci = {k: [100 * x for x in wilson_interval(v[2], v[0])] for k, v in g.items()}
    print(f, {k: f"old {v[1]}/{v[0]}, new {v[2]}/{v[0]} [{ci[k][0]:.0f}-{ci[k][1]:.0f}]" for k, v in g.items()})
