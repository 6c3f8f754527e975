"""Re-run the K best distinct sequences of a search log (search.py) on new starts: the first 8 training
objects per group x 2 starts, ``--seed 500`` (32 episodes each), and print their success rates.

    python docs/runs/translate_hands/zm_sharpa/selection.py OUTDIR sharpa_wave z- 6

(2026-11-28: the five best of ``search.jsonl`` by search score, and the search's final mean; outputs
``evals/sel_sharpa_wave_*.json``, printed in ``selection.txt``).
"""
import hashlib
import json
import os
import subprocess
import sys

outdir, hand, axis, k = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
rows = [json.loads(line) for line in open(os.path.join(outdir, "search.jsonl"))]
seen, best = set(), []
for r in sorted(rows, key=lambda r: -r["score"]):
    if r["spec"] not in seen:
        seen.add(r["spec"])
        best.append(r)
    if len(best) == k:
        break
for r in best:
    spec = r["spec"]
    h = hashlib.md5(f"sel{spec}{hand}{axis}".encode()).hexdigest()[:12]
    out = os.path.join(outdir, "evals", f"sel_{hand}_{h}.json")
    if not os.path.exists(out):
        subprocess.run(["unicross", "eval", "--policy", "seq:" + spec, "--hand", hand, "--protocol", "translate",
                        "--axis", axis, "--objects", "train", "--limit", "8", "--trials-per-object", "2", "--seed", "500",
                        "--workers", "2", "--out", out], capture_output=True, check=True)
    d = json.load(open(out))
    s = d["summaries"]["translate"]
    drops = sum(t["dropped"] for t in d["trials"]["translate"])
    print(f"search score {r['score']:.3f} (gen {r['gen']}, sr {r['sr']}) | select sr {s['sr']:.1f} "
          f"({s['successes']}/{s['n']}) drops {drops} | {spec} | {os.path.basename(out)}", flush=True)
