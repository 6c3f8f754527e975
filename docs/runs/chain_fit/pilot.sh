#!/bin/bash
# Pilot on training objects only (chooses a screen's recipe; judges nothing): screen M's run on training seed SEED
# (runs/l1rep3m_sSEED, epoch 1500, its replay buffer; default 16) resumed for 500 more epochs each way named
# (default "A B"): A at optim.lr 3e-5, B at the stage's 1e-4 with the grasp rows weighted 3; then probe.py on the
# training objects' states for M's export and the pilots'.
#   nohup bash docs/runs/chain_fit/pilot.sh > runs/chainfit_pilot.log 2>&1 &            # seed 16: A and B (66th session)
#   nohup bash docs/runs/chain_fit/pilot.sh 17 B > runs/chainfit_pilot_s17.log 2>&1 &   # seed 17: B
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
S=${1:-16}
SUF=$([ "$S" = 16 ] || echo _s$S)
PTS=()
for V in ${2:-A B}; do
  R=runs/chainfit_pilot_$V$SUF
  [ -d $R ] || cp -r runs/l1rep3m_s$S $R || exit 1
  if [ $V = A ]; then SET=(--set optim.lr=3.0e-5); else SET=(--set 'optim.mode_weights={rotate_x+: 5, grasp: 3}'); fi
  [ -f $R.pt ] || { unicross distill --resume --out $R --epochs 2000 "${SET[@]}" > $R.log 2>&1 \
    && unicross export $R --out $R.pt; } || exit 1
  PTS+=($R.pt)
done
python docs/runs/chain_fit/probe.py train runs/chain_fit_train_states.pt docs/runs/chain_fit/probe_train_pilot$SUF.json \
  docs/runs/student_l1/student_l1_rep3_m_s$S.pt "${PTS[@]}"
echo DONE
