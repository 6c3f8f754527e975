#!/bin/bash
# Issue #12's measurements on a lent 16-core machine (Python 3.12, its own torch), run from the
# repository root by the device tool with the wheel bundle of ../shared/tools/device-wheels.sh in .whl:
#   bash docs/runs/device16/run.sh      (writes under $OUT; ~7 min)
# 1. Inductor's on-disk cache warmed: each task's step-math graph compiled once, in parallel processes;
# 2. benchmarks/scaling.py with the step math compiled: 1..16 workers (and 16 workers at 4096 frames);
# 3. benchmarks/env_throughput.py: eager and compiled step vs bare physics on each task id, one core.
set -u
export PYTHONUNBUFFERED=1
OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
T0=$(date +%s)
el() { echo "[$(( $(date +%s) - T0 )) s] $*" | tee -a "$OUT/log.txt"; }
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
python3 -m pip install -q --no-index --no-deps --no-build-isolation --no-compile --upgrade --target /tmp/site . || exit 1
export PYTHONPATH=/tmp/site
mkdir -p /tmp/b && cp benchmarks/scaling.py benchmarks/env_throughput.py /tmp/b/ && cd /tmp/b  # outside the source tree
{ nproc; lscpu | grep "Model name"; python3 -c "import torch, sys; print('torch', torch.__version__, 'python', sys.version)"; } >> "$OUT/log.txt" 2>&1
el "installed; warming the compile cache"
for t in Grasp Relocate Rotate Translate MultiSkill; do
  timeout 240 python3 env_throughput.py --steps 5 --reps 1 --modes compiled --tasks UniCross-$t-v1 --no-settings \
    > "/tmp/warm_$t.log" 2>&1 &
done
timeout 240 python3 scaling.py --workers 1 --iterations 1 --env-steps 20 > /tmp/warm_scaling.log 2>&1 &
wait
grep -h "compiled in\|Error\|error" /tmp/warm_*.log >> "$OUT/log.txt"
el "scaling, compiled"
timeout 300 python3 scaling.py --workers 1 2 4 8 16 --iterations 6 --json "$OUT/scaling16_compiled.json" \
  --png "$OUT/scaling16_compiled.png" 2>&1 | grep -v Warning >> "$OUT/log.txt"
el "scaling, 16 workers x 256 steps"
timeout 90 python3 scaling.py --workers 16 --iterations 4 --set collector.frames_per_batch=4096 \
  --json "$OUT/scaling16_batch4096.json" 2>&1 | grep -v Warning >> "$OUT/log.txt"
el "env throughput"
timeout 150 python3 env_throughput.py --steps 300 --reps 3 --modes eager compiled --no-settings \
  --json "$OUT/env_throughput16.json" 2>&1 | grep -v Warning >> "$OUT/log.txt"
el done
