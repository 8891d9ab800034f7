"""Editing a splat cloud (docs/editing.md): crop by an axis-aligned or oriented box, remove rows;
every attribute of the kept splats is the source's bit for bit, and the boxes refuse what is not
a box."""
import numpy as np
import pytest

import open3d_gs as o3d

geometry = o3d.t.geometry


def test_crop_by_an_axis_aligned_box_keeps_the_splats_inside(playbot):
    pcd, _ = playbot
    lo, hi = pcd.get_min_bound(), pcd.get_max_bound()
    box = geometry.AxisAlignedBoundingBox(lo + 0.25 * (hi - lo), hi - 0.25 * (hi - lo))
    p = pcd.point.positions.astype(np.float64)  # the box test runs in float64
    inside = np.all((p >= box.min_bound) & (p <= box.max_bound), axis=1)
    assert 0 < inside.sum() < len(pcd)
    cropped = pcd.crop(box)
    for name in pcd.point:
        np.testing.assert_array_equal(cropped.point[name], pcd.point[name][inside], err_msg=name)
    assert len(pcd.crop(box, invert=True)) == len(pcd) - inside.sum()
    assert len(pcd.crop(pcd.get_axis_aligned_bounding_box())) == len(pcd)


def test_crop_by_an_oriented_box_tests_in_the_box_frame(playbot):
    pcd, _ = playbot
    a = np.radians(30)
    R = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    center = pcd.get_center()
    extent = 0.5 * (pcd.get_max_bound() - pcd.get_min_bound())
    box = geometry.OrientedBoundingBox(center, R, extent)
    local = (pcd.point.positions.astype(np.float64) - center) @ R  # R^T (p - c), row-wise
    inside = np.all(np.abs(local) <= extent / 2, axis=1)
    assert 0 < inside.sum() < len(pcd)
    cropped = pcd.crop(box)
    for name in pcd.point:
        np.testing.assert_array_equal(cropped.point[name], pcd.point[name][inside], err_msg=name)
    np.testing.assert_array_equal(box.R, R)
    assert box.contains(center)


def test_remove_by_index_is_select_by_index_inverted(playbot):
    pcd, _ = playbot
    removed = pcd.remove_by_index([0, 10, 10, len(pcd) - 1])
    assert len(removed) == len(pcd) - 3
    np.testing.assert_array_equal(removed.point.f_dc,
                                  pcd.select_by_index([0, 10, len(pcd) - 1], invert=True).point.f_dc)
    with pytest.raises(o3d.Open3DError, match="out of range"):
        pcd.remove_by_index([len(pcd)])


def test_boxes_refuse_what_is_not_a_box():
    with pytest.raises(o3d.Open3DError, match="min_bound 1 exceeds max_bound 0 on axis y"):
        geometry.AxisAlignedBoundingBox([0, 1, 0], [1, 0, 1])
    box = geometry.AxisAlignedBoundingBox([0, 0, 0], [1, 1, 1])
    with pytest.raises(o3d.Open3DError, match="exceeds max_bound"):
        box.min_bound = [2, 0, 0]  # a setter builds a checked box too
    np.testing.assert_array_equal(box.min_bound, [0, 0, 0])  # unchanged
    with pytest.raises(o3d.Open3DError, match="not a rotation"):
        geometry.OrientedBoundingBox([0, 0, 0], np.diag([1.0, 1.0, -1.0]), [1, 1, 1])
    with pytest.raises(o3d.Open3DError, match="negative edge"):
        geometry.OrientedBoundingBox([0, 0, 0], np.eye(3), [1, -1, 1])
    obb = geometry.OrientedBoundingBox.create_from_axis_aligned_bounding_box(box)
    np.testing.assert_array_equal(obb.extent, [1, 1, 1])
    assert obb.contains([1, 1, 1]) and not obb.contains([1, 1, 1.001])


def test_select_in_view_takes_the_centres_inside_the_polygon(playbot):
    pcd, views = playbot
    camera = views[0].camera.resized(96, 96)
    rect = [(20, 20), (70, 20), (70, 60), (20, 60)]
    everything = pcd.select_in_view(camera, rect, include_occluded=True)
    # The centres projected here in float64 (OpenCV axes, pixel centres on integers), the
    # splats in front of the near plane (0.2) and inside the closed rectangle.
    p = pcd.point.positions.astype(np.float64)
    cam = (camera.world_to_camera[:3, :3] @ p.T).T + camera.world_to_camera[:3, 3]
    z = cam[:, 2]
    front = z > 0.2
    x = camera.fx * cam[:, 0] / np.where(front, z, 1) + camera.cx
    y = camera.fy * cam[:, 1] / np.where(front, z, 1) + camera.cy
    inside = front & (x >= 20) & (x <= 70) & (y >= 20) & (y <= 60)
    # The renderer also culls splats whose footprint misses every tile; a centre inside the
    # image always has one, so the two sets agree but for centres within rounding of an edge.
    want = set(np.flatnonzero(inside))
    assert len(want.symmetric_difference(set(everything))) <= 3, len(want)
    shown = pcd.select_in_view(camera, rect)
    assert set(shown) <= set(everything) and 0 < len(shown) < len(everything)
    edited = pcd.remove_by_index(shown)
    assert len(edited) == len(pcd) - len(shown)


def test_pick_gives_the_dominant_splat_and_the_point_at_the_depth(playbot):
    pcd, views = playbot
    camera = views[0].camera.resized(64, 64)
    r = o3d.visualization.rendering.OffscreenRenderer(64, 64, "cpu")
    r.scene.add_geometry("scene", pcd)
    r.setup_camera(camera)
    depth = r.render_to_depth_image()
    alpha = r.render_to_image()[..., 3]
    hits = 0
    for x, y in [(32, 32), (20, 40), (45, 25), (0, 0)]:
        pick = pcd.pick(camera, x, y)
        assert pick["hit"] == (alpha[y, x] > 0)
        if not pick["hit"]:
            continue
        hits += 1
        assert np.float32(pick["expected_depth"]) == depth[y, x]
        assert pick["alpha"] == pytest.approx(alpha[y, x], abs=1e-6)
        assert 0 <= pick["splat"] < len(pcd) and 0 < pick["weight"] <= pick["alpha"]
        view = camera.world_to_camera[:3, :3] @ pick["point"] + camera.world_to_camera[:3, 3]
        assert view[2] == pytest.approx(pick["expected_depth"], rel=1e-12)
        assert camera.fx * view[0] / view[2] + camera.cx == pytest.approx(x, abs=1e-9)
    assert hits >= 3


@pytest.mark.parametrize("backend", ["cpu", "vulkan"])
def test_the_id_image_names_each_pixels_pick_and_its_geometry(playbot, backend):
    pcd, views = playbot
    camera = views[0].camera.resized(48, 40)
    r = o3d.visualization.rendering.OffscreenRenderer(48, 40, backend)
    # Two geometries: IDs run through them in name order ("a" first, then "b").
    half = len(pcd) // 2
    a, b = pcd.select_by_index(range(half)), pcd.select_by_index(range(half, len(pcd)))
    r.scene.add_geometry("b", b)
    r.scene.add_geometry("a", a)
    r.setup_camera(camera)
    ids = r.render_to_id_image()
    assert ids.dtype == np.int32 and ids.shape == (40, 48)
    alpha = r.render_to_image()[..., 3]
    np.testing.assert_array_equal(ids >= 0, alpha > 0)
    # The pick of the whole cloud, at pixels spread over the image: the same splat (the
    # shared scenes' views agree on every pixel, docs/editing.md "ID images").
    checked = 0
    for y in range(0, 40, 7):
        for x in range(0, 48, 7):
            pick = pcd.pick(camera, x, y)
            assert ids[y, x] == (pick["splat"] if pick["hit"] else -1), (x, y)
            if ids[y, x] >= 0:
                name, index = r.locate_splat(int(ids[y, x]))
                assert (name, index) == (("a", pick["splat"]) if pick["splat"] < half
                                         else ("b", pick["splat"] - half))
                checked += 1
    assert checked >= 10
    assert r.locate_splat(-1) is None
