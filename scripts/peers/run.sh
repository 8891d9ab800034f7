#!/usr/bin/env bash
# Times the peer CUDA rasterizers (the original 3DGS, gsplat 1.6.0's rasterization(), HiGS
# from gsplat.experimental) beside our gs-bench on the same scenes, views and sizes. Run it
# from the repository root on an NVIDIA GPU machine:
#   bash scripts/peers/run.sh [--build-only | --no-build] OUT_DIR [time_peers.py args]
# Needs .parity-peer/diff-gaussian-rasterization (scripts/parity/README.md) and
# .parity-peer/gsplat (scripts/peers/fetch-gsplat.sh), nvcc, ninja, Python (PYTHON, default
# python3) with a CUDA torch and numpy, and build/bin/gs-bench (GS_BENCH) and
# build/bin/gs-render (GS_RENDER) where ours should be timed and compared; VK_DRIVER_FILES
# defaults to NVIDIA's driver where only /usr/local/nvidia lists it. First every peer is built (JIT, for the local GPU's
# architecture, into TORCH_EXTENSIONS_DIR, default /tmp/gs-peers-torch-extensions, kept for
# later runs), then one process times them and runs gs-bench. --build-only stops after the
# build, --no-build skips it (a build already made on this machine). Writes
# OUT_DIR/{env.txt,build.log,peers.log,peers.json,peers.md,gs-bench*.json,gs-bench*.log}.
set -euo pipefail

usage() {
    echo "usage: bash scripts/peers/run.sh [--build-only | --no-build] OUT_DIR [time_peers.py args]" >&2
    exit 2
}
mode=all
case ${1:-} in
--build-only) mode=build && shift ;;
--no-build) mode=timing && shift ;;
esac
[[ $# -ge 1 && $1 != -* ]] || usage
mkdir -p "$1"
out=$(cd "$1" && pwd)
shift
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
py=${PYTHON:-python3}
gs_bench=${GS_BENCH:-build/bin/gs-bench}
gs_render=${GS_RENDER:-build/bin/gs-render}

# One run of this script at a time on a machine: the JIT builds and the process that imports
# them never overlap (gsplat's loaders delete torch's build lock before building).
if command -v flock >/dev/null; then
    exec 9>"${TMPDIR:-/tmp}/gs-peers.lock"
    flock 9
fi

# NVIDIA's Vulkan driver on the lent GPU machines is listed only under /usr/local/nvidia, and
# it loads only where libglvnd is installed (docs/environment-notes.md).
icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [[ -z ${VK_DRIVER_FILES:-} && -f $icd ]]; then
    export VK_DRIVER_FILES=$icd
fi
export TORCH_EXTENSIONS_DIR=${TORCH_EXTENSIONS_DIR:-/tmp/gs-peers-torch-extensions}
if [[ -z ${TORCH_CUDA_ARCH_LIST:-} ]]; then
    TORCH_CUDA_ARCH_LIST=$("$py" -c 'import torch; print("%d.%d" % torch.cuda.get_device_capability())')
    export TORCH_CUDA_ARCH_LIST
fi
export MAX_JOBS=${MAX_JOBS:-$(nproc)}

{
    echo "date: $(date -u +%FT%TZ)"
    echo "repo: $(git rev-parse HEAD 2>/dev/null || echo unknown)"
    for peer in .parity-peer/diff-gaussian-rasterization .parity-peer/gsplat; do
        echo "$peer: $(cat "$peer/PEER_COMMIT" 2>/dev/null || echo 'missing PEER_COMMIT')"
    done
    "$py" -c 'import sys, torch; print("python", sys.version.split()[0], "torch", torch.__version__, "cuda", torch.version.cuda)'
    echo "nvcc: $(nvcc --version 2>/dev/null | tail -n 1 || echo 'not on PATH')"
    echo "ninja: $(ninja --version 2>/dev/null || echo 'not on PATH')"
    echo "TORCH_CUDA_ARCH_LIST=$TORCH_CUDA_ARCH_LIST MAX_JOBS=$MAX_JOBS TORCH_EXTENSIONS_DIR=$TORCH_EXTENSIONS_DIR"
    nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv 2>&1 || true
} | tee "$out/env.txt"

if [[ $mode != timing ]]; then
    "$py" -u scripts/peers/time_peers.py --build-only "$@" 2>&1 | tee "$out/build.log"
fi
if [[ $mode == build ]]; then
    exit 0
fi

ours=()
if [[ -x $gs_bench ]]; then
    ours+=(--gs-bench "$gs_bench")
else
    echo "run.sh: no gs-bench at $gs_bench: peers only" | tee -a "$out/env.txt"
fi
if [[ -x $gs_render ]]; then
    ours+=(--gs-render "$gs_render")
fi
# Later arguments win, so the caller's may replace these.
"$py" -u scripts/peers/time_peers.py --out "$out" ${ours[@]+"${ours[@]}"} "$@" 2>&1 |
    tee "$out/peers.log"
