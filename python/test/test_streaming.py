"""Streaming a paged file from Python: renders converge to the image of the same splats added
as a cloud, the progress is reported, and what cannot stream raises."""
import time

import numpy as np
import pytest

import open3d_gs as o3d
Renderer = o3d.visualization.rendering.OffscreenRenderer


def distinct_depth_cloud(n, seed=1):
    """n splats in front of a camera at the origin looking along +z, at depths 0.001 apart:
    the depth order cannot depend on the pool slots a stream puts them in."""
    rng = np.random.default_rng(seed)
    xyz = np.column_stack([rng.uniform(-1, 1, (n, 2)), 3.0 + 0.001 * rng.permutation(n)])
    pcd = o3d.t.geometry.PointCloud(xyz.astype(np.float32))
    pcd.point["scale"] = np.full((n, 3), 0.05, np.float32)
    pcd.point["rot"] = np.tile(np.float32([1, 0, 0, 0]), (n, 1))
    pcd.point["opacity"] = np.zeros((n, 1), np.float32)
    pcd.point["f_dc"] = rng.uniform(-1, 1, (n, 3)).astype(np.float32)
    return pcd


def looking_along_z(r):
    r.setup_camera(o3d.camera.PinholeCamera(64, 64, 50.0, 50.0, 31.5, 31.5))


def render_until_settled(r, limit=20000):
    """Renders as a viewer does until the stream settles (1 ms apart); the last image and the
    renders it took."""
    for renders in range(1, limit + 1):
        image = r.render_to_image()
        if r.scene.stream_progress["settled"]:
            return image, renders
        time.sleep(0.001)
    raise AssertionError(f"the stream did not settle: {r.scene.stream_progress['text']}")


def test_stream_converges_to_the_clouds_image(tmp_path):
    pcd = distinct_depth_cloud(3000, seed=4)
    path = str(tmp_path / "cloud.gspages")
    o3d.t.io.write_splat_pages(path, pcd, page_capacity=64)
    r = Renderer(64, 64, "vulkan")
    looking_along_z(r)
    r.scene.stream_splats(path, gpu_budget="1M", reads_per_step=4)
    p = r.scene.stream_progress
    # 1 MiB holds more than the file: the pool gets a slot per page, no more.
    assert p["pool_pages"] == p["file_pages"] > 0 and not p["settled"]  # a slot per page
    image, renders = render_until_settled(r)
    assert renders >= 2  # the first render gives the worker its view
    p = r.scene.stream_progress
    assert p["pages_wanted"] == 0 and not p["starved"] and p["error"] == ""
    assert p["resident_pages"] <= p["file_pages"] and p["bytes_read"] > 0
    assert "complete" in p["text"]
    whole = Renderer(64, 64, "vulkan")
    whole.scene.add_geometry("cloud", pcd)
    looking_along_z(whole)
    np.testing.assert_array_equal(image, whole.render_to_image())
    assert r.scene.stop_streaming() and r.scene.stream_progress is None


def test_a_compact_stream_holds_more_and_draws_as_the_compact_cloud(tmp_path):
    pcd = distinct_depth_cloud(3000, seed=5)
    path = str(tmp_path / "cloud.gspages")
    o3d.t.io.write_splat_pages(path, pcd, page_capacity=64)
    # SH degree 0: 16 + 40 bytes a splat and its bit exact, 16 + 20 compact; 8 exact pages
    # of 64 splats are 28,736 bytes, which hold 12 compact ones (28,736 / (64 x 36.125)).
    budget = int(8 * 64 * 56.125)
    exact = Renderer(64, 64, "vulkan")
    exact.scene.stream_splats(path, gpu_budget=budget)
    assert exact.scene.stream_progress["pool_pages"] == 8
    r = Renderer(64, 64, "vulkan")
    r.compact_storage = True  # the stream follows the renderer's setting
    r.scene.stream_splats(path, gpu_budget=budget)
    assert r.scene.stream_progress["pool_pages"] == 12
    r.scene.stream_splats(path, gpu_budget="1M", compact_storage=True, reads_per_step=64)
    r.compact_storage = False  # the pool keeps its precision
    looking_along_z(r)
    image, _ = render_until_settled(r)
    whole = Renderer(64, 64, "vulkan", compact_storage=True)
    whole.scene.add_geometry("cloud", pcd)
    looking_along_z(whole)
    np.testing.assert_array_equal(image, whole.render_to_image())


def test_what_cannot_stream_raises(tmp_path):
    pcd = distinct_depth_cloud(300)
    path = str(tmp_path / "cloud.gspages")
    o3d.t.io.write_splat_pages(path, pcd, page_capacity=64)
    with pytest.raises(o3d.Open3DError, match="'cpu' splat backend cannot stream"):
        Renderer(64, 64, "cpu").scene.stream_splats(path)
    r = Renderer(64, 64, "vulkan")
    r.scene.add_geometry("cloud", pcd)
    with pytest.raises(o3d.Open3DError, match="remove them first"):
        r.scene.stream_splats(path)
    r.scene.clear_geometry()
    with pytest.raises(o3d.Open3DError, match="is not a size in bytes"):
        r.scene.stream_splats(path, gpu_budget="lots")
    for bad in (True, -1, 1.5, None, "0.5"):
        with pytest.raises(o3d.Open3DError, match="gpu_budget|not a size in bytes"):
            r.scene.stream_splats(path, gpu_budget=bad)
    r.scene.stream_splats(path, gpu_budget=1 << 20)
    with pytest.raises(o3d.Open3DError, match="StopStreaming first"):
        r.scene.add_geometry("cloud", pcd)
    looking_along_z(r)
    with pytest.raises(o3d.Open3DError, match="not while a stream runs"):
        r.render_batch([r.camera])
    r.scene.stream_splats(path, gpu_budget="auto")  # replaces the stream
    with pytest.raises(o3d.Open3DError, match="at least 8 nodes"):
        o3d.t.io.write_splat_pages(str(tmp_path / "bad.gspages"), pcd, page_capacity=4)
