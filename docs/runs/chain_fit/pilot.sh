#!/bin/bash
# Pilot on training objects only (chooses the next screen's recipe; judges nothing): screen M's seed-16 run
# (runs/l1rep3m_s16, epoch 1500, its replay buffer) resumed for 500 more epochs two ways, A at optim.lr 3e-5, B at
# the stage's 1e-4 with the grasp rows weighted 3; then probe.py on the training objects' states for both exports.
#   nohup bash docs/runs/chain_fit/pilot.sh > runs/chainfit_pilot.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
for V in A B; do
  R=runs/chainfit_pilot_$V
  [ -d $R ] || cp -r runs/l1rep3m_s16 $R || exit 1
  if [ $V = A ]; then SET=(--set optim.lr=3.0e-5); else SET=(--set 'optim.mode_weights={rotate_x+: 5, grasp: 3}'); fi
  [ -f $R.pt ] || { unicross distill --resume --out $R --epochs 2000 "${SET[@]}" > $R.log 2>&1 \
    && unicross export $R --out $R.pt; } || exit 1
done
python docs/runs/chain_fit/probe.py train runs/chain_fit_train_states.pt docs/runs/chain_fit/probe_train_pilot.json \
  docs/runs/student_l1/student_l1_rep3_m_s16.pt runs/chainfit_pilot_A.pt runs/chainfit_pilot_B.pt
echo DONE
