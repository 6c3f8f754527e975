#!/usr/bin/env bash
# After shipping: the gait itself on the rule's held-out trials, docs/results.md regenerated (rule step 5; written to
# /tmp first), then clone seeds 1 and 2 of the same recipe (reported, not chosen on). ~3 + 47 + 22 min on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/../../.."
D=docs/runs/rotate_zm_it12
H="--protocol rotate --axis z- --objects test --limit 20 --trials-per-object 3 --seed 0 --workers 2"
[ -s $D/gait_test120 ] || unicross eval --policy gait:$D/rotate_z-_it12_2.jsonl.gz $H --out $D/gait_test120 > $D/gait_eval.log 2>&1
[ -s /tmp/results63.md ] || unicross report --paper --hand allegro --limit 10 --trials-per-object 3 --min-trials 100 \
    --workers 2 --seed 0 --out /tmp/results63.md > /tmp/report63.log 2>&1
for s in 1 2; do
  [ -s runs/clone/zm_it12_s$s/policy.pt ] || python benchmarks/gait_clone.py --gait $D/rotate_z-_it12_2.jsonl.gz \
      --limit 8 --trials 2 --rounds 8 --beta 0.5 --obs-std-min 1e-2 --heldout 20 --seed $s --out runs/clone/zm_it12_s$s \
      > $D/clone_s$s.log 2>&1
  mkdir -p $D/clone_s$s && cp runs/clone/zm_it12_s$s/{log.jsonl,command.txt} $D/clone_s$s/
  [ -s $D/clone_s${s}_test120 ] || unicross eval --policy runs/clone/zm_it12_s$s/policy.pt $H --out $D/clone_s${s}_test120 \
      > /dev/null 2>&1
done
