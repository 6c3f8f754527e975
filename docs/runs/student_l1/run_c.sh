#!/bin/bash
# rule.txt screen C: run.sh's stage with env.mode_repeats={rotate_x+: 3}, one seed; training screen and report cells
# (common.sh: rep_screen, which also measures x+ on the 120 held-out trials). First, step 1's seed-0 student on 300
# training trials, for comparison.
#   nohup bash docs/runs/student_l1/run_c.sh [SEED] > runs/student_l1_c.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
S=${1:-0}
[ -f $D/train300_student_l1_s0.json ] || screen $D/student_l1_s0.pt $D/train300_student_l1_s0.json train 50 allegro/rotate_x+ > runs/drift_l1_s0.log 2>&1 || exit 1
rep_screen runs/l1rep3_w30_s$S "" $S || exit 1
echo DONE
