#!/usr/bin/env python3
"""Views per second of OffscreenRenderer.render_batch from Python, the number gs-bench
--batch gives for C++ (docs/python.md): batches of N views (a cameras.json's views
repeated) at W x H, readback to numpy included, float32 and uint8.

    PYTHONPATH=build/python python3 benchmarks/python/batch_views_per_second.py \
        ../shared/data/playbot/playbot_125k.ply ../shared/data/playbot/cameras.json
"""
import argparse
import time

import open3d_gs as o3d


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene")
    parser.add_argument("cameras")
    parser.add_argument("--batch", type=int, default=64)
    parser.add_argument("--size", type=int, nargs=2, default=(800, 800), metavar=("W", "H"))
    parser.add_argument("--seconds", type=float, default=5.0, help="timed seconds per dtype")
    parser.add_argument("--backend", default="vulkan", choices=["vulkan", "cpu"])
    args = parser.parse_args()
    views = o3d.camera.read_cameras_json(args.cameras)
    cameras = [views[i % len(views)].camera for i in range(args.batch)]
    r = o3d.visualization.rendering.OffscreenRenderer(args.size[0], args.size[1], args.backend)
    r.scene.add_geometry("scene", o3d.t.io.read_point_cloud(args.scene))
    for dtype in ("uint8", "float32"):
        # A new array per call, one numpy array reused, one batch_array reused (the GPU
        # writes it directly on Vulkan).
        for mode in ("new array", "out= reused", "out=batch_array"):
            # RGBA in both dtypes (alpha=True): what the device writes, the numbers in
            # docs/python.md; the cameras.json views are scaled to --size (rescale=True).
            out = r.render_batch(cameras, dtype, alpha=True, rescale=True)  # warm-up: pipelines, buffers, clocks
            if mode == "out=batch_array":
                out = r.batch_array(args.batch, dtype)
            reused = out if mode != "new array" else None
            for _ in range(2):
                r.render_batch(cameras, dtype, out=reused, alpha=True, rescale=True)
            batches, start = 0, time.monotonic()
            while time.monotonic() - start < args.seconds:
                r.render_batch(cameras, dtype, out=reused, alpha=True, rescale=True)
                batches += 1
            seconds = time.monotonic() - start
            print(f"python render_batch {dtype}, {mode}: "
                  f"{batches * args.batch / seconds:.0f} views/s ({batches} batches of {args.batch} "
                  f"at {args.size[0]}x{args.size[1]}, {r.backend})", flush=True)


if __name__ == "__main__":
    main()
