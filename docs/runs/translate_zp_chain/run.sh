#!/bin/bash
# rule.txt: the chain-aware PPO fine-tune of translate z+ (after the dataset of rule.txt is in runs/tzpchain), then
# every held-out run of the rule for both sides into runs/tzpchain, then the judge. Each step is skipped when its file
# exists, so a call resumes.  nohup bash docs/runs/translate_zp_chain/run.sh > runs/tzpchain/run.log 2>&1 &
# `run.sh shipped` runs only the shipped expert's side (which needs no candidate), e.g. at nice 19 beside the training.
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
R=runs/tzpchain
MODES="grasp relocate rotate_x+ rotate_x- rotate_y+ rotate_y- rotate_z+ rotate_z- translate_z+ translate_z-"
SIDES="cand shipped"
[ "$1" = shipped ] && SIDES=shipped
[ -f $R/grasps_chain_train.pt ] || { echo "make the dataset first (rule.txt)"; exit 1; }
if [ "$1" != shipped ] &&  [ ! -f $R/ft_s0/policy.pt ]; then
  RES=; [ -f $R/ft_s0/checkpoint.pt ] && RES=--resume
  unicross train --skill translate --axis z+ --out $R/ft_s0 --total-frames 245760 --set seed=0 \
    --set collector.frames_per_batch=4096 --set optim.kl_stop=0.032 --set model.init_log_std=-2.5 \
    --set model.init_policy=allegro/translate_z+ --set optim.critic_warmup=5 \
    --set env.grasp_dataset=$R/grasps_chain_train.pt $RES > $R/ft_s0.log 2>&1 || exit 1
  unicross export $R/ft_s0 --out $R/ft_s0/policy.pt || exit 1
fi
[ "$1" = shipped ] || for m in $MODES; do  # the ten shipped experts, translate z+ replaced by the candidate
  mkdir -p $R/experts_cand/$m
  cp unicross/checkpoints/allegro/$m.pt $R/experts_cand/$m/checkpoint.pt
done
[ "$1" = shipped ] || cp $R/ft_s0/policy.pt $R/experts_cand/translate_z+/checkpoint.pt
for S in 0 1 2 3; do
  for who in $SIDES; do
    if [ $who = shipped ]; then E=experts:allegro P=allegro/translate_z+; else E=experts:$R/experts_cand P=$R/ft_s0/policy.pt; fi
    [ -f $R/chain_${who}_s$S.json ] || unicross chain --policy $E --sequence grasp,relocate,translate:z+ --objects test \
      --limit 10 --trials-per-object 5 --seed $S --out $R/chain_${who}_s$S.json > $R/chain_${who}_s$S.log 2>&1 || exit 1
    [ -f $R/cell_${who}_s$S.json ] || unicross eval --policy $P --protocol translate --axis z+ --objects test --limit 10 \
      --trials-per-object 5 --seed $S --workers 2 --out $R/cell_${who}_s$S.json > $R/cell_${who}_s$S.log 2>&1 || exit 1
  done
done
[ "$1" = shipped ] || python docs/runs/translate_zm_chain/judge.py $R --mode translate_z+ --gain 3 > $R/judge_ab.txt
for S in 0 1 2 3; do
  for who in $SIDES; do
    if [ $who = shipped ]; then P=allegro/translate_z+; else P=$R/ft_s0/policy.pt; fi
    [ -f $R/unseen_${who}_s$S.json ] || unicross eval --policy $P --protocol translate --axis z+ --objects unseen --limit 10 \
      --trials-per-object 5 --seed $S --workers 2 --out $R/unseen_${who}_s$S.json > $R/unseen_${who}_s$S.log 2>&1 || exit 1
    [ -f $R/dist_${who}_s$S.json ] || unicross eval --policy $P --protocol translate --axis z+ --objects test --disturb \
      --limit 10 --trials-per-object 5 --seed $S --workers 2 --out $R/dist_${who}_s$S.json > $R/dist_${who}_s$S.log 2>&1 || exit 1
  done
done
[ "$1" = shipped ] || python docs/runs/translate_zm_chain/judge.py $R --mode translate_z+ --gain 3 --guard > $R/judge.txt
echo DONE
