"""rule.txt B2: choose between the fresh floored x+ clones on their 300 training trials alone (drift.py outputs).

    python docs/runs/student_l1/choose.py train300_clone_s4.json train300_clone_s5.json

Qualifies: dropped <= 80 and mean drift after the stop <= 0.02 rad; of those, the most successes (a tie: fewer drops).
Prints the table and writes choice.json ({"chosen": FILE or null}).
"""
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
rows = []
for path in sys.argv[1:]:
    s = json.load(open(path))["summary"]
    ok = s["dropped"] <= 80 and s["mean_abs_drift_after"] <= 0.02
    rows.append((ok, s["successes"], -s["dropped"], path))
    print(f"{path}: {s['successes']} successes, {s['dropped']} dropped of {s['n']}, drift after the stop "
          f"{s['mean_abs_drift_after']:.3f} rad -> {'qualifies' if ok else 'does not qualify'}")
good = [r for r in rows if r[0]]
chosen = max(good)[3] if good else None
print(f"chosen: {chosen}")
json.dump(dict(chosen=chosen, rule="rule.txt B2"), open(os.path.join(HERE, "choice.json"), "w"), indent=1)
