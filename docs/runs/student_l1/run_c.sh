#!/bin/bash
# rule.txt screen C: run.sh's stage with env.mode_repeats={rotate_x+: 3}, one seed; training screen and report cells.
#   nohup bash docs/runs/student_l1/run_c.sh [SEED] > runs/student_l1_c.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
S=${1:-0}
[ -f $D/train300_student_l1_s0.json ] || screen $D/student_l1_s0.pt $D/train300_student_l1_s0.json train 50 allegro/rotate_x+ > runs/drift_l1_s0.log 2>&1 || exit 1
R=runs/l1rep3_w30_s$S
if [ ! -f $D/student_cells_rep3_s$S.json ]; then
  stage runs/experts1205x $R $S --set 'env.mode_repeats={rotate_x+: 3}' || exit 1
  unicross export $R --out $D/student_l1_rep3_s$S.pt || exit 1
  screen $D/student_l1_rep3_s$S.pt $D/train300_student_l1_rep3_s$S.json train 50 allegro/rotate_x+ > runs/drift_l1rep3_s$S.log 2>&1 || exit 1
  python docs/runs/student_ft_1202b/seed_cells.py $D/student_l1_rep3_s$S.pt $D/student_cells_rep3_s$S.json > runs/cells_l1rep3_s$S.log 2>&1 || exit 1
fi
echo DONE
