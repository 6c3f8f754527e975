# Shared by the run scripts of this folder (sourced from the repository root, the venv active).
D=docs/runs/student_l1
MODES="grasp relocate rotate_x+ rotate_x- rotate_y+ rotate_y- rotate_z+ rotate_z- translate_z+ translate_z-"

# stage EXPERTS OUT SEED [--set ...]: the weight-30 stage with optim.l1 = 0.01 (rule.txt step 1), resumed when OUT has
# a checkpoint; extra arguments are appended (screen C's env.mode_repeats); EPOCHS overrides the 1500 epochs (screen E)
stage() {
  local E=$1 R=$2 S=$3 RES=
  shift 3
  experts_dir || return 1
  [ -f $R/checkpoint.pt ] && RES=--resume
  unicross distill --experts $E --out $R --epochs ${EPOCHS:-1500} $RES --set model.init_policy=runs/student_1204_morning.pt --set optim.lr=1.0e-4 --set optim.warmup_frames=102400 --set env.object_limit=null --set collector.rollout_steps=256 --set optim.grad_steps=30 --set optim.batch_size=1024 --set buffer.capacity=300000 --set logging.checkpoint_every=25 --set seed=$S --set env.chain_share=0.15 --set 'optim.mode_weights={rotate_x+: 30}' --set optim.l1=0.01 "$@" > $R.log 2>&1
}

# experts_dir: runs/experts1205x (the ten experts shipped when screens A-L ran, unicross/checkpoints/allegro/<mode>.pt
# of commit a60ae24^, before the z- and y+ experts were replaced, as <mode>/checkpoint.pt) and
# runs/student_1204_morning.pt (the stage's default init), made when missing (a fresh checkout); stage and
# experts_with_xp call it
experts_dir() {
  experts_at a60ae24^ runs/experts1205x || return 1
  [ -f runs/student_1204_morning.pt ] || git show e10d371:unicross/checkpoints/allegro/student.pt > runs/student_1204_morning.pt
}

# experts_at COMMIT DIR: the ten experts shipped at COMMIT (unicross/checkpoints/allegro/<mode>.pt) as
# DIR/<mode>/checkpoint.pt, each made when missing
experts_at() {
  local m
  for m in $MODES; do
    [ -f $2/$m/checkpoint.pt ] && continue
    mkdir -p $2/$m && git show $1:unicross/checkpoints/allegro/$m.pt > $2/$m/checkpoint.tmp \
      && mv $2/$m/checkpoint.tmp $2/$m/checkpoint.pt || return 1
  done
}

# experts_with_xp DIR POLICY: the shipped experts (runs/experts1205x) with rotate_x+ replaced by POLICY
experts_with_xp() {
  local m
  experts_dir || return 1
  for m in $MODES; do
    mkdir -p $1/$m; cp runs/experts1205x/$m/checkpoint.pt $1/$m/checkpoint.pt
  done
  cp $2 $1/rotate_x+/checkpoint.pt
}

# screen POLICY OUT.json OBJECTS LIMIT LABELLER: drift.py (docs/runs/student_xp_drift) on OBJECTS x 3 trials, paths
# relative to the repository root
screen() {
  python docs/runs/student_xp_drift/drift.py $1 $2 --objects $3 --limit $4 --trials 3 --labeller $5
}

# rep_screen RUN TAG SEED [stage arguments]: screens C, E, F, G and H (run_c.sh ... run_h.sh): the stage into RUN
# with x+ walked three times plus the arguments, its export $D/student_l1_rep3TAG_sSEED.pt (TAG "" for C, "_e1800",
# "_w10", "_w10ship", "_w15ship"), drift.py on 300 training trials (seed 0 only), the report cells, then x+ on the 120
# held-out trials; each step skipped when its file exists
rep_screen() {
  local R=$1 X=$2 S=$3 P N
  shift 3
  P=$D/student_l1_rep3${X}_s$S.pt
  N=$(basename $R)
  if [ ! -f $D/student_cells_rep3${X}_s$S.json ]; then
    stage runs/experts1205x $R $S --set 'env.mode_repeats={rotate_x+: 3}' "$@" || return 1
    unicross export $R --out $P || return 1
    if [ "$S" = 0 ]; then
      screen $P $D/train300_student_l1_rep3${X}_s$S.json train 50 allegro/rotate_x+ > runs/drift_$N.log 2>&1 || return 1
    fi
    python docs/runs/student_ft_1202b/seed_cells.py $P $D/student_cells_rep3${X}_s$S.json > runs/cells_$N.log 2>&1 || return 1
  fi
  [ -f $D/test120_student_l1_rep3${X}_s$S.json ] \
    || screen $P $D/test120_student_l1_rep3${X}_s$S.json test 20 allegro/rotate_x+ > runs/drift_${N}_test.log 2>&1
}

# ship_screen WEIGHT SEED: screens G (weight 10) and H (weight 15): rep_screen from the shipped student with x+ weight
# WEIGHT, into runs/l1rep3wWEIGHTship_sSEED, tag _wWEIGHTship (ship.py derives the same names from the weight)
ship_screen() {
  rep_screen runs/l1rep3w$1ship_s$2 _w$1ship $2 --set "optim.mode_weights={rotate_x+: $1}" \
    --set model.init_policy=allegro/student
}

# seed_evals TAG SEED: the rotate cells (rotate_seeds.py) and the long horizon (chain_seeds.py) of
# $D/student_l1_rep3TAG_sSEED.pt under evaluation seeds 1-3 (screens L, M, N), each skipped when its file exists
seed_evals() {
  local P=$D/student_l1_rep3$1_s$2.pt N=l1rep3${1#_}_s$2
  [ -f $D/rotate_seeds_rep3$1_s$2.json ] \
    || python $D/rotate_seeds.py $D/rotate_seeds_rep3$1_s$2.json $P > runs/rotseeds_$N.log 2>&1 || return 1
  [ -f $D/chain_seeds_rep3$1_s$2.json ] \
    || python $D/chain_seeds.py $D/chain_seeds_rep3$1_s$2.json $P > runs/chainseeds_$N.log 2>&1 || return 1
}

# m_stage SEED: screen M's stage (K's arguments from K's initial student, the experts shipped at 723f266) into
# runs/l1rep3m_sSEED, resumed when it has a checkpoint (run_m.sh; run_n.sh when M's run is missing)
m_stage() {
  experts_at 723f266 runs/experts1207 || return 1
  [ -f runs/student_pre_k.pt ] || git show 06e213f^:unicross/checkpoints/allegro/student.pt > runs/student_pre_k.pt \
    || return 1
  stage runs/experts1207 runs/l1rep3m_s$1 $1 --set 'env.mode_repeats={rotate_x+: 3}' \
    --set "optim.mode_weights={rotate_x+: 5}" --set model.init_policy=runs/student_pre_k.pt
}

# resume_m TAG SEED [distill arguments]: screens N and O (run_n.sh, run_o.sh): M's run on SEED (runs/l1rep3m_sSEED,
# epoch 1500, its replay buffer; m_stage makes it again when missing) copied to runs/l1rep3TAG_sSEED (TAG without its
# underscore) and resumed to epoch 2000 with the arguments, then the export $D/student_l1_rep3TAG_sSEED.pt, its log,
# the report cells and seed_evals; each step skipped when its file exists
resume_m() {
  local X=$1 S=$2 P R
  shift 2
  P=$D/student_l1_rep3${X}_s$S.pt
  R=runs/l1rep3${X#_}_s$S
  if [ ! -f $D/student_cells_rep3${X}_s$S.json ]; then
    if [ ! -d $R ]; then
      [ -f runs/l1rep3m_s$S/checkpoint.pt ] || m_stage $S || return 1
      cp -r runs/l1rep3m_s$S $R.tmp && mv $R.tmp $R || return 1
    fi
    unicross distill --resume --out $R --epochs 2000 "$@" > $R.log 2>&1 || return 1
    unicross export $R --out $P || return 1
    cp $R/metrics.jsonl $D/metrics_rep3${X}_s$S.jsonl
    python docs/runs/student_ft_1202b/seed_cells.py $P $D/student_cells_rep3${X}_s$S.json \
      > runs/cells_l1rep3${X#_}_s$S.log 2>&1 || return 1
  fi
  seed_evals $X $S
}

# resume_o TAG SEED MODES [distill arguments]: screens P and Q (run_p.sh, run_q.sh): O's run on SEED (runs/l1rep3o_sSEED,
# epoch 2000, its replay buffer; run_o.sh makes it again when missing) copied to runs/l1rep3TAG_sSEED (TAG without its
# underscore) and resumed to epoch 2500 with runs/experts1207p (the experts of 723f266 with the rotate z+ expert of
# 564f969; the resume labels the buffer again by them) and O's arguments plus the given ones, then the export
# $D/student_l1_rep3TAG_sSEED.pt, its log, the report cells, rotate_seeds.py on MODES ("" for its six rotate modes)
# and chain_seeds.py under evaluation seeds 1-3; each step skipped when its file exists
resume_o() {
  local X=$1 S=$2 M=$3 P R
  shift 3
  P=$D/student_l1_rep3${X}_s$S.pt
  R=runs/l1rep3${X#_}_s$S
  experts_at 723f266 runs/experts1207p || return 1
  if ! cmp -s runs/experts1207p/rotate_z+/checkpoint.pt <(git show 564f969:unicross/checkpoints/allegro/rotate_z+.pt); then
    git show 564f969:unicross/checkpoints/allegro/rotate_z+.pt > runs/experts1207p/rotate_z+/checkpoint.pt || return 1
  fi
  if [ ! -f $D/student_cells_rep3${X}_s$S.json ]; then
    if [ ! -d $R ]; then
      [ -f runs/l1rep3o_s$S/checkpoint.pt ] || bash $D/run_o.sh $S || return 1
      cp -r runs/l1rep3o_s$S $R.tmp && mv $R.tmp $R || return 1
    fi
    unicross distill --resume --experts runs/experts1207p --out $R --epochs 2500 \
      --set 'optim.mode_weights={rotate_x+: 5, grasp: 3}' "$@" > $R.log 2>&1 || return 1
    unicross export $R --out $P || return 1
    cp $R/metrics.jsonl $D/metrics_rep3${X}_s$S.jsonl
    python docs/runs/student_ft_1202b/seed_cells.py $P $D/student_cells_rep3${X}_s$S.json \
      > runs/cells_l1rep3${X#_}_s$S.log 2>&1 || return 1
  fi
  [ -f $D/rotate_seeds_rep3${X}_s$S.json ] || python $D/rotate_seeds.py $D/rotate_seeds_rep3${X}_s$S.json $P \
    ${M:+--modes $M} > runs/rotseeds_l1rep3${X#_}_s$S.log 2>&1 || return 1
  [ -f $D/chain_seeds_rep3${X}_s$S.json ] || python $D/chain_seeds.py $D/chain_seeds_rep3${X}_s$S.json $P \
    > runs/chainseeds_l1rep3${X#_}_s$S.log 2>&1
}
