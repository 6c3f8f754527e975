#!/bin/bash
# rule.txt screen N: `run_n.sh SEED` copies screen M's run on that training seed (runs/l1rep3m_sSEED, epoch 1500,
# its replay buffer; common.sh m_stage makes it again when missing) to runs/l1rep3n_sSEED and resumes it to epoch 2000 at
# optim.lr 3e-5, then the export (tag _n), the report's cells, the rotate cells and the long horizon under evaluation
# seeds 1-3. Judged by judge_i.py N (N3). Each step is skipped when its file exists, so a call resumes.
#   nohup bash -c 'for s in 16 17 18; do bash docs/runs/student_l1/run_n.sh $s || exit 1; done' > runs/student_l1_n.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
resume_m _n $1 --set optim.lr=3.0e-5 || exit 1
echo DONE
