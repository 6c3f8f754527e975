#!/bin/bash
# Seeds 1 and 2 of the x+ clone (rule.txt step 3's command), each on the 120 held-out trials of step 2 (~12 min each).
set -e
D=docs/runs/rotate_sequences
for s in 1 2; do
    python benchmarks/gait_clone.py --sequence "$(cat $D/x+/chosen.txt)" --mode rotate_x+ --limit 32 --trials 2 \
        --rounds 6 --beta 0.5 --workers 2 --seed $s --out runs/rot_seq_x+_s$s > $D/x+/clone_s$s.log 2>&1
    unicross eval --policy runs/rot_seq_x+_s$s/policy.pt --protocol rotate --axis x+ --objects test --limit 20 \
        --trials-per-object 3 --seed 0 --workers 2 --out $D/x+/clone_s${s}_test.json
done
