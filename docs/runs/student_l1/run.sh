#!/bin/bash
# rule.txt steps 1-3: the weight-30 stage with optim.l1=0.01 on the shipped experts, seeds 0, 1, 2, each followed by
# its report cells; stops after seed 0 when its x+ cell is below 19 (step 3).
#   nohup bash docs/runs/student_l1/run.sh > runs/student_l1.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
[ -f runs/student_1204_morning.pt ] || git show e10d371:unicross/checkpoints/allegro/student.pt > runs/student_1204_morning.pt
for S in 0 1 2; do
  R=runs/l1_w30_s$S
  if [ ! -f $D/student_cells_s$S.json ]; then
    stage runs/experts1205x $R $S || exit 1
    unicross export $R --out $D/student_l1_s$S.pt || exit 1
    python docs/runs/student_ft_1202b/seed_cells.py $D/student_l1_s$S.pt $D/student_cells_s$S.json > runs/cells_l1_s$S.log 2>&1 || exit 1
  fi
  if [ $S = 0 ] && ! python -c "import json,sys; c=json.load(open('$D/student_cells_s0.json')); sys.exit(c['test']['rotate_x+']['summary']['sr'] < 19)"; then
    echo "GATE: seed 0's x+ cell is below 19; rule.txt step 3 ends FAILED"; echo DONE; exit 0
  fi
done
python docs/runs/student_xp_drift/judge3.py $D/student_cells_s0.json $D/student_cells_s1.json $D/student_cells_s2.json | tee $D/judge.txt
echo DONE
