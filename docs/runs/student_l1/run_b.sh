#!/bin/bash
# rule.txt contingency B: two fresh floored x+ clones (no held-out evaluation before the choice), their training
# screens, the choice (choose.py), then the chosen clone's report cell and held-out 120, and the l1 stage on it
# (seeds 0-2, gate after seed 0: x+ >= the clone's cell - 5), judged by judge3.py --expert rotate_x+=....
#   nohup bash docs/runs/student_l1/run_b.sh > runs/student_l1_b.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
SEQ='index:4:-0.010:0:1000+thumb:4:0.010:0:1000+index:4:0.010:@thumb:0.5+thumb:4:-0.010:@thumb:0.5'
for S in 4 5; do
  [ -f runs/xp_b_s$S/policy.pt ] || python benchmarks/gait_clone.py --sequence "$SEQ" --mode rotate_x+ --limit 32 --trials 2 --rounds 6 --beta 0.5 --workers 2 --seed $S --obs-std-min 1e-2 --out runs/xp_b_s$S > runs/xp_b_s$S.log 2>&1 || exit 1
  cp runs/xp_b_s$S/command.txt $D/clone_s${S}_command.txt; cp runs/xp_b_s$S/log.jsonl $D/clone_s${S}_log.jsonl
done
for S in 4 5; do
  [ -f $D/train300_clone_s$S.json ] || screen runs/xp_b_s$S/policy.pt $D/train300_clone_s$S.json train 50 runs/xp_b_s$S/policy.pt > runs/drift_b_s$S.log 2>&1 || exit 1
done
python $D/choose.py $D/train300_clone_s4.json $D/train300_clone_s5.json | tee $D/choice.txt
C=$(python -c "import json; c=json.load(open('$D/choice.json'))['chosen']; print(c.split('_')[-1][:-5] if c else '')")
[ -n "$C" ] || { echo "B2 chose nothing"; echo DONE; exit 0; }
P=runs/xp_b_$C/policy.pt
cp $P $D/clone_${C}_policy.pt
[ -f $D/clone_${C}_expert_cell.json ] || python docs/runs/xp_clone_drift/expert_cell.py $P $D/clone_${C}_expert_cell.json > runs/cell_b_$C.log 2>&1 || exit 1
[ -f $D/test120_clone_$C.json ] || screen $P $D/test120_clone_$C.json test 20 $P > runs/test120_b_$C.log 2>&1 || exit 1
E=runs/experts_b_$C
experts_with_xp $E $P
BAR=$(python -c "import json; print(json.load(open('$D/clone_${C}_expert_cell.json'))['summary']['sr'] - 5)")
for S in 0 1 2; do
  R=runs/l1b_w30_s$S
  if [ ! -f $D/student_cells_b_s$S.json ]; then
    stage $E $R $S || exit 1
    unicross export $R --out $D/student_l1_b_s$S.pt || exit 1
    python docs/runs/student_ft_1202b/seed_cells.py $D/student_l1_b_s$S.pt $D/student_cells_b_s$S.json > runs/cells_l1b_s$S.log 2>&1 || exit 1
  fi
  if [ $S = 0 ] && ! python -c "import json,sys; c=json.load(open('$D/student_cells_b_s0.json')); sys.exit(c['test']['rotate_x+']['summary']['sr'] < $BAR)"; then
    echo "GATE: seed 0's x+ cell is below $BAR; rule.txt B3 ends FAILED"; echo DONE; exit 0
  fi
done
python docs/runs/student_xp_drift/judge3.py --expert rotate_x+=$D/clone_${C}_expert_cell.json $D/student_cells_b_s{0,1,2}.json | tee $D/judge_b.txt
echo DONE
