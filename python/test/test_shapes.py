"""One shape rule for every colour array (float32 RGBA, uint8 RGB, alpha= for the other), the
background in every path, and cameras of another size refused unless rescale=True."""
import numpy as np
import pytest

import open3d_gs as o3d

Renderer = o3d.visualization.rendering.OffscreenRenderer


def patch_cloud():
    """A few splats in the middle of a camera's view at the origin: the corners stay empty."""
    g = np.linspace(-0.3, 0.3, 4)
    xy = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    pcd = o3d.t.geometry.PointCloud(np.concatenate([xy, np.full((len(xy), 1), 4.0)], 1))
    pcd.point["scale"] = np.full((len(xy), 3), 0.1)
    pcd.point["rot"] = np.tile([1.0, 0, 0, 0], (len(xy), 1))
    pcd.point["opacity"] = np.full(len(xy), 2.0)
    pcd.point["f_dc"] = np.tile([1.0, -0.5, 0.2], (len(xy), 1))
    return pcd


def camera(width=40, height=30):
    return o3d.camera.PinholeCamera(width, height, 40.0, 40.0, (width - 1) / 2, (height - 1) / 2)


@pytest.fixture
def renderer(backend):
    r = Renderer(40, 30, backend)
    r.scene.add_geometry("patch", patch_cloud())
    r.setup_camera(camera())
    return r


def test_one_rule_for_channels(renderer):
    r = renderer
    cams = [camera(), camera()]
    expected = {("float32", None): 4, ("uint8", None): 3, ("float32", False): 3, ("uint8", True): 4}
    for (dtype, alpha), channels in expected.items():
        single = r.render_to_image(dtype, alpha=alpha)
        batch = r.render_batch(cams, dtype, alpha=alpha)
        assert single.shape == (30, 40, channels) and single.dtype == np.dtype(dtype)
        assert batch.shape == (2, 30, 40, channels) and batch.dtype == np.dtype(dtype)
        if dtype == "float32":
            np.testing.assert_array_equal(batch[0], single)
        else:  # the device's rounding against round-to-nearest: within one level
            assert np.abs(batch[0].astype(int) - single).max() <= 1
    full = r.render_to_image()
    np.testing.assert_array_equal(r.render_to_image(alpha=False), full[..., :3])
    # An `out` says which it wants by its channels; a batch_array is RGBA (the device's).
    rgb = np.zeros((2, 30, 40, 3), np.uint8)
    assert r.render_batch(cams, "uint8", out=rgb) is rgb
    np.testing.assert_array_equal(rgb, r.render_batch(cams, "uint8"))
    fast = r.batch_array(2, "uint8")
    assert fast.shape == (2, 30, 40, 4)
    r.render_batch(cams, "uint8", out=fast)
    np.testing.assert_array_equal(fast[..., :3], rgb)
    with pytest.raises(o3d.Open3DError, match=r"shape \(2, 30, 40, 3\)"):
        r.render_batch(cams, "uint8", out=fast, alpha=False)


def test_background_in_every_path(renderer):
    r = renderer
    bg = np.array([0.2, 0.4, 0.6])
    r.scene.set_background(bg)
    corner = (0, 0)
    image = r.render_to_image()
    np.testing.assert_allclose(image[corner][:3], bg, atol=1e-6)
    assert image[corner][3] == 0  # alpha stays coverage: nothing there
    assert image[15, 20, 3] > 0.5  # the splats are there
    np.testing.assert_array_equal(r.render_to_image("uint8")[corner], np.round(bg * 255))
    batch = r.render_batch([camera()])
    np.testing.assert_array_equal(batch[0], image)
    assert np.abs(r.render_batch([camera()], "uint8")[0][corner].astype(int) - np.round(bg * 255)).max() <= 1
    assert np.abs(r.render_batch([camera()], "uint8", alpha=True)[0][corner][:3].astype(int)
                  - np.round(bg * 255)).max() <= 1
    doc = Renderer.render_to_image.__doc__
    assert "background" in doc and "over a black background;" not in doc


def test_other_sizes_are_refused_unless_rescaled(renderer):
    r = renderer
    big = camera().resized(80, 60)  # the same view at twice the size
    with pytest.raises(o3d.Open3DError, match=r"setup_camera: the camera is 80x60, the renderer's picture 40x30: "
                                              r"pass rescale=True"):
        r.setup_camera(big)
    with pytest.raises(o3d.Open3DError, match=r"render_batch: camera 1 is 80x60.*rescale=True"):
        r.render_batch([camera(), big])
    r.setup_camera(big, rescale=True)
    assert (r.camera.width, r.camera.height) == (40, 30)
    scaled = r.render_to_image()
    np.testing.assert_array_equal(r.render_batch([big], rescale=True)[0], scaled)
    r.setup_camera(camera())  # scaled back, it is the renderer's own camera again
    np.testing.assert_array_equal(scaled, r.render_to_image())
