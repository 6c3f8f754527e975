#!/bin/bash
# Lent 16-core machine with a GPU (2026-11-27): the checks that need it, in one call.
#   1. The SAPIEN renderer (`unicross render --renderer sapien`, render.SapienBackend), never run before:
#      replay trajectories recorded on the 2-core VM (traj/*.npz, the shipped experts on held-out test
#      objects; README) into a ManiSkill scene with SAPIEN rendering on the GPU; a still (PNG) and an
#      animation (GIF) of each.
#   2. Issue #12: where a fresh process's ~85 s first compiled call goes on these machines
#      (device16_acting, calls 3-4): first_call.py on an empty Inductor cache (fills it), then on the cache
#      it left with TORCHINDUCTOR_CPP_CACHE_PRECOMPILE_HEADERS=0 (no per-process precompiled header), then
#      with the default (1).
#   bash docs/runs/device16_render/run.sh 2   (call 2, after the fixes of call 1's findings)
#      first_call.py on an empty cache, then on the cache it left (unicross.compiling.settle_vec_isa now
#      records Inductor's instruction-set probes), then the CLI's SAPIEN still (the replay env no longer
#      compiles the step math).
# From the repository root, with the wheel bundle of ../shared/tools/device-wheels.sh in .whl and the
# Vulkan/EGL loaders in .gl (device README): run with carry [".whl", ".gl"], timeout_s >= 540.
set -u
export PYTHONUNBUFFERED=1
OUT=${OUT:-/tmp/out}; R=/tmp/res; mkdir -p "$OUT" "$R"
T0=$(date +%s)
el() { echo "[$(( $(date +%s) - T0 )) s] $*" | tee -a "$R/log.txt"; }
pack() { tar -cf "$OUT/results.tar" -C "$R" .; }  # after every stage: what a timeout leaves still comes back
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
python3 -m pip install -q --no-index --no-deps --no-build-isolation --no-compile --upgrade --target /tmp/site . || exit 1
export PYTHONPATH=/tmp/site
[ -f /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ] && export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
[ -f /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json ] && export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
{ nproc; lscpu | grep "Model name"; nvidia-smi -L; ldconfig -p | grep -c libvulkan;
  python3 -c "import torch, sys; print('torch', torch.__version__, 'python', sys.version.split()[0])"; } >> "$R/log.txt" 2>&1
el "installed"
SRC=$PWD
mkdir -p /tmp/w && cd /tmp/w  # outside the source tree
cp "$SRC/docs/runs/device16_acting/first_call.py" .
if [ "${1:-1}" = 2 ]; then  # call 2: the two fixes of call 1's findings, warm first call and the CLI's still
  export TORCHINDUCTOR_CACHE_DIR=/tmp/inductor_render2
  first_call2() {  # tag timeout
    el "first call, $1"
    TORCH_LOGS="+torch._inductor.codecache" timeout "$2" python3 first_call.py > "$R/first_call_$1.json" 2> "$R/first_call_$1.err"
    echo "  rc=$? fx graph cache hits $(grep -c 'fx graph cache hit' "$R/first_call_$1.err")," \
      "misses $(grep -c 'fx graph cache miss' "$R/first_call_$1.err")" | tee -a "$R/log.txt"
    grep "first_step_s\|make_and_reset_s" "$R/first_call_$1.json" | tee -a "$R/log.txt"
    ls "$TORCHINDUCTOR_CACHE_DIR"/unicross_vec_isa_* >> "$R/log.txt" 2>&1; pack
  }
  first_call2 cold2 170
  first_call2 warm2 90
  el "the CLI's still (SAPIEN)"
  timeout 45 python3 /tmp/site/bin/unicross render "$(ls "$SRC"/docs/runs/device16_render/traj/*.npz | head -1)" \
    --renderer sapien --out "$R/cli_still.png" > "$R/cli_still.log" 2>&1; el "  rc=$?"
  el done; pack; exit 0
fi
el "render (SAPIEN)"
timeout 60 python3 /tmp/site/bin/unicross render "$(ls "$SRC"/docs/runs/device16_render/traj/*.npz | head -1)" \
  --renderer sapien --out "$R/cli_still.png" > "$R/cli_still.log" 2>&1; el "  the CLI's still: rc=$?"
timeout 150 python3 "$SRC/docs/runs/device16_render/render_all.py" "$R" "$SRC"/docs/runs/device16_render/traj/*.npz \
  > "$R/render.jsonl" 2> "$R/render.err"; el "  render_all: rc=$?"; cat "$R/render.jsonl" >> "$R/log.txt"
pack
export TORCHINDUCTOR_CACHE_DIR=/tmp/inductor_render && rm -rf "$TORCHINDUCTOR_CACHE_DIR"
first_call() {  # tag env timeout
  el "first call, $1"
  env $2 TORCH_LOGS="+torch._inductor.codecache" timeout "$3" python3 first_call.py > "$R/first_call_$1.json" 2> "$R/first_call_$1.err"
  echo "  rc=$? fx graph cache hits $(grep -c 'fx graph cache hit' "$R/first_call_$1.err")," \
    "misses $(grep -c 'fx graph cache miss' "$R/first_call_$1.err")" | tee -a "$R/log.txt"
  grep "first_step_s\|make_and_reset_s" "$R/first_call_$1.json" | tee -a "$R/log.txt"
  pack
}
first_call cold TORCHINDUCTOR_CPP_CACHE_PRECOMPILE_HEADERS=1 230
first_call warm_nopch TORCHINDUCTOR_CPP_CACHE_PRECOMPILE_HEADERS=0 110
first_call warm_pch TORCHINDUCTOR_CPP_CACHE_PRECOMPILE_HEADERS=1 110
el done; pack
