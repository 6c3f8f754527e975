#!/bin/bash
set -x
cd "$(git rev-parse --show-toplevel)"
source .venv/bin/activate
while ! grep -q DONE runs/cand_chain.log; do sleep 10; done  # docs/runs/xp_clone_drift/cand_chain.sh > runs/cand_chain.log
for c in s2 s3 f3e3; do
  [ -f docs/runs/xp_clone_drift/cand_${c}_expert_cell.json ] || python docs/runs/xp_clone_drift/expert_cell.py runs/xp_cand_$c/policy.pt docs/runs/xp_clone_drift/cand_${c}_expert_cell.json > runs/cell_cand_$c.log 2>&1
done
docs/runs/xp_clone_drift/student_chain.sh s2 0
echo DONE4
