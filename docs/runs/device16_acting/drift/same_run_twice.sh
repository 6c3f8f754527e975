#!/bin/bash
# 1-worker grasp training, 12 iterations, run twice (same seed: the same actions and physics), collection
# rate per iteration. (The "frozen" runs, fixed lr 0, were refused by the config check: lr must be > 0.)
run() {
  rm -rf /tmp/prof/lr_$1_$2
  if [ $1 = frozen ]; then extra="--set optim.schedule=fixed --set optim.lr=0.0 --set optim.lr_min=0.0"; else extra=""; fi
  timeout 900 unicross train --skill grasp --out /tmp/prof/lr_$1_$2 --num-envs 1 --total-frames 12288 \
    --set logging.eval_trials=0 --set logging.final_eval_trials=0 $extra > /tmp/prof/lr_$1_$2.log 2>&1
  python -c "
import json
rows = [json.loads(l) for l in open('/tmp/prof/lr_$1_$2/metrics.jsonl') if 'collect_s' in l]
print('$1 $2', [round(1024 / r['collect_s']) for r in rows], 'success', [round(r.get('success_rate', 0), 2) for r in rows])"
}
run learning 1; run frozen 1; run frozen 2; run learning 2
