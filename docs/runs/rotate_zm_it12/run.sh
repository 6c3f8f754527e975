#!/usr/bin/env bash
# Steps 1-3 of rule.txt: the two z- searches (A from the z+ gaits reversed, B from the z- gaits), then the clone of
# the candidate (step 2 picks it: pick.py; clone.sh). Re-running skips what exists. ~25 min of searches + ~10 of clone, 2 cores.
set -euo pipefail
cd "$(dirname "$0")/../../.."
D=docs/runs/rotate_zm_it12
G=docs/runs/gait_search
mkdir -p runs/gait runs/clone
COMMON=(--skill rotate --axis z- --refine z- --hold --no-stop --tracking phase --lookahead 1.5 --steps 400
        --amplitude 0.6 --no-randomize --limit 4 --generations 6 --sigma 0.15 --select 6 --select-seeds 4)
[ -s runs/gait/rotate_z-_it12_A.jsonl ] || python benchmarks/gait_search.py "${COMMON[@]}" --init-reversed \
    --init $G/rotate_z+_hold.jsonl.gz $G/rotate_z+_hold2.jsonl.gz --out runs/gait/rotate_z-_it12_A.jsonl > $D/search_A.log 2>&1
[ -s runs/gait/rotate_z-_it12_B.jsonl ] || python benchmarks/gait_search.py "${COMMON[@]}" \
    --init $G/rotate_z-_hold.jsonl.gz $G/rotate_z-_hold2.jsonl.gz --out runs/gait/rotate_z-_it12_B.jsonl > $D/search_B.log 2>&1
gzip -kf runs/gait/rotate_z-_it12_A.jsonl runs/gait/rotate_z-_it12_B.jsonl
cp runs/gait/rotate_z-_it12_A.jsonl.gz runs/gait/rotate_z-_it12_B.jsonl.gz $D/
python $D/pick.py $D/rotate_z-_it12_A.jsonl.gz $D/rotate_z-_it12_B.jsonl.gz --out $D/candidate.json || exit 0
bash $D/clone.sh "$(python -c "import json; print(json.load(open('$D/candidate.json'))['log'])")"
