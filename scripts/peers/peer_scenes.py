#!/usr/bin/env python3
"""The scenes and views the peers are timed on: view 0 of each scene as gs-bench renders it.

For time_peers.py. Scene names (render_original.SCENES plus playbot_125k), gridK scenes,
PATH[:CAMERAS] specs and any of those but a grid with #N (its first N splats, gs-bench
--first N: the frame's fixed cost, issue 47's one-splat and 1,000-splat rows) are loaded with render_original's readers, so every peer gets the splats
our C++ readers decode. The view is gs-bench's (cpp/apps/gs_bench/BenchScenes.cpp):
ScaleViewTo for cameras.json scenes (bench_view_entry), and for --grid K the scene of
MakeGridScene (make_grid) and the camera of MakeGridCamera (grid_camera_entry), reproduced
here because gs-bench and gs-convert cannot write the grid out. Only numpy: no torch.
"""

from pathlib import Path

import numpy as np

from parity_imports import ro

# Scene names beside render_original's: name -> (scene, cameras) under SHARED/data.
SCENES = {"playbot_125k": ("playbot/playbot_125k.ply", "playbot/cameras.json"), **ro.SCENES}
DEFAULT_SCENES = "playbot_125k,chair,biker_152k,grid7,playbot_125k#1,playbot_125k#1000"
DEFAULT_GRID_TILE = "playbot_125k"


def bench_view_entry(entry, width, height):
    """A cameras.json entry for `entry` moved to width x height as gs-bench moves it.

    gs-bench's ScaleViewTo (cpp/apps/gs_bench/BenchScenes.cpp): fx = fy = fx_json * H /
    H_json, principal point at the image centre. render_original.view_camera of the
    returned entry at (width, height) is exactly that camera, and gs-render reads it so too.
    """
    fx = entry["fx"] * height / entry["height"]
    return {"id": 0, "img_name": "bench", "width": width, "height": height, "fx": fx, "fy": fx,
            "position": list(entry["position"]), "rotation": [list(r) for r in entry["rotation"]]}


def make_grid(tile, k):
    """gs-bench --grid K's scene: bench::MakeGridScene (cpp/apps/gs_bench/BenchScenes.cpp).

    K x K copies of `tile`, copy (gx, gz) at block gz * K + gx, its x and z moved by
    (g - (K - 1) / 2) * s, s = 1.1 * max(extent_x, extent_z) of the tile's bounding box,
    each coordinate float32(double(x) + offset). Returns (grid Gaussians, s).
    """
    if k < 1:
        raise ValueError(f"grid K must be >= 1, got {k}")
    p = tile.means
    lo = p.min(axis=0).astype(np.float64)
    hi = p.max(axis=0).astype(np.float64)
    s = 1.1 * max(float(hi[0] - lo[0]), float(hi[2] - lo[2]))
    blocks = []
    x64, z64 = p[:, 0].astype(np.float64), p[:, 2].astype(np.float64)
    for gz in range(k):
        for gx in range(k):
            block = p.copy()
            block[:, 0] = (x64 + (gx - (k - 1) / 2.0) * s).astype(np.float32)
            block[:, 2] = (z64 + (gz - (k - 1) / 2.0) * s).astype(np.float32)
            blocks.append(block)
    copies = k * k

    def tiled(a):
        return np.tile(a, (copies,) + (1,) * (a.ndim - 1))

    grid = ro.Gaussians(means=np.concatenate(blocks), shs=tiled(tile.shs),
                        opacities=tiled(tile.opacities), scales=tiled(tile.scales),
                        rotations=tiled(tile.rotations), sh_degree=tile.sh_degree)
    return grid, s


def grid_camera_entry(tile, view0, k, spacing, width, height):
    """gs-bench --grid K's camera: bench::MakeGridCamera (cpp/apps/gs_bench/BenchScenes.cpp).

    The rotation of cameras.json view 0, fx = fy = 1400 H / 1080, principal point at the
    centre, centre = mean(tile positions) - forward * d, forward = the camera-to-world
    rotation's third column, d = 1.05 (K s / 2) / (W / (2 fx)). The mean is summed in
    double in file order, as the C++ loop does (cumsum adds sequentially).
    """
    n = len(tile.means)
    mean = np.cumsum(tile.means.astype(np.float64), axis=0)[-1] / max(n, 1)
    fx = 1400.0 * height / 1080.0
    rotation = np.asarray(view0["rotation"], dtype=np.float64)  # rows; camera-to-world
    forward = rotation[:, 2]
    d = 1.05 * (k * spacing / 2.0) / (width / (2.0 * fx))
    centre = mean - forward * d
    return {"id": 0, "img_name": f"grid{k}", "width": width, "height": height, "fx": fx,
            "fy": fx, "position": [float(v) for v in centre],
            "rotation": [list(r) for r in view0["rotation"]]}


class Scene:
    """One benchmark scene: its splats and view 0 at any size, as gs-bench renders it."""

    def __init__(self, label, bench_name, path, cameras_path, gaussians, entry_at, grid=None,
                 first=None):
        self.label = label  # short name for tables
        self.bench_name = bench_name  # gs-bench's name for it (file name, gridKxK, [first N])
        self.path = Path(path)
        self.cameras_path = Path(cameras_path)
        self.gaussians = gaussians
        self.entry_at = entry_at  # (width, height) -> cameras.json entry of view 0
        self.grid = grid  # K for a grid scene
        self.first = first  # N for the first N splats of the file (gs-bench --first N)


def parse_scene_specs(text):
    return [s.strip() for s in text.split(",") if s.strip()]


def resolve_scene_file(spec, shared):
    """(label, scene file, cameras.json) of a scene name or a path[:cameras]."""
    data = Path(shared) / "data"
    if spec in SCENES:
        scene, cameras = SCENES[spec]
        return spec, data / scene, data / cameras
    path, _, cameras = spec.partition(":")
    path = Path(path)
    cameras = Path(cameras) if cameras else path.parent / "cameras.json"
    if not path.is_file():
        raise ValueError(f"scene '{spec}': no such scene name ({', '.join(SCENES)}) or file")
    if not cameras.is_file():
        raise ValueError(f"scene '{spec}': no cameras file {cameras}")
    return path.stem, path, cameras


def load_scenes(specs, shared, grid_tile):
    tiles = {}

    def tile_of(spec):
        if spec not in tiles:
            label, path, cameras = resolve_scene_file(spec, shared)
            tiles[spec] = (label, path, cameras, ro.load_scene(path), ro.load_cameras(cameras))
        return tiles[spec]

    scenes = []
    for spec in specs:
        if spec.startswith("grid") and spec[4:].isdigit():
            k = int(spec[4:])
            _, path, cameras_path, tile, cameras = tile_of(grid_tile)
            grid, spacing = make_grid(tile, k)
            view0 = cameras[0]
            scenes.append(Scene(
                f"grid{k}x{k}", f"grid{k}x{k}", path, cameras_path, grid,
                lambda w, h, tile=tile, view0=view0, k=k, s=spacing:
                    grid_camera_entry(tile, view0, k, s, w, h),
                grid=k))
        else:
            spec, _, first = spec.partition("#")
            if first and (not first.isdigit() or int(first) < 1):
                raise ValueError(f"scene '{spec}#{first}': #N takes a splat count >= 1")
            label, path, cameras_path, gaussians, cameras = tile_of(spec)
            view0 = cameras[0]
            bench_name = path.name
            if first:
                n = int(first)
                gaussians = first_splats(gaussians, n)
                label = f"{label} first {n:,}"
                bench_name = f"{path.name}[first {n}]"  # gs-bench's job name (GsBench.cpp)
            scenes.append(Scene(label, bench_name, path, cameras_path, gaussians,
                                lambda w, h, view0=view0: bench_view_entry(view0, w, h),
                                first=int(first) if first else None))
    return scenes


def first_splats(g, n):
    """The first n splats: bench::FirstSplats, which refuses n past the scene's count."""
    if n > len(g.means):
        raise ValueError(f"#{n}: the scene has {len(g.means)} splats")
    return ro.Gaussians(means=g.means[:n], shs=g.shs[:n], opacities=g.opacities[:n],
                        scales=g.scales[:n], rotations=g.rotations[:n], sh_degree=g.sh_degree)


def parse_resolutions(text):
    out = []
    for item in text.split(","):
        w, sep, h = item.strip().lower().partition("x")
        if not sep or not w.isdigit() or not h.isdigit() or int(w) < 1 or int(h) < 1:
            raise ValueError(f"resolution '{item}' must look like 1920x1080")
        out.append((int(w), int(h)))
    return out
