#!/usr/bin/env python3
"""Renders the shared scenes with the original 3DGS CUDA rasterizer.

The original is graphdeco-inria/diff-gaussian-rasterization (commit 59f5f77), built
from its source folder (--peer) with torch.utils.cpp_extension and called through its
raw binding `_C.rasterize_gaussians`. Its Python package is not imported: it expects
`_C` to be installed next to it, and the forward call needs none of its autograd code.

The inputs reproduce what `gs-render --cameras F --view i --width 800 --height 800`
renders, with the same decoded splat values as our C++ readers produce. This is the
convention that made the crops in shared/data/parity, so keep it in step with them.

Only numpy is needed to read scenes and build cameras; torch is imported when the
peer is built, so the readers can be checked on machines without torch.
"""

import argparse
import hashlib
import json
import os
import re
import shutil
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

SH_C0 = 0.28209479177387814
REPO_ROOT = Path(__file__).resolve().parents[2]
DEFAULT_SHARED = REPO_ROOT.parent / "shared"
IMAGE_SIZE = 800
# getProjectionMatrix's planes as the 3DGS trainer sets them. The near plane only
# shapes the NDC z the rasterizer ignores; it culls at view z <= 0.2 on its own.
ZNEAR, ZFAR = 0.01, 100.0

# scene name -> (scene file, cameras file), relative to SHARED/data.
SCENES = {
    "playbot_31k": ("playbot/playbot_31k.ply", "playbot/cameras.json"),
    "chair": ("chair/chair.splat", "chair/cameras.json"),
    "biker_152k": ("biker/biker_152k.ply", "biker/cameras.json"),
}
# Scenes without a cameras.json: raw trainer outputs, viewed from orbit_cameras.py's 24 views.
ORBIT_SCENES = {
    "sh3_iter7000": "sh3_iter7000/point_cloud.ply",
    "sh3_iter7000_splat": "sh3_iter7000/model.splat",
    "train3": "train3/train_3points.ply",
    "pc_short": "pc_short/pc_short.ply",
}


# --------------------------------------------------------------------------- scenes


@dataclass
class Gaussians:
    """Decoded splats, float32, in the layout the original's forward pass takes."""

    means: np.ndarray  # [N, 3]
    shs: np.ndarray  # [N, (D+1)^2, 3], coefficient-major like the trainer's features
    opacities: np.ndarray  # [N, 1], after the sigmoid
    scales: np.ndarray  # [N, 3], linear
    rotations: np.ndarray  # [N, 4], (w, x, y, z), normalised
    sh_degree: int


PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}


def read_ply_vertices(path):
    """The vertex element of a binary little-endian PLY as a numpy structured array."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            raise ValueError(f"{path}: not a PLY file")
        fields, count, in_vertex = [], None, False
        while True:
            line = f.readline()
            if not line:
                raise ValueError(f"{path}: header has no end_header")
            words = line.decode("ascii").split()
            if not words or words[0] in ("comment", "obj_info"):
                continue
            if words[0] == "format" and words[1] != "binary_little_endian":
                raise ValueError(f"{path}: only binary_little_endian PLY is supported")
            if words[0] == "element":
                # Every element before the vertices would shift the data; 3DGS has none.
                if count is None and words[1] != "vertex":
                    raise ValueError(f"{path}: element '{words[1]}' precedes 'vertex'")
                in_vertex = words[1] == "vertex"
                if in_vertex:
                    count = int(words[2])
            if words[0] == "property" and in_vertex:
                if words[1] == "list":
                    raise ValueError(f"{path}: list property in 'vertex'")
                fields.append((words[2], "<" + PLY_TYPES[words[1]]))
            if words[0] == "end_header":
                break
        # Trailing bytes after the declared vertices are ignored, as our reader does.
        return np.fromfile(f, dtype=np.dtype(fields), count=count)


def sh_degree_for_rest(num_rest):
    for degree in range(4):
        if num_rest == 3 * ((degree + 1) ** 2 - 1):
            return degree
    raise ValueError(f"{num_rest} f_rest properties; expected 0, 9, 24 or 45")


def load_ply(path):
    """Raw 3DGS columns, decoded as our PLY reader does (cpp/open3d/t/io/PlyReader.cpp)."""
    v = read_ply_vertices(path)
    names = v.dtype.names
    num_rest = sum(1 for n in names if n.startswith("f_rest_"))
    degree = sh_degree_for_rest(num_rest)
    nc = (degree + 1) ** 2 - 1

    def cols(*keys):
        return np.stack([v[k].astype(np.float32) for k in keys], axis=1)

    f_dc = cols("f_dc_0", "f_dc_1", "f_dc_2")
    # The file stores f_rest channel-major: f_rest_[c * nc + k] is coefficient k of channel c.
    f_rest = np.zeros((len(v), 3, 0), np.float32)
    if nc:
        f_rest = cols(*[f"f_rest_{i}" for i in range(3 * nc)]).reshape(-1, 3, nc)
    shs = np.concatenate([f_dc[:, None, :], f_rest.transpose(0, 2, 1)], axis=1)
    # Our reader stores float32(exp(double(log_scale))).
    scales = np.exp(cols("scale_0", "scale_1", "scale_2").astype(np.float64)).astype(np.float32)
    return dict(
        means=cols("x", "y", "z"),
        shs=np.ascontiguousarray(shs),
        opacity_logit=cols("opacity")[:, 0],
        scales=scales,
        rot=cols("rot_0", "rot_1", "rot_2", "rot_3"),
        sh_degree=degree,
    )


def load_splat(path):
    """Raw columns of an antimatter15 .splat, decoded as cpp/open3d/t/io/SplatFormat.cpp does."""
    data = np.fromfile(path, dtype=np.uint8)
    if data.size % 32:
        raise ValueError(f"{path}: size {data.size} is not a multiple of 32")
    records = data.reshape(-1, 32)
    floats = records[:, :24].copy().view("<f4")
    rgba = records[:, 24:28].astype(np.float64)
    # Our reader turns the colour bytes back into f_dc and the alpha byte into a logit
    # (clamped off 0 and 1), each in double and stored as float32.
    f_dc = ((rgba[:, :3] / 255.0 - 0.5) / SH_C0).astype(np.float32)
    alpha = np.clip(rgba[:, 3] / 255.0, 1e-6, 1.0 - 1e-6)
    rot = ((records[:, 28:32].astype(np.float64) - 128.0) / 128.0).astype(np.float32)
    return dict(
        means=np.ascontiguousarray(floats[:, :3]),
        shs=f_dc[:, None, :],
        opacity_logit=np.log(alpha / (1.0 - alpha)).astype(np.float32),
        scales=np.ascontiguousarray(floats[:, 3:6]),
        rot=rot,
        sh_degree=0,
    )


def normalise_quaternions(rot):
    """Our reader's normalisation (SplatColumns.cpp FinalizeColumns): the squared norm in
    double, quaternions within 2^-20 of unit length kept bit-exact, the rest scaled by
    1/sqrt(n2) in double and stored as float32."""
    q = rot.astype(np.float64)
    n2 = np.sum(q * q, axis=1)
    if np.any(n2 == 0.0):
        raise ValueError(f"splat {int(np.argmax(n2 == 0.0))} has a zero rotation quaternion")
    scaled = (q * (1.0 / np.sqrt(n2))[:, None]).astype(np.float32)
    keep = np.abs(n2 - 1.0) <= 2.0**-20
    return np.where(keep[:, None], rot, scaled).astype(np.float32)


def sigmoid(x):
    with np.errstate(over="ignore"):  # exp(-x) -> inf gives the right limit, 0
        return (1.0 / (1.0 + np.exp(-x.astype(np.float64)))).astype(np.float32)


def load_scene(path):
    """Gaussians from a 3DGS PLY or .splat, activated as the rasterizer expects them."""
    path = Path(path)
    raw = load_splat(path) if path.suffix == ".splat" else load_ply(path)
    columns = [raw["means"], raw["shs"].reshape(len(raw["means"]), -1),
               raw["opacity_logit"][:, None], raw["scales"], raw["rot"]]
    # gs-render's reader refuses non-finite values by default; so do we, to stay aligned.
    bad = ~np.all(np.isfinite(np.concatenate(columns, axis=1)), axis=1)
    if bad.any():
        raise ValueError(f"{path}: splat {int(np.argmax(bad))} has a non-finite value")
    return Gaussians(
        means=raw["means"],
        shs=raw["shs"],
        opacities=sigmoid(raw["opacity_logit"])[:, None],
        scales=raw["scales"],
        rotations=normalise_quaternions(raw["rot"]),
        sh_degree=raw["sh_degree"],
    )


# -------------------------------------------------------------------------- cameras


@dataclass
class Camera:
    width: int
    height: int
    fx: float
    fy: float
    R: np.ndarray  # [3, 3] float32 world-to-camera rotation
    t: np.ndarray  # [3] float32
    viewmatrix: np.ndarray  # [4, 4] float32, the original's (transposed) layout
    projmatrix: np.ndarray  # [4, 4] float32, viewmatrix @ P^T
    tanfovx: float
    tanfovy: float
    campos: np.ndarray  # [3] float32


def load_cameras(path):
    with open(path) as f:
        return json.load(f)


def projection_matrix(tan_half_fovx, tan_half_fovy, znear=ZNEAR, zfar=ZFAR):
    """3DGS's getProjectionMatrix (utils/graphics_utils.py), in float64."""
    top = tan_half_fovy * znear
    right = tan_half_fovx * znear
    bottom, left = -top, -right
    P = np.zeros((4, 4))
    P[0, 0] = 2.0 * znear / (right - left)
    P[1, 1] = 2.0 * znear / (top - bottom)
    P[0, 2] = (right + left) / (right - left)
    P[1, 2] = (top + bottom) / (top - bottom)
    P[3, 2] = 1.0
    P[2, 2] = zfar / (zfar - znear)
    P[2, 3] = -(zfar * znear) / (zfar - znear)
    return P


def view_camera(entry, width=IMAGE_SIZE, height=IMAGE_SIZE):
    """The camera gs-render builds for one cameras.json entry at width x height.

    Mirrors camera/CamerasJson.cpp and PinholeCamera::Resized: focal lengths scale with
    the image size (for the shared 800x800, fx = fy views this is fx_json * 800 /
    height_json), the principal point is the image centre, R_wc = rotation^T and
    t = -R_wc @ position, all in float64.
    """
    fx = entry["fx"] * width / entry["width"]
    fy = entry["fy"] * height / entry["height"]
    R64 = np.asarray(entry["rotation"], dtype=np.float64).T
    t64 = -R64 @ np.asarray(entry["position"], dtype=np.float64)
    W2C = np.eye(4)
    W2C[:3, :3], W2C[:3, 3] = R64, t64
    # The original reads matrices column-major: 3DGS passes getWorld2View2(...).T.
    viewmatrix = W2C.astype(np.float32).T
    tanfovx, tanfovy = width / (2.0 * fx), height / (2.0 * fy)
    # The trainer fills P in a float32 tensor and multiplies float32 matrices; here P is
    # built in float64 and rounded to float32, the product of the float32 matrices is
    # taken in float64 and rounded once, so projmatrix is the correctly rounded product.
    P32 = projection_matrix(tanfovx, tanfovy).astype(np.float32)
    projmatrix = (viewmatrix.astype(np.float64) @ P32.T.astype(np.float64)).astype(np.float32)
    campos = (-R64.T @ t64).astype(np.float32)  # PinholeCamera::GetCenter
    return Camera(width, height, fx, fy, R64.astype(np.float32), t64.astype(np.float32),
                  viewmatrix, projmatrix, tanfovx, tanfovy, campos)


def parse_views(spec, count):
    if spec == "all":
        return list(range(count))
    views = [int(v) for v in spec.split(",") if v.strip()]
    for v in views:
        if not 0 <= v < count:
            raise ValueError(f"view {v} out of range 0..{count - 1}")
    return views


def parse_scenes(spec):
    known = [*SCENES, *ORBIT_SCENES]
    names = known if spec == "all" else [s.strip() for s in spec.split(",") if s.strip()]
    for name in names:
        if name not in known:
            raise ValueError(f"unknown scene '{name}' (known: {', '.join(known)})")
    return names


def scene_paths(shared, name):
    """(scene file, cameras.json), the latter None for ORBIT_SCENES (see orbit_cameras.py)."""
    data = Path(shared) / "data"
    if name in ORBIT_SCENES:
        return data / ORBIT_SCENES[name], None
    scene, cameras = SCENES[name]
    return data / scene, data / cameras


def scene_and_cameras(shared, name, cameras_dir):
    """Paths and contents; an orbit scene's generated views are written to cameras_dir."""
    scene_path, cameras_path = scene_paths(shared, name)
    gaussians = load_scene(scene_path)
    if cameras_path is None:
        from orbit_cameras import write_orbit_cameras
        cameras_path = Path(cameras_dir) / f"{name}_cameras.json"
        write_orbit_cameras(gaussians.means, cameras_path)
    return scene_path, cameras_path, gaussians, load_cameras(cameras_path)


# ------------------------------------------------------------------ peer extension


def log(msg):
    print(msg, flush=True)


def _torch_header_has(pattern, *relative_paths):
    from torch.utils.cpp_extension import include_paths

    for base in include_paths():
        for rel in relative_paths:
            p = Path(base) / rel
            if p.is_file() and re.search(pattern, p.read_text(errors="replace")):
                return True
    return False


def _cuda_header_exists(name):
    from torch.utils.cpp_extension import CUDA_HOME

    return CUDA_HOME is not None and (Path(CUDA_HOME) / "include" / name).is_file()


# API spellings of 2023 that a newer torch / CUDA may have dropped, as (name, regex,
# replacement). Each is a rename with the same meaning (Tensor::data<T>() returned
# data_ptr<T>(); AT_ERROR was TORCH_CHECK(false, ...); device_launch_parameters.h only
# declares what nvcc predefines), valid on old toolchains too, so no numerics change.
COMPAT_PATCHES = [
    ("Tensor::data<T>() -> data_ptr<T>()", r"\.data<", ".data_ptr<"),
    ("AT_ERROR -> TORCH_CHECK(false, ...)", r"\bAT_ERROR\(", "TORCH_CHECK(false, "),
    ("drop #include device_launch_parameters.h", r'#include\s*"device_launch_parameters.h"', ""),
]


def needed_compat_patches():
    """The patches the local torch / CUDA headers call for; empty when the pristine
    sources should compile as they are."""
    needed = []
    if not _torch_header_has(r"T\s*\*\s*data\(\)\s*const", "ATen/core/TensorBody.h",
                             "ATen/core/TensorBase.h"):
        needed.append(COMPAT_PATCHES[0])
    if not _torch_header_has(r"define\s+AT_ERROR", "c10/util/Exception.h"):
        needed.append(COMPAT_PATCHES[1])
    if not _cuda_header_exists("device_launch_parameters.h"):
        needed.append(COMPAT_PATCHES[2])
    return needed


def patched_copy(peer, build_dir, patches):
    """A copy of the peer's sources under build_dir with the patches applied."""
    dst = Path(build_dir) / "patched-src"
    if dst.exists():
        shutil.rmtree(dst)
    shutil.copytree(peer, dst, ignore=shutil.ignore_patterns(".git", "build", "third_party"))
    for path in dst.rglob("*"):
        if path.suffix not in (".cu", ".cpp", ".h"):
            continue
        text = path.read_text()
        new = text
        for _, pattern, repl in patches:
            new = re.sub(pattern, repl, new)
        if new != text:
            path.write_text(new)
    return dst


def peer_sources(src):
    """The extension's sources as setup.py lists them."""
    names = ["cuda_rasterizer/rasterizer_impl.cu", "cuda_rasterizer/forward.cu",
             "cuda_rasterizer/backward.cu", "rasterize_points.cu", "ext.cpp"]
    return [str(Path(src) / n) for n in names]


def default_build_dir(peer):
    # Stable per peer folder, so a second run on the same machine reuses the objects.
    key = hashlib.sha1(str(Path(peer).resolve()).encode()).hexdigest()[:10]
    return Path(tempfile.gettempdir()) / f"gs-parity-peer-build-{key}"


def _load_extension(src, glm, build_dir):
    from torch.utils.cpp_extension import load

    # setup.py passes only the glm include to nvcc. The pre-included <cstdint> covers
    # toolchains whose headers no longer pull it in for rasterizer_impl.h's uintptr_t.
    return load(
        name="diff_gaussian_rasterization_peer_C",
        sources=peer_sources(src),
        extra_cuda_cflags=["-I" + glm, "-include", "cstdint"],
        extra_cflags=["-include", "cstdint"],
        extra_include_paths=[glm],
        build_directory=str(build_dir),
        verbose=True,
    )


def build_peer(peer, build_dir=None, force_compat=False):
    """Builds the original's extension and returns (module, info dict).

    The pristine sources are built unless the local headers show that an old API
    spelling is gone (or --compat); if the pristine build fails anyway, it is retried
    once from a copy with every compatibility rename applied.
    """
    import torch

    peer = Path(peer).resolve()
    if not (peer / "cuda_rasterizer" / "forward.cu").is_file():
        raise FileNotFoundError(f"{peer} is not a diff-gaussian-rasterization source folder")
    glm = peer / "third_party" / "glm"
    if not (glm / "glm" / "glm.hpp").is_file():
        raise FileNotFoundError(f"{glm}/glm/glm.hpp missing (copy glm's glm/ folder there)")
    if not torch.cuda.is_available():
        raise RuntimeError("torch sees no CUDA device")
    build_dir = Path(build_dir or default_build_dir(peer))
    build_dir.mkdir(parents=True, exist_ok=True)
    major, minor = torch.cuda.get_device_capability()
    # The local GPU's architecture only, unless the caller chose one.
    os.environ.setdefault("TORCH_CUDA_ARCH_LIST", f"{major}.{minor}")
    log(f"peer: building {peer} for TORCH_CUDA_ARCH_LIST={os.environ['TORCH_CUDA_ARCH_LIST']} "
        f"in {build_dir} (torch {torch.__version__}, CUDA {torch.version.cuda}); "
        "a few minutes the first time")

    patches = list(COMPAT_PATCHES) if force_compat else needed_compat_patches()
    start = time.time()
    try:
        src = patched_copy(peer, build_dir, patches) if patches else peer
        for name, _, _ in patches:
            log(f"peer: compatibility rename: {name}")
        module = _load_extension(src, str(glm), build_dir)
    except Exception as e:  # noqa: BLE001 - any build error earns one retry
        if patches == COMPAT_PATCHES:
            raise
        log(f"peer: build failed ({type(e).__name__}: {e}); retrying with every rename")
        patches = list(COMPAT_PATCHES)
        module = _load_extension(patched_copy(peer, build_dir, patches), str(glm), build_dir)
    log(f"peer: built in {time.time() - start:.1f} s")
    commit_file = peer / "PEER_COMMIT"
    info = {
        "peer_dir": str(peer),
        "peer_commit": commit_file.read_text().strip() if commit_file.is_file() else None,
        "compat_renames": [name for name, _, _ in patches],
        "cuda_arch_list": os.environ["TORCH_CUDA_ARCH_LIST"],
        "gpu": torch.cuda.get_device_name(),
        "torch": torch.__version__,
        "torch_cuda": torch.version.cuda,
    }
    return module, info


class OriginalRenderer:
    """Renders views with the built extension; keeps one scene on the GPU at a time."""

    def __init__(self, module):
        import torch

        self.torch = torch
        self.module = module
        self.device = torch.device("cuda")
        self._scene_key = None
        self._scene = None

    def _upload(self, key, g):
        if key != self._scene_key:
            t = lambda a: self.torch.from_numpy(np.ascontiguousarray(a)).to(self.device)
            self._scene = dict(means=t(g.means), shs=t(g.shs), opacities=t(g.opacities),
                               scales=t(g.scales), rotations=t(g.rotations), degree=g.sh_degree)
            self._scene_key = key
        return self._scene

    def render(self, key, gaussians, cam):
        """float32 [H, W, 3], black background, not clamped."""
        torch = self.torch
        s = self._upload(key, gaussians)
        t = lambda a: torch.from_numpy(np.ascontiguousarray(a)).to(self.device)
        empty = torch.Tensor([])  # what GaussianRasterizer passes for unused inputs
        args = (
            torch.zeros(3, dtype=torch.float32, device=self.device),  # bg
            s["means"], empty, s["opacities"], s["scales"], s["rotations"],
            1.0,  # scale_modifier
            empty,  # cov3D_precomp
            t(cam.viewmatrix), t(cam.projmatrix),
            float(cam.tanfovx), float(cam.tanfovy),
            cam.height, cam.width,
            s["shs"], s["degree"], t(cam.campos),
            False,  # prefiltered
            False,  # debug
        )
        with torch.no_grad():
            _, color, _, _, _, _ = self.module.rasterize_gaussians(*args)
        torch.cuda.synchronize()
        return color.permute(1, 2, 0).contiguous().cpu().numpy()


# ----------------------------------------------------------------------------- main


def add_common_args(parser):
    parser.add_argument("--peer", required=True,
                        help="the original's source folder (diff-gaussian-rasterization)")
    parser.add_argument("--build-dir", help="where to build the peer (default: a stable temp dir)")
    parser.add_argument("--compat", action="store_true",
                        help="build from a patched copy even if the pristine sources should do")
    parser.add_argument("--shared", default=str(DEFAULT_SHARED),
                        help="shared folder with data/ (default: ../shared beside the repo)")
    parser.add_argument("--scenes", default="all",
                        help=f"all or a list of {', '.join([*SCENES, *ORBIT_SCENES])}")
    parser.add_argument("--views", default="all", help="all or a list such as 0,9")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_common_args(parser)
    parser.add_argument("--out", required=True, help="folder for {scene}_view{i:02d}.npy")
    args = parser.parse_args(argv)

    module, _ = build_peer(args.peer, args.build_dir, args.compat)
    renderer = OriginalRenderer(module)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name in parse_scenes(args.scenes):
        _, _, gaussians, cameras = scene_and_cameras(args.shared, name, out)
        log(f"{name}: {len(gaussians.means)} splats, SH degree {gaussians.sh_degree}")
        for i in parse_views(args.views, len(cameras)):
            start = time.time()
            image = renderer.render(name, gaussians, view_camera(cameras[i]))
            np.save(out / f"{name}_view{i:02d}.npy", image)
            log(f"  view {i:2d}: {time.time() - start:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
