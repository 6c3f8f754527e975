#!/usr/bin/env bash
# Rule step 2b: the second search round from the better first-round log (candidate.json), then step 2 on it alone
# and, if found, step 3 (the clone) and the shipped expert's held-out cell. ~15 min + ~10, 2 cores.
set -euo pipefail
cd "$(dirname "$0")/../../.."
D=docs/runs/rotate_zm_it12
INIT=$(python -c "import json; print(json.load(open('$D/candidate.json'))['log'])")
[ -s runs/gait/rotate_z-_it12_2.jsonl ] || python benchmarks/gait_search.py --skill rotate --axis z- --refine z- \
    --hold --no-stop --tracking phase --lookahead 1.5 --steps 400 --amplitude 0.6 --no-randomize --limit 4 \
    --generations 6 --sigma 0.15 --select 6 --select-seeds 4 --init "$INIT" --out runs/gait/rotate_z-_it12_2.jsonl \
    > $D/search_2.log 2>&1
gzip -kf runs/gait/rotate_z-_it12_2.jsonl && cp runs/gait/rotate_z-_it12_2.jsonl.gz $D/
python $D/pick.py $D/rotate_z-_it12_2.jsonl.gz --out $D/candidate_2.json || exit 0
bash $D/clone.sh $D/rotate_z-_it12_2.jsonl.gz
