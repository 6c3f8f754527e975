#!/bin/bash
# rule.txt screen F: screen C's stage (env.mode_repeats={rotate_x+: 3}) with optim.mode_weights={rotate_x+: 10}, one
# seed; training screen (seed 0 only) and report cells, then x+ on the 120 held-out trials.
#   nohup bash docs/runs/student_l1/run_f.sh [SEED] > runs/student_l1_f.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
S=${1:-0}
R=runs/l1rep3w10_s$S
P=$D/student_l1_rep3_w10_s$S.pt
if [ ! -f $D/student_cells_rep3_w10_s$S.json ]; then
  stage runs/experts1205x $R $S --set 'env.mode_repeats={rotate_x+: 3}' --set 'optim.mode_weights={rotate_x+: 10}' || exit 1
  unicross export $R --out $P || exit 1
  if [ "$S" = 0 ]; then
    screen $P $D/train300_student_l1_rep3_w10_s$S.json train 50 allegro/rotate_x+ > runs/drift_l1rep3w10_s$S.log 2>&1 || exit 1
  fi
  python docs/runs/student_ft_1202b/seed_cells.py $P $D/student_cells_rep3_w10_s$S.json > runs/cells_l1rep3w10_s$S.log 2>&1 || exit 1
fi
[ -f $D/test120_student_l1_rep3_w10_s$S.json ] || screen $P $D/test120_student_l1_rep3_w10_s$S.json test 20 allegro/rotate_x+ > runs/drift_l1rep3w10_test_s$S.log 2>&1 || exit 1
echo DONE
