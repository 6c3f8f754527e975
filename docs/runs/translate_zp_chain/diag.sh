#!/bin/bash
# Diagnosis after the judge (chooses nothing): both translate z+ policies from the chain's own settled states on the
# test sticks (../translate_zm_chain/'s diagnosis dataset, made again), n = 100 each.
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
R=runs/tzpchain
[ -f $R/grasps_chain_test.pt ] || unicross grasps --chain grasp,relocate --policy experts:allegro --objects test-elongated \
  --per-object 2 --seed 2 --out $R/grasps_chain_test.pt > $R/grasps_test.log 2>&1 || exit 1
for who in shipped cand; do
  if [ $who = shipped ]; then P=allegro/translate_z+; else P=$R/ft_s0/policy.pt; fi
  [ -f $R/diag_$who.json ] || unicross eval --policy $P --protocol translate --axis z+ --objects test --limit 10 \
    --trials-per-object 5 --seed 0 --workers 2 --grasps $R/grasps_chain_test.pt --out $R/diag_$who.json > $R/diag_$who.log 2>&1 || exit 1
done
echo DONE
