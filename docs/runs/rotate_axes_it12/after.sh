#!/usr/bin/env bash
# After shipping axis AX (y+: rule step 4b; z+: rule2.txt, 69th session): the gait itself on the rule's 120 held-out
# trials, then clone seeds 1 and 2 of the shipped recipe (reported, not chosen on; three seeds before calling the
# recipe stable), each on the same 120 held-out trials. As rotate_zm_it12/after.sh without the report.
# ~3 + 2 x 12 min on 2 cores; skips what exists.
#   bash docs/runs/rotate_axes_it12/after.sh y+
set -euo pipefail
cd "$(dirname "$0")/../../.."
AX=${1:-y+}
D=docs/runs/rotate_axes_it12/$AX
case $AX in  # the gait each shipped clone was made from (its clone_s0/command.txt)
  y+) G=$D/rotate_y+_it12_2.jsonl.gz ;;
  z+) G=$D/rotate_z+_it12_A.jsonl.gz ;;
  *) echo "axis must be y+ or z+ (the axes shipped by rule.txt / rule2.txt)" >&2; exit 2 ;;
esac
H="--protocol rotate --axis $AX --objects test --limit 20 --trials-per-object 3 --seed 0 --workers 2"
[ -s $D/gait_test120 ] || unicross eval --policy gait:$G $H --out $D/gait_test120 > $D/gait_eval.log 2>&1
for s in 1 2; do
  [ -s runs/clone/${AX}_it12_s$s/policy.pt ] || python benchmarks/gait_clone.py --gait $G --limit 8 --trials 2 \
      --rounds 8 --beta 0.5 --obs-std-min 1e-2 --heldout 20 --seed $s --out runs/clone/${AX}_it12_s$s > $D/clone_s$s.log 2>&1
  mkdir -p $D/clone_s$s && cp runs/clone/${AX}_it12_s$s/{log.jsonl,command.txt} $D/clone_s$s/
  [ -s $D/clone_s${s}_test120 ] || unicross eval --policy runs/clone/${AX}_it12_s$s/policy.pt $H \
      --out $D/clone_s${s}_test120 > $D/clone_s${s}_eval.log 2>&1
done
