"""open3d_gs: 3D Gaussian Splatting scenes from Python (docs/python.md).

The layout follows Open3D's Python package:
    open3d_gs.t.geometry.PointCloud, open3d_gs.t.io.read_point_cloud / write_point_cloud,
    open3d_gs.camera.PinholeCamera / read_cameras_json,
    open3d_gs.visualization.rendering.OffscreenRenderer, open3d_gs.visualization.draw.
Errors of the C++ library arrive as open3d_gs.Open3DError (a RuntimeError) with its message.
"""
import sys as _sys

from . import _core
from ._core import Open3DError, camera, t, visualization
from ._rasterization import rasterization  # gsplat-style: arrays in, images out

# `import open3d_gs.t.io` and `from open3d_gs.camera import PinholeCamera` work as in
# Open3D: the extension's submodules are registered under the package's names.
for _name, _module in (
    ("t", t),
    ("t.geometry", t.geometry),
    ("t.io", t.io),
    ("camera", camera),
    ("visualization", visualization),
    ("visualization.rendering", visualization.rendering),
):
    _sys.modules[__name__ + "." + _name] = _module

__all__ = ["Open3DError", "camera", "t", "visualization"]
