#!/bin/bash
# Issue #12 on a lent 16-core machine with a GPU (2026-12-04, 45th session), one call:
#   1. the tests skipped where there is no GPU: tests/test_algorithm.py::test_update_on_the_gpu_matches_the_cpu
#      (the PPO update with optim.update_device=cuda against the CPU's on the same batches),
#      tests/test_collector.py::test_ppo_learner_on_the_gpu and tests/test_dagger.py::test_dagger_learner_on_the_gpu
#      (the trainers with CPU env workers and the learner on the GPU, checkpoint and resume);
#   2. benchmarks/scaling.py --workers 2 8 16 with collector.overlap and --update-devices cpu cuda: the
#      learner on the CPU and on the GPU, each worker count, in the same run (compiled step math, the
#      default 1024-frame batch, the real PPO update), JSON + PNG;
#   3. if time is left: 16 workers with 4096-frame batches, the same two update devices.
# From the repository root, with the wheel bundle of ../shared/tools/device-wheels.sh (+ pytest) in .whl:
# copy this file to .devrun/run_gpu.sh and run `bash .devrun/run_gpu.sh` with carry [".whl", ".devrun"], timeout_s 560.
set -u
export PYTHONUNBUFFERED=1
OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
T0=$(date +%s)
el() { echo "[$(( $(date +%s) - T0 )) s] $*" | tee -a "$OUT/log.txt"; }
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
python3 -m pip install -q --no-index --no-deps --no-build-isolation --no-compile --upgrade --target /tmp/site . || exit 1
export PYTHONPATH=/tmp/site
{ nproc; lscpu | grep "Model name"; nvidia-smi --query-gpu=name --format=csv,noheader;
  python3 -c "import torch, sys; print('torch', torch.__version__, 'python', sys.version.split()[0], 'cuda', torch.cuda.is_available())"; } >> "$OUT/log.txt" 2>&1
el "installed"
timeout 150 python3 -m pytest -q -p no:cacheprovider tests/test_algorithm.py tests/test_collector.py tests/test_dagger.py -k "gpu or bandit" > "$OUT/pytest_gpu.txt" 2>&1
el "gpu test rc=$? $(tail -1 "$OUT/pytest_gpu.txt")"
SRC=$PWD
mkdir -p /tmp/w && cd /tmp/w  # outside the source tree
cp "$SRC/benchmarks/scaling.py" .
el "scaling, overlap, update on cpu and cuda"
timeout 320 python3 scaling.py --workers 2 8 16 --iterations 5 --env-steps 1000 --set collector.overlap=true \
  --update-devices cpu cuda --json "$OUT/scaling_gpu_update.json" --png "$OUT/scaling_gpu_update.png" \
  > "$OUT/scaling.log" 2> "$OUT/scaling.err"
el "  rc=$?"
LEFT=$(( 520 - ($(date +%s) - T0) ))
if [ "$LEFT" -gt 80 ]; then
  el "16 workers, 4096-frame batches (${LEFT} s left)"
  timeout "$LEFT" python3 scaling.py --workers 16 --iterations 4 --env-steps 600 --set collector.overlap=true \
    --set collector.frames_per_batch=4096 --update-devices cpu cuda --json "$OUT/scaling_gpu_update_w16_4096.json" \
    > "$OUT/scaling_w16.log" 2> "$OUT/scaling_w16.err"
  el "  rc=$?"
fi
el done
