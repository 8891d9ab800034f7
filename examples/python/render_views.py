#!/usr/bin/env python3
"""Renders every view of a 3DGS cameras.json to PNGs without a display, in batches.

    PYTHONPATH=build/python python3 examples/python/render_views.py \
        ../shared/data/playbot/playbot_125k.ply ../shared/data/playbot/cameras.json out/
"""
import argparse
import pathlib
import sys
import time

import numpy as np

import open3d_gs as o3d


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", help="splat file in any format the library reads")
    parser.add_argument("cameras", help="3DGS cameras.json")
    parser.add_argument("output", help="folder for view_NNN.png (made when missing)")
    parser.add_argument("--backend", default="vulkan", choices=["vulkan", "cpu"])
    parser.add_argument("--width", type=int, help="image width (default: the first view's)")
    parser.add_argument("--height", type=int, help="image height (default: the first view's)")
    parser.add_argument("--batch", type=int, default=16, help="views per render_batch call")
    args = parser.parse_args()

    views = o3d.camera.read_cameras_json(args.cameras)
    width = args.width or views[0].camera.width
    height = args.height or views[0].camera.height
    out = pathlib.Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    renderer = o3d.visualization.rendering.OffscreenRenderer(width, height, args.backend)
    renderer.scene.add_geometry("scene", o3d.t.io.read_point_cloud(args.scene))
    # One array for every batch, in memory the GPU writes directly (no copy on the host).
    batch = renderer.batch_array(args.batch, "uint8")
    start = time.monotonic()
    for first in range(0, len(views), args.batch):
        chunk = views[first:first + args.batch]
        # rescale=True: --width / --height ask for the views at another size.
        images = renderer.render_batch([v.camera for v in chunk], "uint8", out=batch[:len(chunk)], rescale=True)
        for i, image in enumerate(images):
            o3d.io.write_image(out / f"view_{first + i:03d}.png", np.ascontiguousarray(image[..., :3]))
        done = first + len(chunk)
        bar = "#" * (30 * done // len(views))
        print(f"\r[{bar:<30}] {done}/{len(views)} views", end="", file=sys.stderr, flush=True)
    seconds = time.monotonic() - start
    print(f"\n{len(views)} views of {width}x{height} in {seconds:.2f} s ({len(views) / seconds:.1f} views/s, "
          f"{renderer.backend} backend) into {out}", file=sys.stderr)


if __name__ == "__main__":
    main()
