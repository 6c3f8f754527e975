#!/bin/bash
# The shipped student (chain stage, 2026-12-04) and its experts on the paper's full protocols where the students before
# it lost ground unseen (docs/record/full_protocol.md), paired by trial, under 12 solver iterations (the default since
# 2026-12-04), 2-core VM: unseen translate z+ (200 objects x 25), then unseen grasp (400 x 25).
set -eu
D=docs/runs/student_chain_full
for P in allegro/student allegro/translate_z+; do
  unicross eval --policy $P --protocol translate --axis z+ --objects unseen --workers 2 --seed 0 --out $D/unseen_translate_zp_${P#allegro/}.json
done
for P in allegro/student allegro/grasp; do
  unicross eval --policy $P --protocol grasp --objects unseen --workers 2 --seed 0 --out $D/unseen_grasp_${P#allegro/}.json
done
gzip -9 $D/*.json   # the results as committed (unicross.evaluation.read_results reads .json.gz)
