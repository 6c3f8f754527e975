#!/bin/bash
# rule.txt screen C: run.sh's stage with env.mode_repeats={rotate_x+: 3}, one seed; training screen and report cells.
#   nohup bash docs/runs/student_l1/run_c.sh [SEED] > runs/student_l1_c.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
D=docs/runs/student_l1
S=${1:-0}
[ -f $D/train300_student_l1_s0.json ] || (cd $D && python ../student_xp_drift/drift.py student_l1_s0.pt train300_student_l1_s0.json --objects train --limit 50 --trials 3 --labeller allegro/rotate_x+) > runs/drift_l1_s0.log 2>&1 || exit 1
R=runs/l1rep3_w30_s$S
if [ ! -f $D/student_cells_rep3_s$S.json ]; then
  [ -f $R/checkpoint.pt ] && RES=--resume || RES=
  unicross distill --experts runs/experts1205x --out $R --epochs 1500 $RES --set model.init_policy=runs/student_1204_morning.pt --set optim.lr=1.0e-4 --set optim.warmup_frames=102400 --set env.object_limit=null --set collector.rollout_steps=256 --set optim.grad_steps=30 --set optim.batch_size=1024 --set buffer.capacity=300000 --set logging.checkpoint_every=25 --set seed=$S --set env.chain_share=0.15 --set 'optim.mode_weights={rotate_x+: 30}' --set optim.l1=0.01 --set 'env.mode_repeats={rotate_x+: 3}' > $R.log 2>&1 || exit 1
  unicross export $R --out $D/student_l1_rep3_s$S.pt || exit 1
  (cd $D && python ../student_xp_drift/drift.py student_l1_rep3_s$S.pt train300_student_l1_rep3_s$S.json --objects train --limit 50 --trials 3 --labeller allegro/rotate_x+) > runs/drift_l1rep3_s$S.log 2>&1 || exit 1
  python docs/runs/student_ft_1202b/seed_cells.py $D/student_l1_rep3_s$S.pt $D/student_cells_rep3_s$S.json > runs/cells_l1rep3_s$S.log 2>&1 || exit 1
fi
echo DONE
