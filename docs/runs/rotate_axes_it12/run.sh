#!/usr/bin/env bash
# rule.txt steps 1-4 for one axis AX (x-, x+ or y+; z+ and y- by rule2.txt, whose step 4 is `confirm.sh AX 480`):
# searches A (the opposite axis's gaits run backwards) and B (the
# axis's own), the second round from the better, the candidate (rotate_zm_it12/pick.py), its clone (seed 0) and the
# shipped expert on the same 120 held-out trials. Re-running skips what exists. ~35-45 min + ~10 on 2 cores.
#   bash docs/runs/rotate_axes_it12/run.sh x-
set -euo pipefail
cd "$(dirname "$0")/../../.."
AX=$1
D=docs/runs/rotate_axes_it12/$AX
G=docs/runs/gait_search
case $AX in
  x-) A=(rotate_x+_hold rotate_x+_sampled); B=(rotate_x-_hold rotate_x-_hold2 rotate_x-_sampled) ;;
  x+) A=(rotate_x-_hold rotate_x-_hold2 rotate_x-_sampled); B=(rotate_x+_hold rotate_x+_sampled) ;;
  y+) A=(rotate_y-_hold rotate_y-_hold2 rotate_y-_phase rotate_y-_nostop)
      B=(rotate_y+_hold rotate_y+_hold2 rotate_y+_phase rotate_y+_reversed) ;;
  z+) A=(rotate_z-_hold rotate_z-_hold2 rotate_z-_reversed rotate_z-_sampled
         ../rotate_zm_it12/rotate_z-_it12_A ../rotate_zm_it12/rotate_z-_it12_B ../rotate_zm_it12/rotate_z-_it12_2)
      B=(rotate_z+_hold rotate_z+_hold2 rotate_z+_sampled) ;;              # rule2.txt
  y-) A=(rotate_y+_hold rotate_y+_hold2 rotate_y+_phase rotate_y+_reversed
         ../rotate_axes_it12/y+/rotate_y+_it12_A ../rotate_axes_it12/y+/rotate_y+_it12_B ../rotate_axes_it12/y+/rotate_y+_it12_2)
      B=(rotate_y-_hold rotate_y-_hold2 rotate_y-_phase rotate_y-_nostop) ;;  # rule2.txt
  *) echo "axis must be x-, x+, y+ (rule.txt), z+ or y- (rule2.txt)" >&2; exit 2 ;;
esac
mkdir -p $D runs/gait runs/clone
R=runs/gait/rotate_${AX}_it12
COMMON=(--skill rotate --axis $AX --refine $AX --hold --no-stop --tracking phase --lookahead 1.5 --steps 400
        --amplitude 0.6 --no-randomize --limit 4 --generations 6 --sigma 0.15 --select 6 --select-seeds 4)
search() {  # NAME INIT... : one search, its log gzipped into $D
  local name=$1; shift
  [ -s ${R}_$name.jsonl ] || python benchmarks/gait_search.py "${COMMON[@]}" "$@" --out ${R}_$name.jsonl \
      > $D/search_$name.log 2>&1
  gzip -kf ${R}_$name.jsonl && cp ${R}_$name.jsonl.gz $D/
}
A=("${A[@]/#/$G/}"); B=("${B[@]/#/$G/}")
search A --init-reversed --init "${A[@]/%/.jsonl.gz}"
search B --init "${B[@]/%/.jsonl.gz}"
P=docs/runs/rotate_zm_it12/pick.py
python $P $D/rotate_${AX}_it12_A.jsonl.gz $D/rotate_${AX}_it12_B.jsonl.gz --out $D/first_round.json || true
search 2 --init "$(python -c "import json; print(json.load(open('$D/first_round.json'))['log'])")"
python $P $D/rotate_${AX}_it12_A.jsonl.gz $D/rotate_${AX}_it12_B.jsonl.gz $D/rotate_${AX}_it12_2.jsonl.gz \
    --out $D/candidate.json || exit 0
LOG=$(python -c "import json; print(json.load(open('$D/candidate.json'))['log'])")
H="--protocol rotate --axis $AX --objects test --limit 20 --trials-per-object 3 --seed 0 --workers 2"
C=runs/clone/${AX}_it12
[ -s $C/policy.pt ] || python benchmarks/gait_clone.py --gait "$LOG" --limit 8 --trials 2 --rounds 8 --beta 0.5 \
    --obs-std-min 1e-2 --heldout 20 --seed 0 --out $C > $D/clone.log 2>&1
mkdir -p $D/clone_s0 && cp $C/log.jsonl $C/command.txt $D/clone_s0/
[ -s $D/clone_s0_test120 ] || unicross eval --policy $C/policy.pt $H --out $D/clone_s0_test120 > $D/clone_eval.log 2>&1
[ -s $D/shipped_test120 ] || unicross eval --policy allegro/rotate_$AX $H --out $D/shipped_test120 > $D/shipped_eval.log 2>&1
python docs/runs/paper_protocol/paired.py $D/clone_s0_test120 $D/shipped_test120 --skill rotate | tee $D/paired.txt
