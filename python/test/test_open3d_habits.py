"""Open3D's habits around rendering: image files, PinholeCameraIntrinsic,
setup_camera(K, extrinsic, width, height), depth with z_in_view_space, draw's dict items,
MaterialRecord()'s default."""
import numpy as np
import pytest

import open3d_gs as o3d

Renderer = o3d.visualization.rendering.OffscreenRenderer


def test_image_files(tmp_path):
    rng = np.random.default_rng(0)
    for shape in [(5, 7, 3), (5, 7, 4), (5, 7), (5, 7, 2)]:
        image = rng.integers(0, 256, shape, dtype=np.uint8)
        path = tmp_path / f"image_{len(shape)}_{shape[-1]}.png"
        assert o3d.io.write_image(str(path), image)
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        np.testing.assert_array_equal(o3d.io.read_image(str(path)), image)
        np.testing.assert_array_equal(o3d.t.io.read_image(str(path)), image)
    depth_mm = rng.integers(0, 65536, (4, 6), dtype=np.uint16)  # 16-bit grey, Open3D's depth PNG
    o3d.io.write_image(tmp_path / "depth.png", depth_mm)
    back = o3d.io.read_image(tmp_path / "depth.png")
    assert back.dtype == np.uint16
    np.testing.assert_array_equal(back, depth_mm)
    # A float render: the 8-bit colour rounded to nearest; the alpha is not written.
    render = rng.uniform(0, 1, (3, 4, 4)).astype(np.float32)
    o3d.io.write_image(tmp_path / "render.png", render)
    np.testing.assert_array_equal(o3d.io.read_image(tmp_path / "render.png"),
                                  np.round(render[..., :3] * 255).astype(np.uint8))
    with pytest.raises(o3d.Open3DError, match=r"\.jpg"):
        o3d.io.write_image(tmp_path / "x.jpg", render)


def test_pinhole_camera_intrinsic_and_setup_camera(playbot, backend):
    pcd, views = playbot
    camera = views[0].camera.resized(80, 60)
    K = camera.intrinsic_matrix
    intrinsic = o3d.camera.PinholeCameraIntrinsic(80, 60, K[0, 0], K[1, 1], K[0, 2], K[1, 2])
    assert (intrinsic.width, intrinsic.height) == (80, 60)
    np.testing.assert_array_equal(intrinsic.intrinsic_matrix, K)
    assert intrinsic.get_focal_length() == (K[0, 0], K[1, 1])
    assert intrinsic.get_principal_point() == (K[0, 2], K[1, 2])
    r = Renderer(80, 60, backend)
    r.scene.add_geometry("playbot", pcd)
    r.setup_camera(camera)
    expected = r.render_to_image()
    E = camera.world_to_camera
    r.setup_camera(K, E, 80, 60)  # Open3D's (intrinsic_matrix, extrinsic, width, height)
    np.testing.assert_array_equal(r.render_to_image(), expected)
    r.setup_camera(intrinsic, E)  # Open3D's (PinholeCameraIntrinsic, extrinsic)
    np.testing.assert_array_equal(r.render_to_image(), expected)
    r.setup_camera(o3d.camera.PinholeCameraIntrinsic(80, 60, K), E)
    np.testing.assert_array_equal(r.render_to_image(), expected)
    # Another size is a different picture: refused unless asked to rescale.
    K2 = camera.resized(160, 120).intrinsic_matrix
    with pytest.raises(o3d.Open3DError, match=r"160x120, the renderer's picture 80x60: pass rescale=True"):
        r.setup_camera(K2, E, 160, 120)
    r.setup_camera(K2, E, 160, 120, rescale=True)
    np.testing.assert_allclose(r.camera.intrinsic_matrix, K, rtol=1e-12)


def test_depth_z_in_view_space(playbot, backend):
    pcd, views = playbot
    r = Renderer(64, 64, backend, near_plane=0.2)
    r.scene.add_geometry("playbot", pcd)
    r.setup_camera(views[0].camera, rescale=True)
    z = r.render_to_depth_image()  # unchanged default: view z, 0 where nothing is
    empty = z == 0
    assert empty.any() and (~empty).any()
    view = r.render_to_depth_image(z_in_view_space=True)  # Open3D: view z, inf where nothing
    np.testing.assert_array_equal(view[~empty], z[~empty])
    assert np.isinf(view[empty]).all()
    np.testing.assert_array_equal(r.render_to_depth_image(True), view)  # positional, as Open3D
    normalised = r.render_to_depth_image(z_in_view_space=False)  # Open3D: 0 near .. 1 far
    assert normalised.dtype == np.float32 and normalised.min() >= 0 and normalised.max() <= 1
    assert (normalised[empty] == 1).all()
    np.testing.assert_allclose(normalised[~empty], np.clip(1 - np.float32(0.2) / z[~empty], 0, 1), rtol=0, atol=1e-6)
    median = r.render_to_depth_image("median", z_in_view_space=True)
    assert np.isinf(median).any() and np.isfinite(median).any()


def test_draw_takes_open3d_dict_items(tmp_path):
    # The items are read before the window opens, so the errors need no display.
    with pytest.raises(FileNotFoundError, match="missing.gspages"):
        o3d.visualization.draw([{"name": "stream", "geometry": tmp_path / "missing.gspages"}])
    with pytest.raises(o3d.Open3DError, match=r"item 0: unknown key 'colour'.*name, geometry"):
        o3d.visualization.draw([{"name": "a", "geometry": o3d.t.geometry.PointCloud(), "colour": 1}])
    with pytest.raises(o3d.Open3DError, match="item 1: a dict item needs 'geometry'"):
        o3d.visualization.draw([o3d.t.geometry.PointCloud(), {"name": "a"}])


def test_draw_opens_the_viewer_with_dict_items(playbot, display):
    pcd, _ = playbot
    sphere = o3d.t.geometry.TriangleMesh.create_sphere(0.2)
    material = o3d.visualization.rendering.MaterialRecord()  # unset: the cloud as splats
    # Runs the viewer for half a second and returns: the items were taken.
    o3d.visualization.draw([{"name": "playbot", "geometry": pcd, "material": material, "is_visible": True},
                            ("sphere", sphere)], title="habits", width=160, height=120, max_seconds=0.5)


def test_material_record_default_draws_splats(playbot):
    pcd, views = playbot
    r = Renderer(32, 32, "cpu")
    material = o3d.visualization.rendering.MaterialRecord()
    assert material.shader == "defaultUnlit"  # Open3D's default, as read
    r.scene.add_geometry("default", pcd, material)  # not set: the cloud's own way, splats
    r.setup_camera(views[0].camera, rescale=True)
    assert r.render_to_image()[..., 3].max() > 0.5
    material.shader = "defaultUnlit"  # asked for: points, which need Filament
    with pytest.raises(o3d.Open3DError, match=r"material.shader = 'gaussianSplat'.*meshes=True"):
        r.scene.add_geometry("points", pcd, material)
    material.shader = "gaussianSplat"
    r.scene.add_geometry("splats", pcd, material)
