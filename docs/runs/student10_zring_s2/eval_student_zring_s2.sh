#!/bin/bash
# the nine held-out evaluations of student seed 2 (teachers: the shipped ten with translate z- the sequence clone)
o=runs/student10_zring_s2
P=$o/checkpoint.pt
E="--objects test --seed 0 --workers 2"
unicross eval --policy $P --protocol translate --axis z- $E --limit 20 --trials-per-object 3 --out $o/eval_translate_z-_test120.json >> $o.eval.log 2>&1
unicross eval --policy $P --protocol grasp,relocate $E --limit 10 --trials-per-object 3 --out $o/eval_test.json >> $o.eval.log 2>&1
unicross eval --policy $P --protocol translate --axis z+ $E --limit 20 --trials-per-object 3 --out $o/eval_translate_test120.json >> $o.eval.log 2>&1
for a in y+ y- z+ x+ x- z-; do unicross eval --policy $P --protocol rotate --axis $a $E --limit 20 --trials-per-object 3 --out $o/eval_rotate_${a}_test120.json >> $o.eval.log 2>&1; done
echo "done $(date)"
