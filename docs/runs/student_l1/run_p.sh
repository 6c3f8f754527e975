#!/bin/bash
# rule.txt screen P: `run_p.sh SEED` copies screen O's run on that training seed (runs/l1rep3o_sSEED, epoch 2000, its
# replay buffer; run_o.sh makes it again when missing) to runs/l1rep3p_sSEED and resumes it to epoch 2500 with the
# experts O distilled but the rotate z+ expert shipped at 564f969 (runs/experts1207p; the resume labels the buffer
# again by them) and O's arguments, then the export (tag _p), the report's cells, the rotate cells and the long horizon
# under evaluation seeds 1-3. Judged by judge_i.py P (P3). Each step is skipped when its file exists, so a call resumes.
#   nohup bash -c 'for s in 16 17 18; do bash docs/runs/student_l1/run_p.sh $s || exit 1; done' > runs/student_l1_p.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
resume_o _p $1 "" || exit 1
echo DONE
