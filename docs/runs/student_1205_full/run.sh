#!/bin/bash
# The student shipped on 2026-12-05 (docs/runs/student_yplus_repeat/, seed 0 of rule_init.txt) on the paper's full
# protocols its predecessors were measured on, paired by trial with its experts' runs under the same physics (12 solver
# iterations, the default since 2026-12-04): test translate z+ (200 x 25; the expert: ../student_test_full/), unseen
# translate z+ (200 x 25) and unseen grasp (400 x 25; the experts: ../student_chain_full/). 2-core VM, commit e5bd11e.
set -eu
D=docs/runs/student_1205_full
unicross eval --policy allegro/student --protocol translate --axis z+ --objects test --workers 2 --seed 0 --out $D/test_translate_zp_student.json
unicross eval --policy allegro/student --protocol translate --axis z+ --objects unseen --workers 2 --seed 0 --out $D/unseen_translate_zp_student.json
unicross eval --policy allegro/student --protocol grasp --objects unseen --workers 2 --seed 0 --out $D/unseen_grasp_student.json
gzip -9 $D/*.json   # the results as committed (unicross.evaluation.read_results reads .json.gz)
