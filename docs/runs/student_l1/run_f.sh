#!/bin/bash
# rule.txt screen F: screen C's stage (env.mode_repeats={rotate_x+: 3}) with optim.mode_weights={rotate_x+: 10}, one
# seed; training screen (seed 0 only) and report cells, then x+ on the 120 held-out trials (common.sh: rep_screen).
#   nohup bash docs/runs/student_l1/run_f.sh [SEED] > runs/student_l1_f.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
S=${1:-0}
rep_screen runs/l1rep3w10_s$S _w10 $S --set 'optim.mode_weights={rotate_x+: 10}' || exit 1
echo DONE
