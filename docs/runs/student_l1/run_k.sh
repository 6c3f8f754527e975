#!/bin/bash
# rule.txt screen K: `run_k.sh shipped` first measures the shipped student's long horizon under evaluation seeds 0-3
# (the long-horizon bars, K1); `run_k.sh SEED` runs J's recipe on one training seed (run_i.sh SEED 5: the stage, the
# report's cells, the rotate cells under evaluation seeds 1-3, held-out x+), then the student's long horizon under
# evaluation seeds 1-3 (chain_seeds.py). Judged by judge_i.py K (K3). Each step is skipped when its file exists.
#   nohup bash -c 'for s in shipped 10 11 12; do bash docs/runs/student_l1/run_k.sh $s || exit 1; done' > runs/student_l1_k.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
D=docs/runs/student_l1
S=$1
if [ "$S" = shipped ]; then
  [ -f $D/chain_seeds_shipped.json ] \
    || python $D/chain_seeds.py $D/chain_seeds_shipped.json allegro/student --seeds 0 1 2 3 > runs/chainseeds_shipped.log 2>&1 \
    || exit 1
  echo DONE; exit 0
fi
bash $D/run_i.sh $S 5 || exit 1
[ -f $D/chain_seeds_rep3_w5ship_s$S.json ] \
  || python $D/chain_seeds.py $D/chain_seeds_rep3_w5ship_s$S.json $D/student_l1_rep3_w5ship_s$S.pt \
       > runs/chainseeds_l1rep3w5ship_s$S.log 2>&1 || exit 1
echo DONE
