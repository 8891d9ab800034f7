#!/usr/bin/env python3
"""The peers' JIT builds: their environment, gsplat's import, stale-lock cleanup, the builds.

For time_peers.py. The original is built by render_original.build_peer; gsplat's three
extensions (its main one, gsplat.scene's packing, gsplat.experimental's HiGS) by gsplat's own
lazy loaders, into TORCH_EXTENSIONS_DIR for the local GPU's architecture, with only the 3DGS
kernels for 3 channels unless --gsplat-full-build. The build process (--build-only, build_all)
and the timing process set up the same environment (configure_build_env), since gsplat
rebuilds from scratch when its build parameters change; scripts/peers/run.sh runs the two one
after the other, so no two processes ever build or import the extensions at once.
"""

import os
import sys
import tempfile
import time
from pathlib import Path

from parity_imports import log, ro

HERE = Path(__file__).resolve().parent
# gsplat's JIT extensions go to TORCH_EXTENSIONS_DIR/<name>; a fixed folder under /tmp
# survives between runs on one machine.
DEFAULT_TORCH_EXTENSIONS_DIR = Path(tempfile.gettempdir()) / "gs-peers-torch-extensions"

# gsplat's build switches (gsplat/cuda/build.py, gsplat/cuda/csrc/Config.h): only the 3DGS
# kernels, for 3 channels, as gsplat's own docs workflow builds it. The 3DGS code is the
# same; the other modules and channel counts only cost build time. --gsplat-full-build
# builds everything.
GSPLAT_LEAN_BUILD_ENV = {
    "NUM_CHANNELS": "3",
    "BUILD_3DGUT": "0",
    "BUILD_2DGS": "0",
    "BUILD_ADAM": "0",
    "BUILD_RELOC": "0",
    "BUILD_LOSSES": "0",
    "BUILD_CAMERA_WRAPPERS": "0",
}


def configure_build_env(full_gsplat_build):
    """Environment of every JIT build, identical in the build and the timing process:
    gsplat rebuilds from scratch when its build parameters differ from the saved ones."""
    import torch

    if not torch.cuda.is_available():
        raise RuntimeError("torch sees no CUDA device")
    major, minor = torch.cuda.get_device_capability()
    os.environ.setdefault("TORCH_CUDA_ARCH_LIST", f"{major}.{minor}")
    os.environ.setdefault("TORCH_EXTENSIONS_DIR", str(DEFAULT_TORCH_EXTENSIONS_DIR))
    if not full_gsplat_build:
        for key, value in GSPLAT_LEAN_BUILD_ENV.items():
            os.environ.setdefault(key, value)
    for key in ("DEBUG", "WITH_SYMBOLS"):
        if os.environ.get(key, "0") != "0":
            log(f"note: {key}={os.environ[key]} changes gsplat's build flags")
    # gsplat's CUDA backend imports rich unconditionally; the shim serves only if rich is absent.
    sys.path.append(str(HERE / "pyshim"))


def import_gsplat(gsplat_peer):
    """gsplat from the exported source folder (never an installed copy)."""
    root = Path(gsplat_peer).resolve()
    if not (root / "gsplat" / "__init__.py").is_file():
        raise FileNotFoundError(f"{root} has no gsplat/ package (run scripts/peers/fetch-gsplat.sh)")
    glm = root / "gsplat" / "cuda" / "csrc" / "third_party" / "glm" / "glm" / "glm.hpp"
    if not glm.is_file():
        raise FileNotFoundError(f"{glm} missing (run scripts/peers/fetch-gsplat.sh)")
    sys.path.insert(0, str(root))
    import gsplat

    if Path(gsplat.__file__).resolve().parent != root / "gsplat":
        raise RuntimeError(f"imported gsplat from {gsplat.__file__}, not from {root}")
    return gsplat


# The JIT extensions' folders under TORCH_EXTENSIONS_DIR (gsplat/cuda/build.py,
# gsplat/scene/kernels/cuda/build.py, gsplat/experimental/render/kernels/cuda/build.py).
GSPLAT_EXTENSIONS = ("gsplat_cuda", "gsplat_scene_cuda",
                     "experimental_gaussian_render_inference_scene_cuda")


def clear_stale_locks(args):
    """Removes the lock file a killed build leaves in its folder, which would make the next
    build wait for ever (torch's FileBaton). Only safe while no other process builds or loads
    these extensions: run.sh holds a lock of its own around both stages."""
    folders = [Path(os.environ["TORCH_EXTENSIONS_DIR"]) / name for name in GSPLAT_EXTENSIONS]
    if "original" in args.peers:
        folders.append(Path(args.original_build_dir or ro.default_build_dir(args.original_peer)))
    for folder in folders:
        lock = folder / "lock"
        if lock.exists():
            lock.unlink()
            log(f"removed the stale build lock {lock}")


def peer_commit(folder):
    f = Path(folder) / "PEER_COMMIT"
    return f.read_text().strip() if f.is_file() else None


def build_gsplat_main():
    """gsplat's main extension (gsplat.rasterization's kernels); raises on failure."""
    from gsplat.cuda import _backend

    if _backend._C is None:
        raise RuntimeError("gsplat's CUDA extension did not load (no CUDA toolkit found?)")
    return _backend._C


def build_gsplat_scene():
    """gsplat.scene's packing extension (GaussianInferenceScene); raises on failure."""
    from gsplat.scene.kernels import _backend

    return _backend._get_backend()


def build_higs(direct):
    """gsplat.experimental's HiGS extension. Its lazy loader turns a failed build into a
    warning and None, so the build stage calls the builder itself to see the error."""
    if direct:
        from gsplat.experimental.render.kernels.cuda.build import (
            build_and_load_experimental_gaussian_render_inference_scene as build)

        return build()
    from gsplat.experimental.render.kernels import _backend

    module = _backend._get_backend()
    if module is None:
        raise RuntimeError("gsplat.experimental's HiGS extension is unavailable (see above; "
                           "run with --build-only to see the build error)")
    return module


def build_all(args, gsplat):
    """--build-only: every extension, one after another, in this one process."""
    failures = []
    steps = []
    if "original" in args.peers:
        steps.append(("original", lambda: ro.build_peer(args.original_peer, args.original_build_dir,
                                                        args.compat)))
    if gsplat is not None:
        if "gsplat" in args.peers:
            steps.append(("gsplat", build_gsplat_main))
        if "higs8" in args.peers or "higs16" in args.peers:
            steps.append(("gsplat.scene", build_gsplat_scene))
            steps.append(("gsplat.experimental (HiGS)", lambda: build_higs(direct=True)))
    for name, step in steps:
        start = time.time()
        log(f"build: {name} ...")
        try:
            step()
            log(f"build: {name} ready in {time.time() - start:.1f} s")
        except Exception as e:  # noqa: BLE001 - report every failed build, then fail
            failures.append(name)
            log(f"build: {name} FAILED after {time.time() - start:.1f} s: {type(e).__name__}: {e}")
    if failures:
        log(f"build: failed: {', '.join(failures)}")
        return 1
    log("build: all peers ready")
    return 0
