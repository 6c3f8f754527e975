#!/bin/bash
# rule.txt screen H: screen G (F's stage, x+ walked three times, l1 0.01, from the shipped student) at x+ weight 15;
# one seed per call, judged pooled over seeds 1, 2, 3 with docs/runs/student_xp_drift/judge3.py (common.sh:
# ship_screen; seed 0 is not run).
#   nohup bash -c 'for s in 1 2 3; do bash docs/runs/student_l1/run_h.sh $s || exit 1; done' > runs/student_l1_h.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
S=${1:-1}
ship_screen 15 $S || exit 1
echo DONE
