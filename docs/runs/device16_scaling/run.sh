#!/bin/bash
# Issue #12 on a lent 16-core machine (2026-12-04), one call:
#   1. a fresh process's first compiled step on an empty Inductor cache (fills it and the records of
#      unicross.compiling.settle_vec_isa / _remember_probe_builds), then on the cache it left: the warm
#      start that took 61 s there with the base probes remembered and the sets' extra probes not;
#   2. benchmarks/scaling.py --workers 1 2 4 8 16 --compare-overlap (compiled step math, default batch,
#      the real PPO update): training frames/s against workers x one env alone, JSON + PNG.
#   bash .../run.sh 2 (second call, a fresh machine): the scaling rows again with more iterations at 2
#   workers (--iterations 12), then 16 workers with 4096-frame batches (the in-hand experts' batch), with
#   and without overlap; the script's one-env rate comes from the same run.
# From the repository root, with the wheel bundle of ../shared/tools/device-wheels.sh in .whl and the
# scripts in .devrun (first_call.py): run with carry [".whl", ".devrun"], timeout_s 560.
set -u
export PYTHONUNBUFFERED=1
OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
T0=$(date +%s)
el() { echo "[$(( $(date +%s) - T0 )) s] $*" | tee -a "$OUT/log.txt"; }
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
python3 -m pip install -q --no-index --no-deps --no-build-isolation --no-compile --upgrade --target /tmp/site . || exit 1
export PYTHONPATH=/tmp/site
{ nproc; lscpu | grep "Model name"; python3 -c "import torch, sys; print('torch', torch.__version__, 'python', sys.version.split()[0])"; } >> "$OUT/log.txt" 2>&1
el "installed"
SRC=$PWD
mkdir -p /tmp/w && cd /tmp/w  # outside the source tree
cp "$SRC/.devrun/first_call.py" "$SRC/benchmarks/scaling.py" .
export TORCHINDUCTOR_CACHE_DIR=/tmp/inductor_scaling && rm -rf "$TORCHINDUCTOR_CACHE_DIR"
first_call() {  # tag timeout
  el "first call, $1"
  timeout "$2" python3 first_call.py > "$OUT/first_call_$1.json" 2> "$OUT/first_call_$1.err"
  el "  rc=$? $(grep -o '"make_and_reset_s": [0-9.]*\|"first_step_s": [0-9.]*' "$OUT/first_call_$1.json" | tr '\n' ' ')"
  ls "$TORCHINDUCTOR_CACHE_DIR" | grep -c unicross_isa_build >> "$OUT/log.txt"
}
if [ "${1:-1}" = 2 ]; then
  el "scaling, 2 workers, 12 iterations"
  timeout 195 python3 scaling.py --workers 2 --compare-overlap --iterations 12 --env-steps 1000 \
    --json "$OUT/scaling16_w2.json" > "$OUT/scaling_w2.log" 2> "$OUT/scaling_w2.err"
  el "  rc=$?"
  el "scaling, 16 workers, 4096-frame batches"
  timeout 125 python3 scaling.py --workers 16 --compare-overlap --iterations 4 --env-steps 1000 \
    --set collector.frames_per_batch=4096 --json "$OUT/scaling16_w16_4096.json" > "$OUT/scaling_w16.log" 2> "$OUT/scaling_w16.err"
  el "  rc=$?"; el done; exit 0
fi
first_call cold 200
first_call warm 90
el "scaling"
timeout 330 python3 scaling.py --workers 1 2 4 8 16 --compare-overlap --iterations 5 \
  --json "$OUT/scaling16.json" --png "$OUT/scaling16.png" > "$OUT/scaling.log" 2> "$OUT/scaling.err"
el "  rc=$?"
grep -c "compiled in\|compiling the step math" "$OUT/scaling.err" >> "$OUT/log.txt"
el done
