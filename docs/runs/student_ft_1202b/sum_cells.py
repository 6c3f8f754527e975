"""Sum a policy's successes over the cells of a report (docs/results.md layout).

    python docs/runs/student_ft_1202b/sum_cells.py REPORT.md [POLICY]

Counts round(SR x n / 100) over every table row whose policy column starts with POLICY (default allegro/student)
in the test, unseen and --disturb sections, and adds the long-horizon overall successes of the student's table
(the first two rows of the "Long horizon" section). Prints the per-section sums and the total as JSON.
"""
import json
import re
import sys

path = sys.argv[1]
policy = sys.argv[2] if len(sys.argv) > 2 else "allegro/student"
section = None
sums: dict[str, int] = {}
long_rows = 0
for line in open(path):
    if line.startswith("## "):
        section = line[3:].strip()
        continue
    if not line.startswith("| ") or section is None:
        continue
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    if section == "Long horizon" and policy == "allegro/student":
        if cells[0].startswith("Gr.") and long_rows < 2:
            m = re.match(r"([\d.]+) \[.*\] \(n=(\d+)\)", cells[4])
            sums["long horizon"] = sums.get("long horizon", 0) + round(float(m[1]) * int(m[2]) / 100)
            long_rows += 1
        continue
    if section.startswith(("Experts, held-out", "Student, held-out", "Unseen", "Disturbances")) and len(cells) >= 3:
        if not cells[1].startswith(policy):
            continue
        m = re.match(r"([\d.]+) \[[^\]]*\] \(n=(\d+)\)", cells[2])
        if m:
            sums[section] = sums.get(section, 0) + round(float(m[1]) * int(m[2]) / 100)
print(json.dumps({"report": path, "policy": policy, **sums, "total": sum(sums.values())}, indent=1))
