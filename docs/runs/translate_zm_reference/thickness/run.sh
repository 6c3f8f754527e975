#!/bin/bash
# The thickness-switched translate z- teacher (rule.txt steps 3-5), from the repository root, 2-core VM (~15 min).
set -e
D=docs/runs/translate_zm_reference/thickness
SHIP=$(cat docs/runs/translate_zm_reference/second_phase/chosen.txt)
TEACHER=$(cat $D/teacher.txt)
# 3. The teacher and the shipped sequence on every training stick x 2 starts (seed 500; search3.py's selection).
python $D/teacher_train.py "$TEACHER" "$SHIP" | tee $D/teacher_train.txt
# 4. The clone (the shipped clone's command; --limit 32: the first 16 training objects per group hold 1 thin cylinder).
python benchmarks/gait_clone.py --sequence "$TEACHER" --mode translate_z- --limit 32 --trials 2 --rounds 6 \
    --beta 0.5 --workers 2 --seed 0 --out runs/clone_zm_thick_s0
# 5. The full test protocol (every test stick x 25): the clone, then the teacher itself.
unicross eval --policy runs/clone_zm_thick_s0/policy.pt --protocol translate --axis z- --objects test --workers 2 \
    --seed 0 --out runs/zm_thick_clone_full.json
unicross eval --policy "seq:$TEACHER" --protocol translate --axis z- --objects test --workers 2 --seed 0 \
    --out runs/zm_thick_teacher_full.json
