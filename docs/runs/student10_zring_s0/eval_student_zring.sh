#!/bin/bash
# the nine held-out evaluations of any student run (unicross distill --out RUN_DIR), written into RUN_DIR;
# usage: bash eval_student_zring.sh [RUN_DIR]   (default runs/student10_zring_s0; used for runs/student10_zring_s{0,1,2}
# (translate z- teacher: the ring clone) and runs/student10_relay_s0 (the relay clone, the shipped student))
o=${1:-runs/student10_zring_s0}
P=$o/checkpoint.pt
E="--objects test --seed 0 --workers 2"
unicross eval --policy $P --protocol translate --axis z- $E --limit 20 --trials-per-object 3 --out $o/eval_translate_z-_test120.json >> $o.eval.log 2>&1
unicross eval --policy $P --protocol grasp,relocate $E --limit 10 --trials-per-object 3 --out $o/eval_test.json >> $o.eval.log 2>&1
unicross eval --policy $P --protocol translate --axis z+ $E --limit 20 --trials-per-object 3 --out $o/eval_translate_test120.json >> $o.eval.log 2>&1
for a in y+ y- z+ x+ x- z-; do unicross eval --policy $P --protocol rotate --axis $a $E --limit 20 --trials-per-object 3 --out $o/eval_rotate_${a}_test120.json >> $o.eval.log 2>&1; done
echo "done $(date)"
