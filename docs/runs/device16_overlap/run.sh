#!/bin/bash
# Issue #12 on a lent 16-core machine, second visit (2026-11-25), from the repository root with the
# wheel bundle of ../shared/tools/device-wheels.sh in .whl, two device calls:
#   bash docs/runs/device16_overlap/run.sh 1
#     (background) hash_probe.py twice: the cache keys of the toy GraphMethod in two processes, diffed;
#     benchmarks/scaling.py eagerly, 2/4/8 workers, without and with collector.overlap (UNICROSS_COMPILE=0:
#     a compiled process pays ~40 s here even on a cache hit). The probe overlapped the first row (2
#     workers without overlap), which it slowed: call 2 measures that row again.
#   bash docs/runs/device16_overlap/run.sh 2
#     scaling.py --compare-overlap at 2 workers, eager then compiled; then profile_probe.py: where a
#     cache hit of the toy graph spends its time.
set -u
export PYTHONUNBUFFERED=1
OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
T0=$(date +%s)
el() { echo "[$(( $(date +%s) - T0 )) s] $*" | tee -a "$OUT/log.txt"; }
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
python3 -m pip install -q --no-index --no-deps --no-build-isolation --no-compile --upgrade --target /tmp/site . || exit 1
export PYTHONPATH=/tmp/site
{ nproc; lscpu | grep "Model name"; python3 -c "import torch, sys; print('torch', torch.__version__, 'python', sys.version)"; } >> "$OUT/log.txt" 2>&1
el "installed"
SRC=$PWD
mkdir -p /tmp/b && cp benchmarks/scaling.py /tmp/b/ && cd /tmp/b  # outside the source tree
if [ "${1:-1}" = 1 ]; then
  ( cd "$SRC"
    timeout 200 python3 docs/runs/device16_overlap/hash_probe.py a > "$OUT/probe_a.log" 2>&1
    timeout 200 python3 docs/runs/device16_overlap/hash_probe.py b > "$OUT/probe_b.log" 2>&1
    diff -a "$OUT/hash_a.txt" "$OUT/hash_b.txt" > "$OUT/hash_diff.txt"
    el "probe done" ) &
  for o in false true; do
    el "scaling, eager, overlap=$o"
    UNICROSS_COMPILE=0 timeout 200 python3 scaling.py --workers 2 4 8 --iterations 6 --set collector.overlap=$o \
      --json "$OUT/scaling16_eager_overlap_$o.json" 2>&1 | grep -v Warning >> "$OUT/log.txt"
  done
  wait
else
  el "scaling, eager, 2 workers, without and with overlap"
  UNICROSS_COMPILE=0 timeout 150 python3 scaling.py --workers 2 --iterations 8 --compare-overlap \
    --json "$OUT/scaling16_eager_compare.json" 2>&1 | grep -v Warning >> "$OUT/log.txt"
  el "scaling, compiled, 2 workers, without and with overlap"
  timeout 260 python3 scaling.py --workers 2 --iterations 8 --compare-overlap \
    --json "$OUT/scaling16_compiled_compare.json" 2>&1 | grep -v Warning >> "$OUT/log.txt"
  el "profile of a cache hit"
  cd "$SRC"
  timeout 100 python3 docs/runs/device16_overlap/hash_probe.py a > "$OUT/probe_a.log" 2>&1
  timeout 60 python3 docs/runs/device16_overlap/profile_probe.py b > "$OUT/profile_b.log" 2>&1
fi
el done
