#!/bin/bash
# rule.txt screen I: screen G's recipe unchanged (common.sh: ship_screen 10) on fresh training seeds 4, 5, 6, each
# student's rotate cells also under evaluation seeds 1-3 (rotate_seeds.py); `run_i.sh experts` first measures the
# six rotate experts under evaluation seeds 0-3 (the bars, I1). Judged by judge_i.py (I3). Each step is skipped when
# its file exists, so a call resumes.
#   nohup bash -c 'for s in experts 4 5 6; do bash docs/runs/student_l1/run_i.sh $s || exit 1; done' > runs/student_l1_i.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
S=${1:-4}
if [ "$S" = experts ]; then
  [ -f $D/rotate_seeds_experts.json ] \
    || python $D/rotate_seeds.py $D/rotate_seeds_experts.json experts --seeds 0 1 2 3 > runs/rotseeds_experts.log 2>&1 \
    || exit 1
  echo DONE; exit 0
fi
ship_screen 10 $S || exit 1
[ -f $D/rotate_seeds_rep3_w10ship_s$S.json ] \
  || python $D/rotate_seeds.py $D/rotate_seeds_rep3_w10ship_s$S.json $D/student_l1_rep3_w10ship_s$S.pt \
       > runs/rotseeds_l1rep3w10ship_s$S.log 2>&1 || exit 1
echo DONE
