#!/usr/bin/env python3
"""A 3DGS scene handled the way Open3D code handles a point cloud: read it, transform it,
select from it, render it offscreen with setup_camera(intrinsic, extrinsic, width, height),
and write the pictures with o3d.io.write_image.

    build/bin/gs-python examples/python/open3d_style.py \\
        ../shared/data/playbot/playbot_31k.ply ../shared/data/playbot/cameras.json out/

For every view (the first --views of cameras.json): color_NNN.png (8-bit RGB over a white
background) and depth_NNN.png (16-bit, view z in millimetres, 0 where nothing is). The
scene is turned --degrees about the vertical through its centre (the cameras stay), and
splats outside the 1st..99th percentile box of the positions (stray far splats) are left
out.
"""
import argparse
import pathlib

import numpy as np

import open3d_gs as o3d


def turn_about_center(center, degrees):
    """The 4x4 turning about the y axis through `center` (Open3D's transform takes 4x4s)."""
    a = np.radians(degrees)
    rotation = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    T = np.eye(4)
    T[:3, :3] = rotation
    T[:3, 3] = center - rotation @ center
    return T


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", help="splat file in any format the library reads")
    parser.add_argument("cameras", help="3DGS cameras.json")
    parser.add_argument("output", help="folder for color_NNN.png and depth_NNN.png (made when missing)")
    parser.add_argument("--degrees", type=float, default=30.0, help="turn of the scene about its vertical")
    parser.add_argument("--views", type=int, default=4, help="how many views of cameras.json to render")
    parser.add_argument("--width", type=int, help="picture width (default: the first view's)")
    parser.add_argument("--height", type=int, help="picture height (default: the first view's)")
    parser.add_argument("--backend", default="vulkan", choices=["vulkan", "cpu"])
    args = parser.parse_args()
    out = pathlib.Path(args.output)
    out.mkdir(parents=True, exist_ok=True)

    pcd = o3d.io.read_point_cloud(args.scene)  # a t.geometry.PointCloud with the 3DGS attributes
    pcd.transform(turn_about_center(pcd.get_center(), args.degrees))  # rot and SH turn with it
    lo, hi = np.percentile(pcd.point.positions, [1, 99], axis=0)
    inside = np.all((pcd.point.positions >= lo) & (pcd.point.positions <= hi), axis=1)
    pcd = pcd.select_by_mask(inside)
    box = pcd.get_axis_aligned_bounding_box()
    print(f"{len(pcd)} splats, SH degree {pcd.get_sh_degree()}, from {box.min_bound.round(2)} "
          f"to {box.max_bound.round(2)}")

    views = o3d.camera.read_cameras_json(args.cameras)[:args.views]
    width = args.width or views[0].camera.width
    height = args.height or views[0].camera.height
    renderer = o3d.visualization.rendering.OffscreenRenderer(width, height, args.backend)
    material = o3d.visualization.rendering.MaterialRecord()
    material.shader = "gaussianSplat"
    renderer.scene.add_geometry("scene", pcd, material)
    renderer.scene.set_background([1.0, 1.0, 1.0])
    for i, view in enumerate(views):
        c = view.camera
        intrinsic = o3d.camera.PinholeCameraIntrinsic(c.width, c.height, c.fx, c.fy, c.cx, c.cy)
        # Open3D's overload; a view of another size than the picture is scaled to it only
        # when asked (rescale=True), since another aspect ratio would stretch it.
        renderer.setup_camera(intrinsic.intrinsic_matrix, c.world_to_camera, intrinsic.width,
                              intrinsic.height, rescale=True)
        o3d.io.write_image(out / f"color_{i:03d}.png", renderer.render_to_image("uint8"))
        depth = renderer.render_to_depth_image(z_in_view_space=True)  # Open3D's: inf where nothing is
        millimetres = np.where(np.isfinite(depth), np.clip(depth * 1000, 0, 65535), 0)
        o3d.io.write_image(out / f"depth_{i:03d}.png", np.round(millimetres).astype(np.uint16))
    print(f"{len(views)} views of {width}x{height} into {out}")


if __name__ == "__main__":
    main()
