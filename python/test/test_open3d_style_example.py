"""examples/python/open3d_style.py on playbot_31k: its PNGs equal renders made here through
the other API (PinholeCamera, rotate, numpy indexing), so the Open3D-style calls do what they
say."""
import pathlib
import subprocess
import sys

import numpy as np

import open3d_gs as o3d

EXAMPLE = pathlib.Path(__file__).resolve().parents[2] / "examples/python/open3d_style.py"


def test_open3d_style_example(data, backend, tmp_path):
    scene, cameras = data("playbot/playbot_31k.ply"), data("playbot/cameras.json")
    done = subprocess.run([sys.executable, str(EXAMPLE), str(scene), str(cameras), str(tmp_path),
                           "--width", "64", "--height", "48", "--views", "2", "--degrees", "30",
                           "--backend", backend], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "2 views of 64x48" in done.stdout

    # The same scene by other means: rotate about the centre, a numpy mask, PinholeCamera.
    pcd = o3d.t.io.read_point_cloud(str(scene))
    a = np.radians(30)
    R = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    pcd.rotate(R, pcd.get_center())
    p = pcd.point.positions
    lo, hi = np.percentile(p, [1, 99], axis=0)
    keep = np.flatnonzero(np.all((p >= lo) & (p <= hi), axis=1))
    pcd = pcd.select_by_index(keep)
    r = o3d.visualization.rendering.OffscreenRenderer(64, 48, backend)
    r.scene.add_geometry("scene", pcd)
    r.scene.set_background([1.0, 1.0, 1.0])
    for i, view in enumerate(o3d.camera.read_cameras_json(str(cameras))[:2]):
        r.setup_camera(view.camera, rescale=True)
        color = o3d.io.read_image(tmp_path / f"color_{i:03d}.png")
        assert color.shape == (48, 64, 3) and color.dtype == np.uint8
        # transform rounds the positions once, rotate about a centre in its own order: the
        # colours may differ in the last bit of a few pixels.
        assert np.abs(color.astype(int) - r.render_to_image("uint8")).max() <= 2
        assert (color != 255).any()  # the scene is in the picture, not only the background
        depth = o3d.io.read_image(tmp_path / f"depth_{i:03d}.png")
        assert depth.shape == (48, 64) and depth.dtype == np.uint16
        z = r.render_to_depth_image()
        assert np.abs(depth.astype(float) - np.round(z * 1000)).max() <= 2
        assert ((depth == 0) == (z == 0)).all()
