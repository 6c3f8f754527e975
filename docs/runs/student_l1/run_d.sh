#!/bin/bash
# rule.txt screen D: the shipped x+ expert with an input floor of 1e-2 as the x+ teacher (after run_c.sh).
#   nohup bash docs/runs/student_l1/run_d.sh > runs/student_l1_d.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
while [ -f runs/student_l1_c.log ] && ! grep -q "^DONE" runs/student_l1_c.log; do sleep 20; done
P=runs/xp_shipped_floor/policy.pt
mkdir -p runs/xp_shipped_floor
python - <<'PY'
import copy
import torch
ck = torch.load("unicross/checkpoints/allegro/rotate_x+.pt", map_location="cpu", weights_only=False)
ck = copy.deepcopy(ck)
ck["config"]["model"]["obs_std_min"] = 1e-2
ck["note"] = ("allegro/rotate_x+ (the shipped weights, unchanged) with model.obs_std_min = 1e-2: its observation "
              "normaliser divides no feature by less than 1e-2 when it acts or labels (docs/runs/student_l1/rule.txt D1)")
torch.save(ck, "runs/xp_shipped_floor/policy.pt")
PY
[ -f $D/train300_shipped_floor.json ] || screen $P $D/train300_shipped_floor.json train 50 $P > runs/drift_shipped_floor.log 2>&1 || exit 1
python - <<'PY' || { echo "D1: does not qualify"; echo DONE; exit 0; }
import json, sys
s = json.load(open("docs/runs/student_l1/train300_shipped_floor.json"))["summary"]
ok = s["successes"] >= 25 and s["dropped"] <= 80 and s["mean_abs_drift_after"] <= 0.02
print(f"D1: {s['successes']} successes, {s['dropped']} dropped of {s['n']}, drift {s['mean_abs_drift_after']:.3f} rad:",
      "qualifies" if ok else "does not qualify")
sys.exit(0 if ok else 1)
PY
cp $P $D/shipped_floor_policy.pt
[ -f $D/shipped_floor_expert_cell.json ] || python docs/runs/xp_clone_drift/expert_cell.py $P $D/shipped_floor_expert_cell.json > runs/cell_shipped_floor.log 2>&1 || exit 1
[ -f $D/test120_shipped_floor.json ] || screen $P $D/test120_shipped_floor.json test 20 $P > runs/test120_shipped_floor.log 2>&1 || exit 1
E=runs/experts_shipped_floor
experts_with_xp $E $P
R=runs/l1fl_w30_s0
if [ ! -f $D/student_cells_fl_s0.json ]; then
  stage $E $R 0 || exit 1
  unicross export $R --out $D/student_l1_fl_s0.pt || exit 1
  python docs/runs/student_ft_1202b/seed_cells.py $D/student_l1_fl_s0.pt $D/student_cells_fl_s0.json > runs/cells_l1fl_s0.log 2>&1 || exit 1
fi
echo DONE
