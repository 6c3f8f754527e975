#!/bin/bash
# seeds 1 and 2 of the shipped student's recipe (teachers: the ten shipped checkpoints of 417c93f; code head 3858ec5)
cd "$(dirname "$0")/../../.."  # the repository root
for s in 1 2; do
  o=runs/student10_zpull_s$s
  E="--objects test --seed 0 --workers 2"
  unicross distill --experts runs/experts10_zpull --out $o --epochs 1500 --set env.object_limit=null --set collector.rollout_steps=256 --set optim.grad_steps=30 --set optim.batch_size=1024 --set buffer.capacity=300000 --set logging.checkpoint_every=25 --set seed=$s > $o.log 2>&1 || { echo "distill $s failed"; exit 1; }
  P=$o/checkpoint.pt
  unicross eval --policy $P --protocol translate --axis z- $E --limit 20 --trials-per-object 3 --out $o/eval_translate_z-_test120.json >> $o.eval.log 2>&1
  unicross eval --policy $P --protocol grasp,relocate $E --limit 10 --trials-per-object 3 --out $o/eval_test.json >> $o.eval.log 2>&1
  unicross eval --policy $P --protocol translate --axis z+ $E --limit 20 --trials-per-object 3 --out $o/eval_translate_test120.json >> $o.eval.log 2>&1
  for a in y+ y- z+ x+ x- z-; do unicross eval --policy $P --protocol rotate --axis $a $E --limit 20 --trials-per-object 3 --out $o/eval_rotate_${a}_test120.json >> $o.eval.log 2>&1; done
  echo "seed $s done $(date)"
done
echo all done
