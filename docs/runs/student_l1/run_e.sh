#!/bin/bash
# rule.txt screen E: screen C's stage (env.mode_repeats={rotate_x+: 3}) over 1800 epochs, one seed; training screen
# (seed 0 only) and report cells, then x+ on the 120 held-out trials (common.sh: rep_screen).
#   nohup bash docs/runs/student_l1/run_e.sh [SEED] > runs/student_l1_e.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
S=${1:-0}
EPOCHS=1800 rep_screen runs/l1rep3e1800_w30_s$S _e1800 $S || exit 1
echo DONE
