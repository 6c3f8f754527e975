#!/bin/bash
# rule.txt screens I and J: `run_i.sh SEED [WEIGHT]` runs G's recipe (common.sh: ship_screen WEIGHT SEED; WEIGHT the
# x+ weight, 10 by default) on one training seed, then the student's rotate cells under evaluation seeds 1-3
# (rotate_seeds.py); `run_i.sh experts` first measures the six rotate experts under evaluation seeds 0-3 (the bars,
# I1). Judged by judge_i.py (I3, J3). Each step is skipped when its file exists, so a call resumes.
#   screen I: nohup bash -c 'for s in experts 4 5 6; do bash docs/runs/student_l1/run_i.sh $s || exit 1; done' > runs/student_l1_i.log 2>&1 &
#   screen J: nohup bash -c 'for s in 7 8 9; do bash docs/runs/student_l1/run_i.sh $s 5 || exit 1; done' > runs/student_l1_j.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
S=${1:-4}
W=${2:-10}
if [ "$S" = experts ]; then
  [ -f $D/rotate_seeds_experts.json ] \
    || python $D/rotate_seeds.py $D/rotate_seeds_experts.json experts --seeds 0 1 2 3 > runs/rotseeds_experts.log 2>&1 \
    || exit 1
  echo DONE; exit 0
fi
ship_screen $W $S || exit 1
[ -f $D/rotate_seeds_rep3_w${W}ship_s$S.json ] \
  || python $D/rotate_seeds.py $D/rotate_seeds_rep3_w${W}ship_s$S.json $D/student_l1_rep3_w${W}ship_s$S.pt \
       > runs/rotseeds_l1rep3w${W}ship_s$S.log 2>&1 || exit 1
echo DONE
