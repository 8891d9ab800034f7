#!/usr/bin/env bash
# The parity scan (scripts/parity/compare.py, without the crop check, which needs the three
# scenes of the crops) on the GPU device machine, from binaries built here.
# Prepare here first: bash scripts/device/prepare.sh, and the original's source in .parity-peer
# (scripts/parity/README.md). The device call carries .gl, .devlibs, .parity-peer,
# build/bin/gs-render (or the copy that GS_RENDER names, relative to the root)
# and the scene files (shared/ is a link and travels only path by path):
#   bash scripts/device/parity.sh OUT_DIR [extra compare.py args, e.g. --scenes train3]
set -euo pipefail
out=${1:?usage: bash scripts/device/parity.sh OUT_DIR [compare.py args]}
shift
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
# Our libraries only for gs-render: torch keeps the device's own libstdc++.
wrapper=$(mktemp /tmp/gs-render-XXXX)
printf '#!/bin/sh\nLD_LIBRARY_PATH=%s exec %s "$@"\n' "$PWD/.devlibs" "$PWD/${GS_RENDER:-build/bin/gs-render}" >"$wrapper"
chmod +x "$wrapper"
mkdir -p "$out"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv | tee "$out/gpu.txt" || true
mkdir -p "$out"
set -o pipefail
python3 -u scripts/parity/compare.py --peer .parity-peer/diff-gaussian-rasterization \
  --gs-render "$wrapper" --shared shared --scenes all --views all --backends cpu,vulkan \
  --json "$out/parity.json" --md "$out/parity.md" "$@" 2>&1 | tee "$out/parity.log"
