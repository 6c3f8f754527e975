#!/bin/bash
# Issue #12 on a lent 16-core machine (2026-11-26): training efficiency at 2 workers with the workers
# acting through GaussianHead.acting_fn (the rollout's fast forward pass), against the same code with
# that one line reverted ("base": the workers call the actor module, as before), in one call:
#   bash docs/runs/device16_acting/run.sh 1
#     benchmarks/scaling.py --workers 2 --compare-overlap, eager (UNICROSS_COMPILE=0) then compiled, each
#     for the new code and the base (call1/; the compiled run of the new code was cut by its timeout
#     after its first row: a cold compile cache);
#   bash docs/runs/device16_acting/run.sh 2
#     worker_probe.py (compiled): one env alone vs the same task in Rollout.collect with either actor
#     path; then scaling.py, 2 workers, compiled, with collector.overlap, new code only (call2/: neither
#     finished: the probe, then run from the source tree, imported the uninstalled package (fixed here:
#     it runs beside scaling.py now), and the scaling run's cold compile (71 s in the main process, as
#     long again in the workers) outlasted its 125 s timeout; no device time was left to rerun it;
#     the timeouts below are raised for a rerun: 100 -> 200 s and 125 -> 250 s).
#   bash docs/runs/device16_acting/run.sh 3
#     call 2's measurements (call3/): first_call.py (a fresh process's first compiled step, Inductor's
#     cache hits and misses logged) with an empty Inductor cache; the compiled overlapped scaling row;
#     first_call.py again with the cache the others left (default compile threads, then
#     TORCHINDUCTOR_COMPILE_THREADS=1: is a worker's ~40 s first call a miss, or a pool start?);
#     the worker probe last.
#   bash docs/runs/device16_acting/run.sh 4
#     where a process's ~1 min start goes (call4/): the time of CUDA's first init in a process on this
#     machine; first_call.py (now profiling make + reset + first step) with no GPU visible
#     (CUDA_VISIBLE_DEVICES=) on an empty cache, again on the cache it left, then with the GPU visible.
#     Call 4 ran it with timeouts of 100 / 35 / 70 s: the cold compile did not finish and nothing was
#     measured; the timeouts are now 200 / 120 / 120 s (call it with timeout_s >= 500).
# From the repository root with the wheel bundle of ../shared/tools/device-wheels.sh in .whl.
set -u
export PYTHONUNBUFFERED=1
OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
T0=$(date +%s)
el() { echo "[$(( $(date +%s) - T0 )) s] $*" | tee -a "$OUT/log.txt"; }
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
python3 -m pip install -q --no-index --no-deps --no-build-isolation --no-compile --upgrade --target /tmp/site_new . || exit 1
cp -r /tmp/site_new /tmp/site_base
sed -i 's/actor = self.actor.acting_fn() if hasattr(self.actor, "acting_fn") else self.actor/actor = self.actor/' \
  /tmp/site_base/unicross/rl/collector.py
grep -c "acting_fn()" /tmp/site_new/unicross/rl/collector.py /tmp/site_base/unicross/rl/collector.py >> "$OUT/log.txt"
{ nproc; lscpu | grep "Model name"; python3 -c "import torch, sys; print('torch', torch.__version__, 'python', sys.version)"; } >> "$OUT/log.txt" 2>&1
el "installed"
SRC=$PWD
mkdir -p /tmp/b && cp benchmarks/scaling.py /tmp/b/ && cd /tmp/b  # outside the source tree
run() {  # code mode timeout
  local env=""; [ "$2" = eager ] && env="UNICROSS_COMPILE=0"
  el "scaling, $1, $2"
  env $env PYTHONPATH=/tmp/site:/tmp/site_$1 timeout "$3" python3 scaling.py --workers 2 --iterations 8 \
    --compare-overlap --json "$OUT/scaling_${2}_$1.json" 2>&1 | grep -v -i warn >> "$OUT/log.txt"
}
if [ "${1:-1}" = 1 ]; then
  run new eager 110
  run base eager 110
  run new compiled 190
  run base compiled 170
elif [ "$1" = 3 ] || [ "$1" = 4 ]; then
  cp "$SRC/docs/runs/device16_acting/first_call.py" "$SRC/docs/runs/device16_acting/worker_probe.py" .
  export TORCHINDUCTOR_CACHE_DIR=/tmp/inductor_call3 && rm -rf "$TORCHINDUCTOR_CACHE_DIR"
  first_call() {  # tag [env [timeout]]
    el "first call, $1"
    env ${2:-} TORCH_LOGS="+torch._inductor.codecache" PYTHONPATH=/tmp/site:/tmp/site_new timeout ${3:-120} \
      python3 first_call.py > "$OUT/first_call_$1.json" 2> "$OUT/first_call_$1.err"
    echo "  fx graph cache hits $(grep -c 'fx graph cache hit' "$OUT/first_call_$1.err")," \
      "misses $(grep -c 'fx graph cache miss' "$OUT/first_call_$1.err")" | tee -a "$OUT/log.txt"
    grep "first_step_s\|make_and_reset_s" "$OUT/first_call_$1.json" | tee -a "$OUT/log.txt"
  }
  if [ "$1" = 4 ]; then
    el "CUDA init"
    PYTHONPATH=/tmp/site timeout 40 python3 -c "import time, torch; t = time.perf_counter(); torch.cuda.init(); \
print('cuda init', round(time.perf_counter() - t, 2), 's', torch.cuda.get_device_name())" 2>&1 | tee -a "$OUT/log.txt"
    first_call cold_nogpu CUDA_VISIBLE_DEVICES= 200
    first_call warm_nogpu CUDA_VISIBLE_DEVICES= 120
    first_call warm_gpu "" 120
    el done; exit 0
  fi
  first_call cold
  el "scaling, new, compiled, overlap"
  PYTHONPATH=/tmp/site:/tmp/site_new timeout 200 python3 scaling.py --workers 2 --iterations 8 \
    --set collector.overlap=true --json "$OUT/scaling_compiled_new_overlap.json" 2>&1 | grep -v -i warn >> "$OUT/log.txt"
  first_call warm
  first_call warm_threads1 TORCHINDUCTOR_COMPILE_THREADS=1
  el "worker probe, compiled"
  PYTHONPATH=/tmp/site:/tmp/site_new timeout 150 python3 worker_probe.py 6 \
    > "$OUT/worker_probe.json" 2> >(grep -v -i warn >> "$OUT/log.txt")
else
  el "worker probe, compiled"
  cp "$SRC/docs/runs/device16_acting/worker_probe.py" .  # beside scaling.py, outside the source tree
  PYTHONPATH=/tmp/site:/tmp/site_new timeout 200 python3 worker_probe.py 6 \
    > "$OUT/worker_probe.json" 2> >(grep -v -i warn >> "$OUT/log.txt")
  el "scaling, new, compiled, overlap"
  PYTHONPATH=/tmp/site:/tmp/site_new timeout 250 python3 scaling.py --workers 2 --iterations 8 \
    --set collector.overlap=true --json "$OUT/scaling_compiled_new_overlap.json" 2>&1 | grep -v -i warn >> "$OUT/log.txt"
fi
el done
