#!/usr/bin/env python3
"""Compares two renders of the same view: the Vulkan backend against the CPU reference by
default, or two scene files (e.g. a PLY and its SPZ) with one backend. Prints PSNR and the
largest difference.

    PYTHONPATH=build/python python3 examples/python/compare_renders.py \
        ../shared/data/biker/biker_152k.ply ../shared/data/biker/cameras.json --view 0
"""
import argparse

import numpy as np

import open3d_gs as o3d


def render(scene, camera, backend, size):
    renderer = o3d.visualization.rendering.OffscreenRenderer(size[0], size[1], backend)
    renderer.scene.add_geometry("scene", o3d.t.io.read_point_cloud(scene))
    renderer.setup_camera(camera, rescale=True)  # the view at --size
    return renderer.render_to_image()


def psnr(a, b):
    mse = float(np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2))
    return float("inf") if mse == 0 else 10 * np.log10(1.0 / mse)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene")
    parser.add_argument("cameras")
    parser.add_argument("--view", type=int, default=0)
    parser.add_argument("--other-scene", help="compare with this file (same backend) instead of the CPU reference")
    parser.add_argument("--backend", default="vulkan", choices=["vulkan", "cpu"])
    parser.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), default=(400, 400))
    args = parser.parse_args()
    camera = o3d.camera.read_cameras_json(args.cameras)[args.view].camera
    a = render(args.scene, camera, args.backend, args.size)
    if args.other_scene:
        b, what = render(args.other_scene, camera, args.backend, args.size), args.other_scene
    else:
        b, what = render(args.scene, camera, "cpu", args.size), "the CPU reference"
    rgb_a, rgb_b = a[..., :3], b[..., :3]
    print(f"view {args.view} at {args.size[0]}x{args.size[1]}, {args.backend} against {what}: "
          f"PSNR {psnr(rgb_a, rgb_b):.1f} dB, max difference {np.abs(rgb_a - rgb_b).max():.2e}")


if __name__ == "__main__":
    main()
