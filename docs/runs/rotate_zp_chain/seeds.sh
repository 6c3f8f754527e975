#!/bin/bash
# Clone seeds 1 and 2 of the shipped chain-aware z+ recipe (rule.txt: other seeds are reported and choose nothing):
# each clone, then bars (a) and (b)'s runs for it (the chain grasp,relocate,rotate:z+ with the ten shipped experts,
# rotate z+ replaced by it, and the report's z+ cell, evaluation seeds 0-3) into runs/zpchain_seeds/. Each step is
# skipped when its file exists.  nohup bash docs/runs/rotate_zp_chain/seeds.sh 1 2 > runs/zpchain_seeds.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
O=runs/zpchain_seeds
MODES="grasp relocate rotate_x+ rotate_x- rotate_y+ rotate_y- rotate_z+ rotate_z- translate_z+ translate_z-"
mkdir -p $O
for C in "$@"; do
  R=runs/clone/zp_chain_s$C
  [ -f $R/policy.pt ] || python benchmarks/gait_clone.py --gait docs/runs/rotate_axes_it12/z+/rotate_z+_it12_A.jsonl.gz \
    --limit 8 --trials 2 --rounds 8 --beta 0.5 --obs-std-min 1e-2 --heldout 20 --seed $C \
    --grasps docs/runs/rotate_zp_chain/grasps_chain_train.pt --out $R > runs/clone_zp_chain_s$C.log 2>&1 || exit 1
  for m in $MODES; do
    mkdir -p $O/experts_c$C/$m
    cp unicross/checkpoints/allegro/$m.pt $O/experts_c$C/$m/checkpoint.pt
  done
  cp $R/policy.pt $O/experts_c$C/rotate_z+/checkpoint.pt
  for S in 0 1 2 3; do
    [ -f $O/chain_c${C}_s$S.json ] || unicross chain --policy experts:$O/experts_c$C --sequence grasp,relocate,rotate:z+ \
      --objects test --limit 10 --trials-per-object 5 --seed $S --out $O/chain_c${C}_s$S.json > $O/chain_c${C}_s$S.log 2>&1 || exit 1
    [ -f $O/cell_c${C}_s$S.json ] || unicross eval --policy $R/policy.pt --protocol rotate --axis z+ --objects test \
      --limit 10 --trials-per-object 5 --seed $S --workers 2 --out $O/cell_c${C}_s$S.json > $O/cell_c${C}_s$S.log 2>&1 || exit 1
  done
done
echo DONE
