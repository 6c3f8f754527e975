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
S=$1 P=$D/student_l1_rep3_q_s$1.pt R=runs/l1rep3q_s$1
experts_at 723f266 runs/experts1207p || exit 1
if ! cmp -s runs/experts1207p/rotate_z+/checkpoint.pt <(git show 564f969:unicross/checkpoints/allegro/rotate_z+.pt); then
  git show 564f969:unicross/checkpoints/allegro/rotate_z+.pt > runs/experts1207p/rotate_z+/checkpoint.pt || exit 1
fi
if [ ! -f $D/student_cells_rep3_q_s$S.json ]; then
  if [ ! -d $R ]; then
    [ -f runs/l1rep3o_s$S/checkpoint.pt ] || bash $D/run_o.sh $S || exit 1
    cp -r runs/l1rep3o_s$S $R.tmp && mv $R.tmp $R || exit 1
  fi
  unicross distill --resume --experts runs/experts1207p --out $R --epochs 2500 \
    --set 'optim.mode_weights={rotate_x+: 5, grasp: 3}' --set seed=1$S > $R.log 2>&1 || exit 1
  unicross export $R --out $P || exit 1
  cp $R/metrics.jsonl $D/metrics_rep3_q_s$S.jsonl
  python docs/runs/student_ft_1202b/seed_cells.py $P $D/student_cells_rep3_q_s$S.json > runs/cells_l1rep3q_s$S.log 2>&1 || exit 1
fi
[ -f $D/rotate_seeds_rep3_q_s$S.json ] || python $D/rotate_seeds.py $D/rotate_seeds_rep3_q_s$S.json $P --modes \
  rotate_x+ rotate_x- rotate_y+ rotate_y- rotate_z+ rotate_z- translate_z+ translate_z- > runs/rotseeds_l1rep3q_s$S.log 2>&1 || exit 1
[ -f $D/chain_seeds_rep3_q_s$S.json ] || python $D/chain_seeds.py $D/chain_seeds_rep3_q_s$S.json $P \
  > runs/chainseeds_l1rep3q_s$S.log 2>&1 || exit 1
echo DONE
