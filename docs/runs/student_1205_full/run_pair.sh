#!/bin/bash
# The student shipped on 2026-12-05 and the expert of SKILL (grasp or relocate; relocate also the zero action) on the
# paper's full test protocol (400 test objects x 25), paired by trial, under 12 solver iterations (the experts' full
# test runs of docs/record/full_protocol.md were under 8). 2-core VM, commit 66dc653; ~10 min per policy alone.
# With --disturb: relocate's expert and the zero action under the disturbance (commit 869025c, beside a CI run; the
# outcomes are seeded per trial, so the load changes only the time).
#     bash docs/runs/student_1205_full/run_pair.sh grasp|relocate
#     bash docs/runs/student_1205_full/run_pair.sh relocate --disturb
set -eu
S=$1
D=docs/runs/student_1205_full
if [ "${2:-}" = --disturb ]; then
  POLICIES="allegro/$S zero"; TAG=${S}_disturb; EXTRA=--disturb
else
  POLICIES="allegro/student allegro/$S"; TAG=$S; EXTRA=
  if [ "$S" = relocate ]; then POLICIES="$POLICIES zero"; fi
fi
for P in $POLICIES; do
  unicross eval --policy $P --protocol $S --objects test $EXTRA --workers 2 --seed 0 --out $D/test_${TAG}_${P#allegro/}.json
done
gzip -9 $D/test_${TAG}_*.json
