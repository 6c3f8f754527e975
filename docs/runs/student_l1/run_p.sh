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
S=$1 P=docs/runs/student_l1/student_l1_rep3_p_s$1.pt R=runs/l1rep3p_s$1
experts_at 723f266 runs/experts1207p || exit 1
if ! cmp -s runs/experts1207p/rotate_z+/checkpoint.pt <(git show 564f969:unicross/checkpoints/allegro/rotate_z+.pt); then
  git show 564f969:unicross/checkpoints/allegro/rotate_z+.pt > runs/experts1207p/rotate_z+/checkpoint.pt || exit 1
fi
if [ ! -f docs/runs/student_l1/student_cells_rep3_p_s$S.json ]; then
  if [ ! -d $R ]; then
    [ -f runs/l1rep3o_s$S/checkpoint.pt ] || bash docs/runs/student_l1/run_o.sh $S || exit 1
    cp -r runs/l1rep3o_s$S $R.tmp && mv $R.tmp $R || exit 1
  fi
  unicross distill --resume --experts runs/experts1207p --out $R --epochs 2500 \
    --set 'optim.mode_weights={rotate_x+: 5, grasp: 3}' > $R.log 2>&1 || exit 1
  unicross export $R --out $P || exit 1
  cp $R/metrics.jsonl docs/runs/student_l1/metrics_rep3_p_s$S.jsonl
  python docs/runs/student_ft_1202b/seed_cells.py $P docs/runs/student_l1/student_cells_rep3_p_s$S.json \
    > runs/cells_l1rep3p_s$S.log 2>&1 || exit 1
fi
seed_evals _p $S || exit 1
echo DONE
