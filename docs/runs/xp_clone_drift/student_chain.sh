#!/bin/bash
# rule 3 step 3 of docs/runs/xp_clone_drift/rule.txt: the weight-30 student stage on the chosen floored x+ teacher
# usage: docs/runs/xp_clone_drift/student_chain.sh CAND SEED
# runs/experts1205x and runs/student_1204_morning.pt: the commands in unicross/checkpoints/allegro/student.json
set -x
cd "$(git rev-parse --show-toplevel)"
source .venv/bin/activate
C=$1; S=$2
E=runs/experts_cand_$C
mkdir -p $E
for m in grasp relocate rotate_x+ rotate_x- rotate_y+ rotate_y- rotate_z+ rotate_z- translate_z+ translate_z-; do mkdir -p $E/$m; cp runs/experts1205x/$m/checkpoint.pt $E/$m/checkpoint.pt; done
cp runs/xp_cand_$C/policy.pt $E/rotate_x+/checkpoint.pt
R=runs/xpc_${C}_w30_s$S
[ -f $R/checkpoint.pt ] && RES=--resume || RES=
unicross distill --experts $E --out $R --epochs 1500 $RES --set model.init_policy=runs/student_1204_morning.pt --set optim.lr=1.0e-4 --set optim.warmup_frames=102400 --set env.object_limit=null --set collector.rollout_steps=256 --set optim.grad_steps=30 --set optim.batch_size=1024 --set buffer.capacity=300000 --set logging.checkpoint_every=25 --set seed=$S --set env.chain_share=0.15 --set 'optim.mode_weights={rotate_x+: 30}' > $R.log 2>&1
unicross export $R --out docs/runs/xp_clone_drift/student_cand_${C}_s$S.pt
python docs/runs/student_ft_1202b/seed_cells.py docs/runs/xp_clone_drift/student_cand_${C}_s$S.pt docs/runs/xp_clone_drift/student_cells_cand_${C}_s$S.json > runs/cells_cand_${C}_s$S.log 2>&1
echo DONE
