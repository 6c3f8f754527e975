#!/bin/bash
# rule.txt screen O: `run_o.sh SEED` copies screen M's run on that training seed (runs/l1rep3m_sSEED, epoch 1500,
# its replay buffer; common.sh m_stage makes it again when missing) to runs/l1rep3o_sSEED and resumes it to epoch 2000 at
# the stage's optim.lr 1e-4 with the grasp rows weighted 3 (pilot B of docs/runs/chain_fit), then the export (tag _o), the
# report's cells, the rotate cells and the long horizon under evaluation seeds 1-3. Judged by judge_i.py O (O3). Each
# step is skipped when its file exists, so a call resumes.
#   nohup bash -c 'for s in 16 17 18; do bash docs/runs/student_l1/run_o.sh $s || exit 1; done' > runs/student_l1_o.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
resume_m _o $1 --set 'optim.mode_weights={rotate_x+: 5, grasp: 3}' || exit 1
echo DONE
