#!/bin/bash
# The relocate expert and the zero action on the paper's full test protocol for relocation under --disturb (400 test
# objects x 25), paired by trial, under 12 solver iterations (docs/record/full_protocol.md's runs were under 8).
# 2-core VM, commit 869025c, beside a CI run (outcomes are seeded per trial: the load changes only the time).
set -eu
D=docs/runs/student_1205_full
for P in allegro/relocate zero; do
  unicross eval --policy $P --protocol relocate --objects test --disturb --workers 2 --seed 0 --out $D/test_relocate_disturb_${P#allegro/}.json
done
gzip -9 $D/test_relocate_disturb_*.json
