#!/usr/bin/env bash
# rule.txt step 4b for AX (y+): the step-3 clone (seed 0) and the shipped expert on the same cell under evaluation
# seeds 1, 2, 3 (360 fresh trials), paired by trial on those alone -> AX/paired_confirm.txt. ~15 min on 2 cores.
# With a second argument 480 (rule2.txt step 4, z+ and y-): seeds 0-3 pooled (run.sh made seed 0's cells)
# -> AX/paired_480.txt.
#   bash docs/runs/rotate_axes_it12/confirm.sh y+
#   bash docs/runs/rotate_axes_it12/confirm.sh z+ 480
set -euo pipefail
cd "$(dirname "$0")/../../.."
AX=$1
D=docs/runs/rotate_axes_it12/$AX
H="--protocol rotate --axis $AX --objects test --limit 20 --trials-per-object 3 --workers 2"
for s in 1 2 3; do
  [ -s $D/clone_s0_test120_seed$s ] || unicross eval --policy runs/clone/${AX}_it12/policy.pt $H --seed $s \
      --out $D/clone_s0_test120_seed$s > /dev/null 2>&1
  [ -s $D/shipped_test120_seed$s ] || unicross eval --policy allegro/rotate_$AX $H --seed $s \
      --out $D/shipped_test120_seed$s > /dev/null 2>&1
done
if [ "${2:-}" = 480 ]; then
  S0=("$D/clone_s0_test120," "$D/shipped_test120,"); OUT=$D/paired_480.txt
else
  S0=("" ""); OUT=$D/paired_confirm.txt
fi
python docs/runs/paper_protocol/paired.py \
    ${S0[0]}$D/clone_s0_test120_seed1,$D/clone_s0_test120_seed2,$D/clone_s0_test120_seed3 \
    ${S0[1]}$D/shipped_test120_seed1,$D/shipped_test120_seed2,$D/shipped_test120_seed3 --skill rotate 2>/dev/null \
    | tee $OUT
