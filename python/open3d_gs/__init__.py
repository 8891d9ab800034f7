"""open3d_gs: 3D Gaussian Splatting scenes from Python (docs/python.md).

The layout follows Open3D's Python package:
    open3d_gs.t.geometry.PointCloud, open3d_gs.t.io.read_point_cloud / write_point_cloud,
    open3d_gs.io.read_image / write_image (also under t.io),
    open3d_gs.camera.PinholeCamera / PinholeCameraIntrinsic / read_cameras_json,
    open3d_gs.visualization.rendering.OffscreenRenderer, open3d_gs.visualization.draw.
Errors of the C++ library arrive as open3d_gs.Open3DError (a RuntimeError) with its message; a
missing input file as open3d_gs.Open3DFileNotFoundError, both Open3DError and FileNotFoundError.
"""
import sys as _sys

from . import _core
from ._core import Open3DError, Open3DFileNotFoundError, camera, io, t, visualization

# `import open3d_gs.t.io` and `from open3d_gs.camera import PinholeCamera` work as in
# Open3D: the extension's submodules are registered under the package's names.
for _name, _module in (
    ("t", t),
    ("t.geometry", t.geometry),
    ("t.io", t.io),
    ("io", io),
    ("camera", camera),
    ("visualization", visualization),
    ("visualization.rendering", visualization.rendering),
):
    _sys.modules[__name__ + "." + _name] = _module

__all__ = ["Open3DError", "Open3DFileNotFoundError", "camera", "io", "t", "visualization"]
