set -e
R=runs/student10_zpull_s0
P=$R/checkpoint.pt
E="--objects test --seed 0 --workers 2"
unicross eval --policy $P --protocol translate --axis z- $E --limit 20 --trials-per-object 3 --out $R/eval_translate_z-_test120.json
unicross eval --policy $P --protocol grasp,relocate $E --limit 10 --trials-per-object 3 --out $R/eval_test.json
unicross eval --policy $P --protocol translate --axis z+ $E --limit 20 --trials-per-object 3 --out $R/eval_translate_test120.json
for a in y+ y- z+ x+ x- z-; do unicross eval --policy $P --protocol rotate --axis $a $E --limit 20 --trials-per-object 3 --out $R/eval_rotate_${a}_test120.json; done
echo ALLDONE
