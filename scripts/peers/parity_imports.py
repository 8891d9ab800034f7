#!/usr/bin/env python3
"""scripts/parity's render_original and compare, for the peer timing modules beside this one.

The peer timing reuses the parity tools (scripts/parity/README.md): render_original's scene
readers, cameras, log and the original rasterizer's build, compare's image metrics and
repository state. They are plain scripts in a folder beside this one, not a package: this
module puts scripts/parity on sys.path (once, first) and imports them, so every module here
reaches them by the same names, `ro` and `cmp`.
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "parity"))
import compare as cmp  # noqa: E402  (scripts/parity/compare.py: metrics, repo state)
import render_original as ro  # noqa: E402  (scene loading, cameras, the original's build)

log = ro.log

__all__ = ["cmp", "log", "ro"]
