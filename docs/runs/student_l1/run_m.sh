#!/bin/bash
# rule.txt screen M: `run_m.sh experts` measures the new z- and y+ experts' rotate cells (M1's bars,
# rotate_seeds_experts_m.json); `run_m.sh SEED` runs K's stage from K's initial student (runs/student_pre_k.pt, the
# allegro/student of commit 06e213f^) with the ten experts shipped at 723f266 (new z- and y+; runs/experts1207) on one
# training seed: the export (tag _m), the report's cells, the rotate cells and the long horizon under evaluation
# seeds 1-3. Judged by judge_i.py M (M3). Each step is skipped when its file exists, so a call resumes.
#   nohup bash -c 'for s in experts 16 17 18; do bash docs/runs/student_l1/run_m.sh $s || exit 1; done' > runs/student_l1_m.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
S=$1
if [ "$S" = experts ]; then
  [ -f $D/rotate_seeds_experts_m.json ] \
    || python $D/experts_m.py $D/rotate_seeds_experts_m.json > runs/rotseeds_experts_m.log 2>&1 || exit 1
  echo DONE; exit 0
fi
P=$D/student_l1_rep3_m_s$S.pt
if [ ! -f $D/student_cells_rep3_m_s$S.json ]; then
  m_stage $S || exit 1
  unicross export runs/l1rep3m_s$S --out $P || exit 1
  cp runs/l1rep3m_s$S/metrics.jsonl $D/metrics_rep3_m_s$S.jsonl
  python docs/runs/student_ft_1202b/seed_cells.py $P $D/student_cells_rep3_m_s$S.json > runs/cells_l1rep3m_s$S.log 2>&1 \
    || exit 1
fi
seed_evals _m $S || exit 1
echo DONE
