"""open3d_gs: 3D Gaussian Splatting scenes from Python (docs/python.md).

The layout follows Open3D's Python package:
    open3d_gs.t.geometry.PointCloud, open3d_gs.t.io.read_point_cloud / write_point_cloud,
    open3d_gs.io.read_image / write_image (also under t.io),
    open3d_gs.camera.PinholeCamera / PinholeCameraIntrinsic / read_cameras_json,
    open3d_gs.visualization.rendering.OffscreenRenderer, open3d_gs.visualization.draw.
Errors of the C++ library arrive as open3d_gs.Open3DError (a RuntimeError) with its message; a
missing input file as open3d_gs.Open3DFileNotFoundError, both Open3DError and FileNotFoundError.
"""
import functools as _functools
import sys as _sys

try:
    import numpy as _numpy  # noqa: F401 (the extension needs it; checked first for a clear error)
except ImportError as _error:
    # A pyenv or venv python3 first in PATH usually lacks numpy; the extension then fails
    # with pybind11's bare "ImportError: initialization failed".
    raise ImportError(
        f"open3d_gs needs numpy, which {_sys.executable} lacks. Run the interpreter the package "
        "was built for: build/bin/gs-python (it sets PYTHONPATH), or /usr/bin/python3 with "
        "PYTHONPATH=build/python (docs/python.md)") from _error

from . import _core
from ._core import Open3DError, Open3DFileNotFoundError, camera, io, t, visualization
from ._rasterization import rasterization  # gsplat-style: arrays in, images out

__version__ = _core.__version__

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


def _describe(value):
    """A short word for an argument in a TypeError: arrays by shape and dtype, never their
    values (pybind11's "Invoked with:" prints whole arrays)."""
    if isinstance(value, _numpy.ndarray):
        return f"numpy.ndarray(shape={value.shape}, dtype={value.dtype})"
    if isinstance(value, (bool, int, float, complex, str, bytes, type(None))):
        text = repr(value)
        return text if len(text) <= 60 else text[:57] + "..."
    if isinstance(value, (list, tuple, dict, set)):
        return f"{type(value).__name__} of {len(value)}"
    return type(value).__name__


def _short_type_errors(function):
    """`function` with pybind11's TypeError for arguments of no overload cut short."""

    @_functools.wraps(function)
    def call(*args, **kwargs):
        try:
            return function(*args, **kwargs)
        except TypeError as error:
            message = str(error)
            at = message.find("\nInvoked with:")
            if at < 0:
                raise
            words = [_describe(a) for a in args] + [f"{k}={_describe(v)}" for k, v in kwargs.items()]
            raise TypeError(message[:at] + "\nInvoked with: " + ", ".join(words)) from None

    return call


def _wrap_bindings(module, seen):
    """Puts _short_type_errors around every function, method, static method, constructor and
    property setter of the extension's classes and modules."""
    builtin = type(len)
    for name, value in list(vars(module).items()):
        if isinstance(value, builtin):
            setattr(module, name, _short_type_errors(value))
        elif isinstance(value, type) and value.__module__.startswith("open3d_gs") and value not in seen:
            seen.add(value)
            for attr, member in list(vars(value).items()):
                if isinstance(member, staticmethod) and isinstance(member.__func__, builtin):
                    setattr(value, attr, staticmethod(_short_type_errors(member.__func__)))
                elif type(member).__name__ == "instancemethod":
                    setattr(value, attr, _short_type_errors(member.__func__))
                elif type(member) is property and member.fset is not None:
                    setattr(value, attr, property(member.fget, _short_type_errors(member.fset),
                                                  member.fdel, member.__doc__))
        elif type(value) is type(_sys) and value.__name__.startswith("open3d_gs._core") and value not in seen:
            seen.add(value)
            _wrap_bindings(value, seen)


_wrap_bindings(_core, set())

__all__ = ["Open3DError", "Open3DFileNotFoundError", "__version__", "camera", "io", "t", "visualization"]
