#!/bin/bash
# The student shipped on 2026-12-05 and the expert of SKILL (grasp or relocate; relocate also the zero action) on the
# paper's full test protocol (400 test objects x 25), paired by trial, under 12 solver iterations (the experts' full
# test runs of docs/record/full_protocol.md were under 8). 2-core VM, commit 66dc653; ~10 min per policy.
#     bash docs/runs/student_1205_full/run_pair.sh grasp|relocate
set -eu
S=$1
D=docs/runs/student_1205_full
POLICIES="allegro/student allegro/$S"
if [ "$S" = relocate ]; then POLICIES="$POLICIES zero"; fi
for P in $POLICIES; do
  unicross eval --policy $P --protocol $S --objects test --workers 2 --seed 0 --out $D/test_${S}_${P#allegro/}.json
done
gzip -9 $D/test_${S}_*.json
