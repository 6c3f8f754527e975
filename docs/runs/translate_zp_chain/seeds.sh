#!/bin/bash
# Seeds 1 and 2 of rule.txt's candidate (reported, choose nothing): the same training with --set seed=S into
# runs/tzpchain/ft_sS, then bars (a) and (b)'s runs for it (chain_candS_sE, cell_candS_sE, evaluation seeds E = 0-3;
# the shipped side's files are run.sh's). Each step is skipped when its file exists.
#   nohup bash docs/runs/translate_zp_chain/seeds.sh 1 2 > runs/tzpchain/seeds.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
R=runs/tzpchain
MODES="grasp relocate rotate_x+ rotate_x- rotate_y+ rotate_y- rotate_z+ rotate_z- translate_z+ translate_z-"
for S in "$@"; do
  if [ ! -f $R/ft_s$S/policy.pt ]; then
    RES=; [ -f $R/ft_s$S/checkpoint.pt ] && RES=--resume
    unicross train --skill translate --axis z+ --out $R/ft_s$S --total-frames 245760 --set seed=$S \
      --set collector.frames_per_batch=4096 --set optim.kl_stop=0.032 --set model.init_log_std=-2.5 \
      --set model.init_policy=allegro/translate_z+ --set optim.critic_warmup=5 \
      --set env.grasp_dataset=$R/grasps_chain_train.pt $RES > $R/ft_s$S.log 2>&1 || exit 1
    unicross export $R/ft_s$S --out $R/ft_s$S/policy.pt || exit 1
  fi
  for m in $MODES; do
    mkdir -p $R/experts_c$S/$m
    cp unicross/checkpoints/allegro/$m.pt $R/experts_c$S/$m/checkpoint.pt
  done
  cp $R/ft_s$S/policy.pt $R/experts_c$S/translate_z+/checkpoint.pt
  for E in 0 1 2 3; do
    [ -f $R/chain_cand${S}_s$E.json ] || unicross chain --policy experts:$R/experts_c$S --sequence grasp,relocate,translate:z+ \
      --objects test --limit 10 --trials-per-object 5 --seed $E --out $R/chain_cand${S}_s$E.json > $R/chain_cand${S}_s$E.log 2>&1 || exit 1
    [ -f $R/cell_cand${S}_s$E.json ] || unicross eval --policy $R/ft_s$S/policy.pt --protocol translate --axis z+ --objects test \
      --limit 10 --trials-per-object 5 --seed $E --workers 2 --out $R/cell_cand${S}_s$E.json > $R/cell_cand${S}_s$E.log 2>&1 || exit 1
  done
done
echo DONE
