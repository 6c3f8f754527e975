#!/bin/bash
# rule.txt screen Q: `run_q.sh SEED` is run_p.sh with the DAgger seed 1SEED (other rollouts than P's): O's run on SEED
# (runs/l1rep3o_sSEED) copied to runs/l1rep3q_sSEED and resumed to epoch 2500 with the experts of runs/experts1207p,
# then the export (tag _q), the report's cells, the rotate and translate cells and the long horizon under evaluation
# seeds 1-3. Each step is skipped when its file exists, so a call resumes.
#   nohup bash -c 'for s in 16 17 18; do bash docs/runs/student_l1/run_q.sh $s || exit 1; done' > runs/student_l1_q.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
resume_o _q $1 "rotate_x+ rotate_x- rotate_y+ rotate_y- rotate_z+ rotate_z- translate_z+ translate_z-" --set seed=1$1 || exit 1
echo DONE
