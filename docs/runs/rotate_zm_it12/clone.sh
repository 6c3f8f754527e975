#!/usr/bin/env bash
# Rule step 3 on the candidate gait LOG: its clone (the shipped z- recipe, seed 0) and the replaced expert's cell on
# the same 120 held-out trials (for step 4). Called by run.sh and run2.sh; skips what exists. ~10 min, 2 cores.
set -euo pipefail
cd "$(dirname "$0")/../../.."
D=docs/runs/rotate_zm_it12
[ -s runs/clone/zm_it12/policy.pt ] || python benchmarks/gait_clone.py --gait "$1" --limit 8 --trials 2 --rounds 8 \
    --beta 0.5 --obs-std-min 1e-2 --heldout 20 --seed 0 --out runs/clone/zm_it12 > $D/clone.log 2>&1
[ -s $D/shipped_test120 ] || unicross eval --policy allegro/rotate_z- --protocol rotate --axis z- --objects test \
    --limit 20 --trials-per-object 3 --seed 0 --workers 2 --out $D/shipped_test120 > $D/shipped_eval.log 2>&1
