"""Step 2 of rule.txt: the candidate of the z- searches, the row `--policy gait:LOG` picks in each log (the highest
selection success), the best of the logs by selection success (ties: the higher search score, then the first log).
Writes --out and exits 1 when that success is under 6 of 32 (nothing found).

    python docs/runs/rotate_zm_it12/pick.py A.jsonl.gz B.jsonl.gz --out candidate.json
"""
import argparse
import json

from unicross.gaits import best_gait

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("logs", nargs="+")
ap.add_argument("--out", required=True)
ap.add_argument("--min-success", type=float, default=6 / 32)
args = ap.parse_args()

rows = []
for i, log in enumerate(args.logs):
    _, row = best_gait(log)
    rows.append((row.get("success", 0.0), row.get("score", float("-inf")), -i, log, row))
    print(f"{log}: selection success {row.get('success')}, score {row.get('score')}")
success, score, _, log, row = max(rows, key=lambda r: r[:3])
found = success >= args.min_success
out = {"log": log, "success": success, "score": score, "selection_episodes": row.get("selection_episodes"),
       "found": found, "min_success": args.min_success}
with open(args.out, "w") as f:
    json.dump(out, f, indent=1)
print(json.dumps(out))
raise SystemExit(0 if found else 1)
