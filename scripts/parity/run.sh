#!/usr/bin/env bash
# Parity of gs-render (CPU reference and Vulkan) with the original 3DGS CUDA rasterizer
# on every view of the shared scenes. Run from the repository root on a CUDA machine:
#   bash scripts/parity/run.sh PEER_DIR OUT_DIR [extra compare.py args]
# PEER_DIR is the original's source folder (see scripts/parity/README.md). Writes
# OUT_DIR/parity.json, OUT_DIR/parity.md and OUT_DIR/parity.log. The Vulkan driver
# environment and PYTHON (default python3, with torch) come from the caller.
set -euo pipefail

if [[ $# -lt 2 ]]; then
    echo "usage: bash scripts/parity/run.sh PEER_DIR OUT_DIR [extra compare.py args]" >&2
    exit 2
fi
peer=$1
out=$2
shift 2
mkdir -p "$out"

# Later arguments win, so extra args such as --scenes or --views narrow the run.
"${PYTHON:-python3}" -u scripts/parity/compare.py \
    --peer "$peer" \
    --scenes all --views all --backends cpu,vulkan --crop-check \
    --json "$out/parity.json" --md "$out/parity.md" \
    "$@" 2>&1 | tee "$out/parity.log"
