#!/bin/bash
# The shipped student (chain stage, 2026-12-04) and its translate experts on the paper's full test protocols for
# translation (200 elongated test objects x 25 trials per direction), paired by trial, under 12 solver iterations (the
# default since 2026-12-04), 2-core VM. The translate z- expert here is the clone shipped on 2026-12-04 (43rd session),
# never run on the full protocol before.
set -eu
D=docs/runs/student_test_full
for AX in z- z+; do
  for P in allegro/student allegro/translate_$AX; do
    N=${P#allegro/}
    unicross eval --policy $P --protocol translate --axis $AX --objects test --workers 2 --seed 0 \
      --out $D/test_translate_${AX/-/m}_${N/-/m}.json
  done
done
gzip -9 $D/*.json   # the results as committed (unicross.evaluation.read_results reads .json.gz)
