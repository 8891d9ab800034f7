"""gsplat-style rasterization: arrays in, images out (docs/python.md "gsplat-style rasterization").

`rasterization(means, quats, scales, opacities, colors, viewmats, Ks, width, height, ...)` takes
the arrays gsplat's `rasterization()` takes, in gsplat's conventions (activated scales and
opacities, wxyz quaternions, world-to-camera viewmats, pixel centres at (x + 0.5, y + 0.5)),
converts them to this library's splat cloud and cameras, and renders every camera through one
`OffscreenRenderer.render_batch` call. It returns numpy arrays shaped as gsplat's
`(render_colors, render_alphas, meta)`.
"""
import collections
import math
import operator
import threading

import numpy as np

from ._core import Open3DError
from ._core import camera as _camera
from ._core import t as _t
from ._core import visualization as _visualization

SH_C0 = 0.28209479177387814  # the degree-0 SH basis constant: colour = 0.5 + SH_C0 * f_dc

# Opacities 0 and 1 have no finite logit (the cloud stores logits). They are clamped to
# [2^-24, 1 - 2^-24]: 1 - 2^-24 is float32's largest value below 1, so an opaque splat changes
# by less than a float32 step, and 2^-24 is far below the 1/255 alpha under which the
# rasterizer (like gsplat's) skips a splat, so a transparent one still draws nothing.
OPACITY_CLAMP = 2.0 ** -24

RENDER_MODES = ("RGB", "D", "ED", "RGB+D", "RGB+ED")
BACKENDS = ("vulkan", "cpu")

# gsplat's keyword arguments that do not change its image (memory layout, gradients, sort
# strategy): accepted and ignored, so gsplat calls run unchanged.
_IGNORED_KNOBS = ("packed", "tile_size", "sparse_grad", "absgrad", "channel_chunk", "segmented")
# gsplat's keyword arguments this renderer can honour only at one value: any other is refused
# rather than silently rendered differently.
_FIXED_KNOBS = {
    "eps2d": 0.3,  # the 2D dilation of the original 3DGS (and gsplat's default)
    "radius_clip": 0.0,
    "camera_model": "pinhole",
    "distributed": False,
    "covars": None,
}
_GSPLAT_FAR_PLANE = 1e10  # gsplat's default far_plane; this renderer culls nothing far away


# --- Input arrays -----------------------------------------------------------------------------

def _float32(name, value):
    """`value` as a C-contiguous float32 array: numpy arrays of any float or int dtype, lists,
    and whatever has `__array__` (a CPU torch tensor); a torch tensor that numpy cannot read
    (on the GPU, or requiring grad) is detached and copied to the CPU first."""
    try:
        array = np.asarray(value)
    except Exception as error:  # torch: a CUDA tensor, or one that requires grad
        if not (hasattr(value, "detach") and hasattr(value, "cpu")):
            raise TypeError(f"{name}: cannot be read as an array ({error})") from error
        array = np.asarray(value.detach().cpu())
    if array.dtype == np.bool_ or not (np.issubdtype(array.dtype, np.floating)
                                       or np.issubdtype(array.dtype, np.integer)):
        raise TypeError(f"{name}: numbers expected, got an array of dtype {array.dtype}")
    with np.errstate(over="ignore"):  # float64 beyond float32's range becomes inf: refused below
        return np.ascontiguousarray(array, dtype=np.float32)


def _require_shape(name, array, shape, hint=""):
    """Refuses an array whose shape differs from `shape` (None: any size on that axis)."""
    if array.ndim != len(shape) or any(s is not None and a != s for a, s in zip(array.shape, shape)):
        want = "(" + ", ".join("?" if s is None else str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"
        raise ValueError(f"{name}: shape {tuple(array.shape)}, expected {want}{hint}")


def _require_finite(name, array):
    """Refuses NaN and Inf (also float64 values beyond float32's range), naming the first bad row."""
    bad = ~np.isfinite(array.reshape(len(array), -1)).all(axis=1) if len(array) else np.zeros(0, bool)
    if bad.any():
        row = int(np.argmax(bad))
        raise ValueError(f"{name}[{row}] is not finite in float32: {array[row].tolist()}")


def _normalised_quats(quats):
    """Unit quaternions as the library's readers make them (t/io SplatColumns.cpp): the squared
    norm in float64; rows already unit to 2^-20 kept bit for bit, the others multiplied by
    1 / norm in float64 and rounded to float32."""
    q = quats.astype(np.float64)
    n2 = np.einsum("ij,ij->i", q, q)
    if (n2 == 0.0).any():
        row = int(np.argmax(n2 == 0.0))
        raise ValueError(f"quats[{row}] is zero: a rotation quaternion cannot be normalised")
    redo = np.abs(n2 - 1.0) > 2.0 ** -20
    out = quats.copy()
    out[redo] = (q[redo] * (1.0 / np.sqrt(n2[redo]))[:, None]).astype(np.float32)
    return out


def opacity_logits(opacities):
    """The cloud's stored opacity: logit(o) = log(o) - log1p(-o) in float64, rounded to
    float32, of o clamped to [OPACITY_CLAMP, 1 - OPACITY_CLAMP] (see OPACITY_CLAMP)."""
    o = np.clip(opacities.astype(np.float64), OPACITY_CLAMP, 1.0 - OPACITY_CLAMP)
    return (np.log(o) - np.log1p(-o)).astype(np.float32)


def rgb_to_f_dc(rgb):
    """The degree-0 SH coefficient whose colour is `rgb`: (c - 0.5) / SH_C0 in float64, rounded
    to float32 (as t/io's ColourToFDc)."""
    return ((rgb.astype(np.float64) - 0.5) / SH_C0).astype(np.float32)


def _colour_attributes(colors, n, sh_degree):
    """(f_dc [N, 3], f_rest [N, K - 1, 3] or None, the SH degree drawn) from gsplat's colours."""
    if colors.ndim == 2:
        _require_shape("colors", colors, (n, 3), " (RGB) or (N, K, 3) (SH coefficients)")
        if sh_degree is not None:
            raise ValueError(f"colors: (N, 3) RGB colours take sh_degree=None, not {sh_degree} "
                             "(SH coefficients are (N, K, 3))")
        return rgb_to_f_dc(colors), None, 0
    _require_shape("colors", colors, (n, None, 3), " (SH coefficients, or (N, 3) RGB)")
    k = colors.shape[1]
    if k == 0:
        raise ValueError("colors: (N, 0, 3) holds no SH coefficient")
    if sh_degree is None:
        degree = math.isqrt(k) - 1
        if (degree + 1) ** 2 != k:
            raise ValueError(f"colors: {k} SH coefficients is not (d + 1)^2 for any degree d; "
                             "give sh_degree to use the first (sh_degree + 1)^2")
    else:
        degree = operator.index(sh_degree)
        if degree < 0 or (degree + 1) ** 2 > k:
            raise ValueError(f"sh_degree {degree} needs {(degree + 1) ** 2} SH coefficients "
                             f"((sh_degree + 1)^2), colors has {k}")
    if degree > 3:
        raise ValueError(f"SH degree {degree}: this renderer evaluates degrees 0 to 3")
    used = (degree + 1) ** 2
    f_rest = np.ascontiguousarray(colors[:, 1:used]) if used > 1 else None
    return np.ascontiguousarray(colors[:, 0]), f_rest, degree


def _cameras(viewmats, ks, width, height):
    """One PinholeCamera per camera: gsplat's K (pixel centres at x + 0.5) moved to this
    renderer's convention (centres at x) by cx - 0.5, cy - 0.5."""
    if len(viewmats) != len(ks):
        raise ValueError(f"viewmats holds {len(viewmats)} cameras and Ks {len(ks)}: one K per viewmat")
    if len(viewmats) == 0:
        raise ValueError("viewmats: no camera (C = 0)")
    cameras = []
    for i, (view, k) in enumerate(zip(viewmats.astype(np.float64), ks.astype(np.float64))):
        if k[0, 1] != 0.0 or k[1, 0] != 0.0 or k[2].tolist() != [0.0, 0.0, 1.0]:
            raise ValueError(f"Ks[{i}] must be [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (no skew): "
                             f"{k.tolist()}")
        if np.abs(view[3] - [0.0, 0.0, 0.0, 1.0]).max() > 1e-5:
            raise ValueError(f"viewmats[{i}]: the last row must be [0, 0, 0, 1] (a world-to-camera "
                             f"[R | t] matrix), got {view[3].tolist()}")
        try:
            cameras.append(_camera.PinholeCamera(width, height, k[0, 0], k[1, 1], k[0, 2] - 0.5,
                                                 k[1, 2] - 0.5, view))
        except Open3DError as error:
            raise ValueError(f"viewmats[{i}] / Ks[{i}]: {error}") from error
    return cameras


def _knobs(knobs):
    """This call's renderer settings from gsplat's keyword arguments and ours."""
    settings = {"near_plane": 0.01, "antialias": False, "compact_storage": False}
    for name, value in knobs.items():
        if name == "near_plane":
            settings["near_plane"] = float(value)
        elif name == "far_plane":
            if not float(value) >= _GSPLAT_FAR_PLANE:
                raise ValueError(f"far_plane {value}: this renderer has no far plane (only gsplat's "
                                 f"default {_GSPLAT_FAR_PLANE:g} or more, which culls nothing here)")
        elif name == "rasterize_mode":
            if value not in ("classic", "antialiased"):
                raise ValueError(f"rasterize_mode '{value}': 'classic' or 'antialiased'")
            settings["antialias"] = value == "antialiased"
        elif name == "compact_storage":
            settings["compact_storage"] = bool(value)
        elif name in _FIXED_KNOBS:
            if not (value is _FIXED_KNOBS[name] or value == _FIXED_KNOBS[name]):
                raise ValueError(f"{name}={value!r}: this renderer draws only {name}="
                                 f"{_FIXED_KNOBS[name]!r}")
        elif name not in _IGNORED_KNOBS:
            raise TypeError(f"rasterization() got an unexpected keyword argument '{name}'")
    return settings


# --- Renderers kept between calls --------------------------------------------------------------

_CACHE_SIZE = 4  # (width, height, backend) entries: a Vulkan device each
_cache = collections.OrderedDict()
_cache_lock = threading.Lock()


def _renderer(width, height, backend):
    """The cached renderer of this size and backend and the lock that makes one call at a time
    use it; the least recently used one goes when a fifth is made."""
    key = (width, height, backend)
    with _cache_lock:
        entry = _cache.get(key)
        if entry is None:
            entry = (_visualization.rendering.OffscreenRenderer(width, height, backend), threading.Lock())
            _cache[key] = entry
            while len(_cache) > _CACHE_SIZE:
                _cache.popitem(last=False)
        _cache.move_to_end(key)
        return entry


def cache_clear():
    """Drops every cached renderer (and with it its Vulkan device)."""
    with _cache_lock:
        _cache.clear()


def cache_info():
    """The (width, height, backend) of each cached renderer, least recently used first."""
    with _cache_lock:
        return list(_cache)


# --- The call ----------------------------------------------------------------------------------

def _size(name, value):
    try:
        size = operator.index(value)
    except TypeError:
        raise TypeError(f"{name}: an int, not {type(value).__name__}") from None
    if size <= 0:
        raise ValueError(f"{name} must be positive, got {size}")
    return size


def _first_row(mask):
    return int(np.argmax(mask.reshape(len(mask), -1).any(axis=1)))


def _splat_cloud(means, quats, scales, opacities, f_dc, f_rest):
    """The library's splat cloud (docs/python.md "Arrays") of gsplat's activated arrays."""
    cloud = _t.geometry.PointCloud(means)
    cloud.point["scale"] = scales
    cloud.point["rot"] = _normalised_quats(quats)
    cloud.point["opacity"] = opacity_logits(opacities)[:, None]
    cloud.point["f_dc"] = f_dc
    if f_rest is not None:
        cloud.point["f_rest"] = f_rest
    return cloud


def rasterization(means, quats, scales, opacities, colors, viewmats, Ks, width, height, *,
                  sh_degree=None, backgrounds=None, render_mode="RGB", backend="vulkan", **knobs):
    """Renders N Gaussians into C cameras with gsplat's conventions; returns numpy arrays
    `(render_colors, render_alphas, meta)` shaped as gsplat's (docs/python.md "gsplat-style
    rasterization" lists every convention and how it differs from gsplat).

    means (N, 3); quats (N, 4) w, x, y, z, any norm (normalised here); scales (N, 3) linear
    (activated); opacities (N,) activated, in [0, 1] (0 and 1 are clamped by 2^-24, values
    outside are refused); colors (N, 3) RGB, or (N, K, 3) SH coefficients (DC first) of which
    the first (sh_degree + 1)^2 are used (sh_degree None: all K, a square); viewmats (C, 4, 4)
    world-to-camera; Ks (C, 3, 3) with gsplat's pixel centres at (x + 0.5, y + 0.5);
    backgrounds (C, 3) or None (black). Anything numpy reads (lists, CPU torch tensors) of any
    float or int dtype is accepted and converted to float32; NaN or Inf is refused naming the
    argument and its first bad row.

    render_mode: "RGB" (C, H, W, 3) colour; "ED" (C, H, W, 1) expected view z, sum(w z) / sum(w)
    (0 where nothing is drawn); "D" (C, H, W, 1) accumulated z, ED * alpha; "RGB+D" and "RGB+ED"
    (C, H, W, 4), the depth as the last channel. render_alphas: (C, H, W, 1) accumulated alpha.
    meta: width, height, n_cameras, render_mode, sh_degree, near_plane, rasterize_mode,
    backend, tile_size and `cameras`, the PinholeCamera of each view (this library's pixel
    centres), for OffscreenRenderer.

    backend: "vulkan" or "cpu" (the double-precision reference). Keyword knobs: gsplat's
    near_plane (default 0.01, gsplat's), far_plane (only >= 1e10: nothing is culled far away),
    rasterize_mode ("classic", or "antialiased": Mip-Splatting's compensation), eps2d (0.3),
    radius_clip (0.0), camera_model ("pinhole"), distributed (False), covars (None); packed,
    tile_size, sparse_grad, absgrad, channel_chunk and segmented are ignored (they do not change
    gsplat's image); compact_storage (ours: Vulkan half-precision storage).

    One renderer per (width, height, backend) is kept between calls (`rasterization.cache_clear()`
    drops them); the scene is freed when the call returns.
    """
    if render_mode not in RENDER_MODES:
        raise ValueError(f"render_mode '{render_mode}': one of {', '.join(RENDER_MODES)}")
    if backend not in BACKENDS:
        raise ValueError(f"backend '{backend}': 'vulkan' or 'cpu'")
    width, height = _size("width", width), _size("height", height)
    settings = _knobs(knobs)

    means = _float32("means", means)
    _require_shape("means", means, (None, 3))
    n = len(means)
    quats = _float32("quats", quats)
    _require_shape("quats", quats, (n, 4), " (w, x, y, z)")
    scales = _float32("scales", scales)
    _require_shape("scales", scales, (n, 3))
    opacities = _float32("opacities", opacities)
    _require_shape("opacities", opacities, (n,), " (an (N, 1) column: squeeze it)")
    colors = _float32("colors", colors)
    viewmats = _float32("viewmats", viewmats)
    _require_shape("viewmats", viewmats, (None, 4, 4))
    Ks = _float32("Ks", Ks)
    _require_shape("Ks", Ks, (None, 3, 3))
    c = len(viewmats)
    if backgrounds is not None:
        backgrounds = _float32("backgrounds", backgrounds)
        _require_shape("backgrounds", backgrounds, (c, 3), " (one RGB per camera of viewmats)")
    for name, array in (("means", means), ("quats", quats), ("scales", scales),
                        ("opacities", opacities), ("colors", colors), ("viewmats", viewmats),
                        ("Ks", Ks), ("backgrounds", backgrounds)):
        if array is not None:
            _require_finite(name, array)
    if n and ((opacities < 0) | (opacities > 1)).any():
        row = _first_row((opacities < 0) | (opacities > 1))
        raise ValueError(f"opacities[{row}] = {opacities[row]} is outside [0, 1]: pass activated "
                         "opacities (the sigmoid of the logits)")
    if n and (scales < 0).any():
        row = _first_row(scales < 0)
        raise ValueError(f"scales[{row}] = {scales[row].tolist()} is negative: pass activated "
                         "scales (exp of the log-scales)")
    f_dc, f_rest, degree = _colour_attributes(colors, n, sh_degree)
    cameras = _cameras(viewmats, Ks, width, height)
    if backgrounds is None:
        backgrounds = np.zeros((c, 3), np.float32)

    if n == 0:  # nothing to draw: the backgrounds (the renderer refuses an empty scene)
        images = np.zeros((c, height, width, 4), np.float32)
        images[..., :3] = backgrounds[:, None, None, :]
        expected = np.zeros((c, height, width), np.float32)
        renderer_backend = backend
    else:
        cloud = _splat_cloud(means, quats, scales, opacities, f_dc, f_rest)
        renderer, lock = _renderer(width, height, backend)
        with lock:
            renderer.sh_degree = degree
            renderer.antialias = settings["antialias"]
            renderer.near_plane = settings["near_plane"]
            renderer.compact_storage = settings["compact_storage"]
            try:
                renderer.scene.add_geometry("splats", cloud)
                del cloud  # the renderer holds its own copy
                images, expected = _render(renderer, cameras, backgrounds, render_mode)
            finally:
                # Frees the renderer's copy of the scene and the backend's (device memory
                # included): the cached renderer keeps no scene between calls.
                renderer.scene.clear_geometry()
        renderer_backend = renderer.backend

    alphas = np.ascontiguousarray(images[..., 3:4])
    depth = None
    if render_mode in ("ED", "RGB+ED"):
        depth = expected[..., None]
    elif render_mode in ("D", "RGB+D"):
        depth = expected[..., None] * alphas
    if render_mode == "RGB":
        render_colors = np.ascontiguousarray(images[..., :3])
    elif render_mode in ("D", "ED"):
        render_colors = np.ascontiguousarray(depth)
    else:
        render_colors = np.concatenate([images[..., :3], depth], axis=-1)
    meta = {
        "width": width, "height": height, "n_cameras": c, "render_mode": render_mode,
        "sh_degree": degree, "near_plane": settings["near_plane"],
        "rasterize_mode": "antialiased" if settings["antialias"] else "classic",
        "backend": renderer_backend, "tile_size": 16, "cameras": cameras,
    }
    return render_colors, alphas, meta


def _render(renderer, cameras, backgrounds, render_mode):
    """(C, H, W, 4) premultiplied-over-background RGBA and (C, H, W) expected depth (or None)."""
    # One batch per distinct background (the renderer has one background at a time): one
    # batch for the usual single colour.
    unique, group = np.unique(backgrounds, axis=0, return_inverse=True)
    group = group.reshape(-1)
    if len(unique) == 1:
        renderer.scene.set_background(unique[0].astype(np.float64))
        images = renderer.render_batch(cameras)
    else:
        images = np.empty((len(cameras), renderer.height, renderer.width, 4), np.float32)
        for g, background in enumerate(unique):
            members = np.flatnonzero(group == g)
            renderer.scene.set_background(background.astype(np.float64))
            images[members] = renderer.render_batch([cameras[i] for i in members])
    expected = None
    if render_mode != "RGB":
        # Depth comes from single renders (render_batch gives colour only); the alpha it is
        # normalised by is the batch's own for the same camera and scene.
        expected = np.empty(images.shape[:3], np.float32)
        for i, view in enumerate(cameras):
            renderer.setup_camera(view)
            expected[i] = renderer.render_to_depth_image("expected")
    return images, expected


rasterization.cache_clear = cache_clear
rasterization.cache_info = cache_info
