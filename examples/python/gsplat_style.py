#!/usr/bin/env python3
"""Renders a 3DGS scene the way a gsplat script does: arrays in, images out.

The PLY's columns are read with numpy and activated as gsplat takes them (exp of the
log-scales, sigmoid of the opacity logits, SH coefficients as (N, K, 3)); cameras.json becomes
world-to-camera viewmats and Ks with gsplat's pixel centres (principal point at W / 2, H / 2);
one open3d_gs.rasterization call renders a batch of views. Writes view_NNN.png (RGB over the
background) and depth_NNN.npy (expected view z, (H, W) float32, 0 where nothing is drawn).
Scenes in other formats are read with open3d_gs.t.io and their arrays pulled out.

    PYTHONPATH=build/python python3 examples/python/gsplat_style.py \\
        ../shared/data/playbot/playbot_31k.ply ../shared/data/playbot/cameras.json out/ \\
        --width 400 --height 300 --views 0,6,12
"""
import argparse
import json
import pathlib
import sys
import time

import numpy as np

import open3d_gs


def read_ply_gaussians(path):
    """means, quats, scales, opacities, sh (N, K, 3) of a binary 3DGS PLY of float columns,
    activated as gsplat takes them; None for any other PLY (compressed, ASCII)."""
    raw = path.read_bytes()
    end = raw.find(b"end_header\n") + len(b"end_header\n")
    header = raw[:end].decode("ascii", "replace").splitlines()
    elements = [line for line in header if line.startswith("element")]
    properties = [line.split() for line in header if line.startswith("property")]
    names = [p[-1] for p in properties]
    if ("format binary_little_endian 1.0" not in header or len(elements) != 1
            or any(p[1] != "float" for p in properties) or "f_dc_0" not in names):
        return None
    count = int(elements[0].split()[2])
    table = np.frombuffer(raw, dtype=[(n, "<f4") for n in names], count=count, offset=end)

    def columns(*cols):
        return np.stack([table[c] for c in cols], axis=1)

    means = columns("x", "y", "z")
    quats = columns("rot_0", "rot_1", "rot_2", "rot_3")  # w, x, y, z; rasterization normalises
    scales = np.exp(columns("scale_0", "scale_1", "scale_2"))
    opacities = 1.0 / (1.0 + np.exp(-table["opacity"].astype(np.float64)))
    # f_rest is stored channel-major (all of red's coefficients, then green's, then blue's);
    # gsplat's SH are (N, K, 3) with the DC term first.
    rest = sorted((n for n in names if n.startswith("f_rest_")), key=lambda n: int(n[7:]))
    per_channel = len(rest) // 3
    sh = np.empty((count, 1 + per_channel, 3), np.float32)
    sh[:, 0] = columns("f_dc_0", "f_dc_1", "f_dc_2")
    for c in range(3):
        sh[:, 1:, c] = columns(*rest[c * per_channel:(c + 1) * per_channel])
    return means, quats, scales, opacities, sh


def read_any_gaussians(path):
    """The same arrays from any format the library reads (its cloud stores linear scales,
    unit quaternions, logits and f_dc / f_rest)."""
    cloud = open3d_gs.t.io.read_point_cloud(str(path))
    p = cloud.point
    sh = p.f_dc[:, None, :]
    if "f_rest" in p:
        sh = np.concatenate([sh, p.f_rest], axis=1)
    opacities = 1.0 / (1.0 + np.exp(-p.opacity[:, 0].astype(np.float64)))
    return p.positions.copy(), p.rot.copy(), p.scale.copy(), opacities, sh


def read_gaussians(path):
    path = pathlib.Path(path)
    arrays = read_ply_gaussians(path) if path.suffix.lower() == ".ply" else None
    return arrays if arrays is not None else read_any_gaussians(path)


def gsplat_cameras(entries, width, height):
    """viewmats (C, 4, 4) world-to-camera and Ks (C, 3, 3) of cameras.json entries, scaled to
    width x height, principal point at the image centre in gsplat's convention."""
    viewmats, Ks = [], []
    for e in entries:
        # 3DGS writes the camera-to-world rotation and the camera centre.
        rotation, centre = np.array(e["rotation"]), np.array(e["position"])
        viewmat = np.eye(4)
        viewmat[:3, :3] = rotation.T
        viewmat[:3, 3] = -rotation.T @ centre
        fx, fy = e["fx"] * width / e["width"], e["fy"] * height / e["height"]
        viewmats.append(viewmat)
        Ks.append([[fx, 0, width / 2], [0, fy, height / 2], [0, 0, 1]])
    return np.array(viewmats), np.array(Ks)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", help="3DGS PLY (other formats through open3d_gs.t.io)")
    parser.add_argument("cameras", help="3DGS cameras.json")
    parser.add_argument("output", help="folder for view_NNN.png and depth_NNN.npy (made when missing)")
    parser.add_argument("--views", help="comma-separated view indices (default: every view)")
    parser.add_argument("--width", type=int, help="image width (default: the first view's)")
    parser.add_argument("--height", type=int, help="image height (default: the first view's)")
    parser.add_argument("--background", type=float, nargs=3, default=[0.0, 0.0, 0.0], metavar=("R", "G", "B"))
    parser.add_argument("--sh-degree", type=int, help="SH degree to draw (default: all the file has)")
    parser.add_argument("--batch", type=int, default=8, help="cameras per rasterization call")
    parser.add_argument("--backend", default="vulkan", choices=["vulkan", "cpu"])
    args = parser.parse_args()

    means, quats, scales, opacities, sh = read_gaussians(args.scene)
    entries = json.loads(pathlib.Path(args.cameras).read_text())
    width, height = args.width or entries[0]["width"], args.height or entries[0]["height"]
    ids = [int(v) for v in args.views.split(",")] if args.views else list(range(len(entries)))
    out = pathlib.Path(args.output)
    out.mkdir(parents=True, exist_ok=True)

    start = time.monotonic()
    for at in range(0, len(ids), args.batch):
        chunk = ids[at:at + args.batch]
        viewmats, Ks = gsplat_cameras([entries[i] for i in chunk], width, height)
        backgrounds = np.tile(args.background, (len(chunk), 1))
        colors, alphas, meta = open3d_gs.rasterization(
            means, quats, scales, opacities, sh, viewmats, Ks, width, height, sh_degree=args.sh_degree,
            backgrounds=backgrounds, render_mode="RGB+ED", backend=args.backend)
        for view, image in zip(chunk, colors):
            rgb8 = np.round(np.clip(image[..., :3], 0.0, 1.0) * 255.0).astype(np.uint8)
            open3d_gs.io.write_image(out / f"view_{view:03d}.png", rgb8)
            np.save(out / f"depth_{view:03d}.npy", image[..., 3])
    seconds = time.monotonic() - start
    print(f"{len(ids)} views of {width}x{height} ({len(means)} splats, SH degree {meta['sh_degree']}, "
          f"{meta['backend']}) in {seconds:.2f} s into {out}", file=sys.stderr)


if __name__ == "__main__":
    main()
