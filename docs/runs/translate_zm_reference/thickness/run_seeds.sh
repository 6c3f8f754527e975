#!/bin/bash
# Seeds 1 and 2 of the clone (rule.txt step 4's command, --seed 1 / 2): the report's test cell and the full test
# protocol of each (from the repository root, 2-core VM, ~7 min per seed).
set -e
D=docs/runs/translate_zm_reference/thickness
TEACHER=$(cat $D/teacher.txt)
for s in 1 2; do
    python benchmarks/gait_clone.py --sequence "$TEACHER" --mode translate_z- --limit 32 --trials 2 --rounds 6 \
        --beta 0.5 --workers 2 --seed $s --out runs/clone_zm_thick_s$s
    mkdir -p $D/clone_s$s
    cp runs/clone_zm_thick_s$s/log.jsonl runs/clone_zm_thick_s$s/command.txt $D/clone_s$s/
    unicross eval --policy runs/clone_zm_thick_s$s/policy.pt --protocol translate --axis z- --objects test --limit 10 \
        --trials-per-object 5 --seed 0 --workers 2 --out $D/clone_s$s/report_test.json
    unicross eval --policy runs/clone_zm_thick_s$s/policy.pt --protocol translate --axis z- --objects test --workers 2 \
        --seed 0 --out runs/zm_thick_clone_s${s}_full.json
    gzip -9 -c runs/zm_thick_clone_s${s}_full.json > $D/full/clone_s${s}_test_full.json.gz
    cp runs/zm_thick_clone_s${s}_full.md $D/full/clone_s${s}_test_full.md
done
