#!/bin/bash
# rule.txt screen G: screen F's stage (x+ walked three times, weight 10, l1 0.01) started from the shipped student
# (model.init_policy=allegro/student) instead of the 2026-12-04 morning student; one seed per call, judged pooled over
# seeds 1, 2, 3 with docs/runs/student_xp_drift/judge3.py (common.sh: ship_screen; seed 0 is not run).
#   nohup bash -c 'for s in 1 2 3; do bash docs/runs/student_l1/run_g.sh $s || exit 1; done' > runs/student_l1_g.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
S=${1:-1}
ship_screen 10 $S || exit 1
echo DONE
