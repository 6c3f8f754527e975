#!/bin/bash
# rule 3 of docs/runs/xp_clone_drift/rule.txt: three floored x+ clone candidates, then their training screens
set -x
cd "$(git rev-parse --show-toplevel)"
source .venv/bin/activate
SEQ='index:4:-0.010:0:1000+thumb:4:0.010:0:1000+index:4:0.010:@thumb:0.5+thumb:4:-0.010:@thumb:0.5'
run() { name=$1; shift
  [ -f runs/xp_cand_$name/policy.pt ] || python benchmarks/gait_clone.py --sequence "$SEQ" --mode rotate_x+ --limit 32 --trials 2 --rounds 6 --beta 0.5 --workers 2 --heldout 20 "$@" --out runs/xp_cand_$name > runs/xp_cand_$name.log 2>&1
}
run s2 --seed 2 --obs-std-min 1e-2
run s3 --seed 3 --obs-std-min 1e-2
run f3e3 --seed 0 --obs-std-min 3e-3
cd docs/runs/xp_clone_drift
for name in s2 s3 f3e3; do
  P=../../../runs/xp_cand_$name/policy.pt
  [ -f train300_cand_$name.json ] || python ../student_xp_drift/drift.py $P train300_cand_$name.json --objects train --limit 50 --trials 3 --labeller $P > ../../../runs/drift_cand_$name.log 2>&1
  [ -f train300_w30_s0_1500_cand_${name}labeller.json ] || python ../student_xp_drift/drift.py ../../../runs/ft_xw30_s0/checkpoint.pt train300_w30_s0_1500_cand_${name}labeller.json --objects train --limit 50 --trials 3 --labeller $P > ../../../runs/drift_w30_cand_$name.log 2>&1
done
echo DONE
