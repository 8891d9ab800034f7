"""Meshes from Python: the Filament path of OffscreenRenderer (needs an X server: Xvfb under
ctest), its depth against analytic values, and the errors that say where meshes can go."""
import os
import subprocess
import sys

import numpy as np
import pytest

import open3d_gs as o3d

Renderer = o3d.visualization.rendering.OffscreenRenderer


def wall(n=20):
    """A wall of blue splats at z = 4, across x, y in [-2, 2]."""
    g = np.linspace(-2, 2, n, dtype=np.float32)
    xy = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    pcd = o3d.t.geometry.PointCloud(np.concatenate([xy, np.full((len(xy), 1), 4, np.float32)], 1))
    pcd.point["scale"] = np.tile(np.float32([0.15, 0.15, 0.01]), (len(xy), 1))
    pcd.point["rot"] = np.tile(np.float32([1, 0, 0, 0]), (len(xy), 1))
    pcd.point["opacity"] = np.full((len(xy), 1), 3.0, np.float32)
    blue = (np.float32([0.1, 0.2, 0.9]) - 0.5) / 0.28209479  # f_dc of that colour
    pcd.point["f_dc"] = np.tile(blue, (len(xy), 1))
    return pcd


def test_a_mesh_in_front_of_splats(display, backend):
    r = Renderer(160, 120, backend, meshes=True)
    assert r.meshes
    r.scene.add_geometry("wall", wall())
    sphere = o3d.t.geometry.TriangleMesh.create_sphere(0.5, 40)
    sphere.translate([0, 0, 2])
    red = o3d.visualization.rendering.MaterialRecord()
    red.base_color = [1, 0, 0, 1]  # defaultUnlit: exactly this colour
    r.scene.add_geometry("sphere", sphere, red)
    # The camera at the origin looking along +z (y down), 60 degrees tall.
    fy = 60 / np.tan(np.radians(30))
    r.setup_camera(o3d.camera.PinholeCamera(160, 120, fy, fy, 79.5, 59.5))
    image = r.render_to_image()
    assert image.shape == (120, 160, 3) and image.dtype == np.uint8
    centre = image[60, 80]
    assert centre[0] > 200 and centre[1] < 10 and centre[2] < 10, centre  # the sphere hides the wall
    beside = image[60, 40].astype(int)  # world x = (40 - 79.5) / fy * 4 = -1.5: on the wall
    assert beside[2] > beside[0] + 50, beside  # the blue wall around the sphere
    depth = r.render_to_depth_image()
    assert depth.shape == (120, 160)
    # The sphere's front at the centre pixel is 2 - 0.5 = 1.5 away; the 40-step tessellation
    # puts it within 0.01 (chord sagitta 0.5 (1 - cos(pi / 40)) = 0.0015). The wall: z = 4
    # in the splats' expected depth.
    assert abs(depth[60, 80] - 1.5) < 0.01, depth[60, 80]
    assert abs(depth[60, 40] - 4.0) < 0.05, depth[60, 40]
    with pytest.raises(o3d.Open3DError, match="8-bit"):
        r.render_to_image("float32")
    with pytest.raises(o3d.Open3DError, match="8-bit RGB"):
        r.render_to_image(alpha=True)
    with pytest.raises(o3d.Open3DError, match="splat-only"):
        r.render_batch([r.camera])
    # Open3D's depth conventions with meshes too: the sphere's 1.5 in view space, and the
    # normalised 1 - near / z.
    assert abs(r.render_to_depth_image(z_in_view_space=True)[60, 80] - 1.5) < 0.01
    assert abs(r.render_to_depth_image(False)[60, 80] - (1 - r.near_plane / 1.5)) < 0.01


def test_the_background_with_meshes(display, backend):
    r = Renderer(64, 48, backend, meshes=True)
    patch = wall(4)
    patch.point.positions[:, :2] *= 0.2  # 16 splats within 0.4 of the axis: the corners are empty
    r.scene.add_geometry("wall", patch)
    r.scene.set_background([0.2, 0.4, 0.6])
    fy = 24 / np.tan(np.radians(30))
    r.setup_camera(o3d.camera.PinholeCamera(64, 48, fy, fy, 31.5, 23.5))
    corner = r.render_to_image()[0, 0].astype(int)
    # Filament's 8-bit target: within a level of round(background * 255).
    assert np.abs(corner - np.round(np.array([0.2, 0.4, 0.6]) * 255)).max() <= 1, corner


def test_meshes_need_meshes_true():
    r = Renderer(16, 16, "cpu")
    with pytest.raises(o3d.Open3DError, match="meshes=True"):
        r.scene.add_geometry("box", o3d.t.geometry.TriangleMesh.create_box())
    points = o3d.visualization.rendering.MaterialRecord()
    points.shader = "defaultUnlit"
    with pytest.raises(o3d.Open3DError, match="draws Gaussian splat clouds only; set material.shader = 'gaussianSplat'"):
        r.scene.add_geometry("points", wall(), points)


def test_without_a_display_the_error_says_so():
    # GLX asked for without an X server: the error names both ways out.
    env = {k: v for k, v in os.environ.items() if k != "DISPLAY"}
    env["OPEN3D_FILAMENT_PLATFORM"] = "glx"
    code = ("import open3d_gs as o3d\n"
            "try:\n    o3d.visualization.rendering.OffscreenRenderer(8, 8, 'cpu', meshes=True)\n"
            "except o3d.Open3DError as e:\n    print(e)\n")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert "needs an X server" in out.stdout and "xvfb-run" in out.stdout, out.stdout + out.stderr


def test_without_a_display_meshes_draw_headless_on_egl():
    # No DISPLAY: Filament runs on EGL. test_a_mesh_in_front_of_splats's scene and checks in a
    # process without an X server.
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "OPEN3D_FILAMENT_PLATFORM")}
    env["PYTHONPATH"] = os.pathsep.join(sys.path)
    code = (f"import sys; sys.path.insert(0, {os.path.dirname(__file__)!r})\n"
            "import numpy as np, open3d_gs as o3d, test_meshes as t\n"
            "r = o3d.visualization.rendering.OffscreenRenderer(160, 120, 'cpu', meshes=True)\n"
            "r.scene.add_geometry('wall', t.wall())\n"
            "sphere = o3d.t.geometry.TriangleMesh.create_sphere(0.5, 40)\n"
            "sphere.translate([0, 0, 2])\n"
            "red = o3d.visualization.rendering.MaterialRecord()\n"
            "red.base_color = [1, 0, 0, 1]\n"
            "r.scene.add_geometry('sphere', sphere, red)\n"
            "fy = 60 / np.tan(np.radians(30))\n"
            "r.setup_camera(o3d.camera.PinholeCamera(160, 120, fy, fy, 79.5, 59.5))\n"
            "image = r.render_to_image().astype(int)\n"
            "depth = r.render_to_depth_image()\n"
            "print('centre', *image[60, 80], 'beside', *image[60, 40], 'depth', depth[60, 80])\n")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    words = out.stdout.split()
    centre = [int(v) for v in words[words.index("centre") + 1:][:3]]
    beside = [int(v) for v in words[words.index("beside") + 1:][:3]]
    depth = float(words[words.index("depth") + 1])
    assert centre[0] > 200 and centre[1] < 10 and centre[2] < 10, out.stdout  # the sphere
    assert beside[2] > beside[0] + 50, out.stdout  # the blue wall around it
    assert abs(depth - 1.5) < 0.01, out.stdout  # as test_a_mesh_in_front_of_splats


def test_mesh_arrays():
    mesh = o3d.t.geometry.TriangleMesh(np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]))
    assert mesh.num_vertices() == 3 and mesh.num_triangles() == 1
    np.testing.assert_array_equal(mesh.vertices[1], [1, 0, 0])
    with pytest.raises(o3d.Open3DError):
        o3d.t.geometry.TriangleMesh(np.float32([[0, 0, 0]]), np.array([[0, 1, 2]]))  # index 2 of 1 vertex
    with pytest.raises(o3d.Open3DError, match=r"\(M, 3\)"):
        o3d.t.geometry.TriangleMesh(np.float32([[0, 0, 0]]), np.array([0, 0, 0]))
