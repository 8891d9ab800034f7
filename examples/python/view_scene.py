#!/usr/bin/env python3
"""Loads a splat scene and opens the interactive viewer on it (needs an X server; put
`xvfb-run -a` in front without a display).

    PYTHONPATH=build/python python3 examples/python/view_scene.py ../shared/data/playbot/playbot_31k.ply
"""
import argparse

import open3d_gs as o3d


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene")
    parser.add_argument("--seconds", type=float, default=0.0, help="close after this many seconds (0: on Q)")
    args = parser.parse_args()
    cloud = o3d.t.io.read_point_cloud(args.scene)
    print(f"{args.scene}: {len(cloud)} splats, SH degree {cloud.get_sh_degree()}")
    o3d.visualization.draw([("scene", cloud)], title=args.scene, max_seconds=args.seconds)


if __name__ == "__main__":
    main()
