#!/bin/bash
# The student shipped on 2026-12-05 afternoon (docs/runs/translate_zm_reference/thickness/, rule.txt step 6) on the
# paper's full protocols, to be paired by trial with its experts' runs under the same physics (12 solver iterations):
# test translate z- (200 x 25; the expert: ../translate_zm_reference/thickness/full/clone_test_full), unseen grasp
# (400 x 25; the expert: ../student_chain_full/), test translate z+ (the expert: ../student_test_full/) and unseen
# translate z+ (../student_chain_full/). 2-core VM, ~4 min per translate run, ~8 for unseen grasp.
set -eu
D=docs/runs/student_thick_full
unicross eval --policy allegro/student --protocol translate --axis z- --objects test --workers 2 --seed 0 --out $D/test_translate_zm_student.json
unicross eval --policy allegro/student --protocol grasp --objects unseen --workers 2 --seed 0 --out $D/unseen_grasp_student.json
unicross eval --policy allegro/student --protocol translate --axis z+ --objects test --workers 2 --seed 0 --out $D/test_translate_zp_student.json
unicross eval --policy allegro/student --protocol translate --axis z+ --objects unseen --workers 2 --seed 0 --out $D/unseen_translate_zp_student.json
gzip -9 $D/*.json   # the results as committed (unicross.evaluation.read_results reads .json.gz)
