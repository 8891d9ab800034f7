"""Open3D's PointCloud habits on splat clouds: transform (rigid and uniform scale, the
Gaussian attributes following), select_by_index / select_by_mask, +, bounds, rotate about the
centre."""
import numpy as np
import pytest

import open3d_gs as o3d

Renderer = o3d.visualization.rendering.OffscreenRenderer
GAUSSIAN = ("positions", "scale", "rot", "opacity", "f_dc", "f_rest")


def rotation(axis, degrees):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    a = np.radians(degrees)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * k @ k


def covariances(pcd):
    """Sigma = R_q S^2 R_q^T per splat, from rot (w, x, y, z) and the linear scales."""
    w, x, y, z = pcd.point.rot.astype(np.float64).T
    R = np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1)], 1)
    S2 = pcd.point.scale.astype(np.float64) ** 2
    return np.einsum("nij,nj,nkj->nik", R, S2, R)


def test_transform_rigid_and_uniform_scale(playbot):
    pcd, _ = playbot
    R, s, t = rotation([1, 2, 3], 40), -1.5, np.array([0.3, -2.0, 1.0])
    M = np.eye(4)
    M[:3, :3], M[:3, 3] = s * R, t
    moved = pcd.clone().transform(M)
    # Positions: A p + t; covariances: s^2 R Sigma R^T (computed here, not by the library).
    np.testing.assert_allclose(moved.point.positions, pcd.point.positions @ (s * R).T + t, atol=2e-6)
    expected = s * s * np.einsum("ij,njk,lk->nil", R, covariances(pcd), R)
    np.testing.assert_allclose(covariances(moved), expected, rtol=0, atol=2e-6 * np.abs(expected).max())
    # The same as the three steps it stands for (the SH rotation and parity included), but
    # for the rounding of R = A / s and the positions' one rounding instead of three.
    steps = pcd.clone().scale(s, [0, 0, 0]).rotate(R, [0, 0, 0]).translate(t)
    for name in GAUSSIAN:
        np.testing.assert_allclose(moved.point[name], steps.point[name], rtol=0, atol=2e-6, err_msg=name)
    assert np.abs(moved.point.f_rest - pcd.point.f_rest).max() > 0.01  # the SH did turn


def test_transform_keeps_the_picture(playbot, backend):
    """Moving the scene by M = [s R | t] and the camera with it renders the same image."""
    pcd, views = playbot
    camera = views[0].camera.resized(64, 64)
    R, s, t = rotation([0, 1, 1], 25), 2.0, np.array([1.0, 0.5, -3.0])
    M = np.eye(4)
    M[:3, :3], M[:3, 3] = s * R, t
    E = camera.world_to_camera
    moved_extrinsic = np.eye(4)  # c' = s c for p' = M p
    moved_extrinsic[:3, :3] = E[:3, :3] @ R.T
    moved_extrinsic[:3, 3] = s * E[:3, 3] - E[:3, :3] @ R.T @ t
    images = []
    for cloud, extrinsic in ((pcd, E), (pcd.clone().transform(M), moved_extrinsic)):
        r = Renderer(64, 64, backend)
        r.scene.add_geometry("playbot", cloud)
        r.setup_camera(camera.intrinsic_matrix, extrinsic)
        images.append(r.render_to_image())
    assert images[0][..., 3].max() > 0.5
    np.testing.assert_allclose(images[1], images[0], rtol=0, atol=2e-3)


def test_transform_refuses_shear_for_splats_not_for_points(playbot):
    pcd, _ = playbot
    shear = np.eye(4)
    shear[0, 1] = 0.2
    before = pcd.point.positions.copy()
    with pytest.raises(o3d.Open3DError, match="shears or scales unevenly"):
        pcd.transform(shear)
    np.testing.assert_array_equal(pcd.point.positions, before)  # unchanged
    with pytest.raises(o3d.Open3DError, match="shears or scales unevenly"):
        pcd.clone().transform(np.diag([1.0, 2.0, 1.0, 1.0]))
    with pytest.raises(o3d.Open3DError, match="last row"):
        pcd.clone().transform(np.ones((4, 4)))
    points = o3d.t.geometry.PointCloud(before)
    points.transform(shear)
    np.testing.assert_allclose(points.point.positions, before @ shear[:3, :3].T, atol=1e-6)


def test_select_by_index_and_mask(playbot):
    pcd, _ = playbot
    indices = np.array([5, 3, 30999, 3])
    picked = pcd.select_by_index(indices)
    assert len(picked) == 4 and picked.get_sh_degree() == 2
    for name in GAUSSIAN:
        np.testing.assert_array_equal(picked.point[name], pcd.point[name][indices], err_msg=name)
    rest = pcd.select_by_index([0, 2, 4], invert=True)
    keep = np.ones(len(pcd), bool)
    keep[[0, 2, 4]] = False
    assert len(rest) == len(pcd) - 3
    np.testing.assert_array_equal(rest.point.f_rest, pcd.point.f_rest[keep])
    mask = pcd.point.positions[:, 1] > 0
    np.testing.assert_array_equal(pcd.select_by_mask(mask).point.positions, pcd.point.positions[mask])
    np.testing.assert_array_equal(pcd.select_by_mask(mask, invert=True).point.opacity, pcd.point.opacity[~mask])
    with pytest.raises(o3d.Open3DError, match="index 31000 is out of range for 31000 points"):
        pcd.select_by_index([31000])
    with pytest.raises(o3d.Open3DError, match="index -1 is out of range"):
        pcd.select_by_index([-1])
    with pytest.raises(o3d.Open3DError, match="1-D bool array of 31000 entries"):
        pcd.select_by_mask(mask[:10])


def test_plus_merges_sh_degrees(playbot):
    pcd, _ = playbot
    a = pcd.select_by_index(np.arange(10))  # SH degree 2
    b = pcd.select_by_index(np.arange(10, 15))
    del b.point["f_rest"]  # degree 0
    both = a + b
    assert len(both) == 15 and both.get_sh_degree() == 2
    np.testing.assert_array_equal(both.point.positions, pcd.point.positions[:15])
    np.testing.assert_array_equal(both.point.f_rest[:10], a.point.f_rest)
    assert (both.point.f_rest[10:] == 0).all()  # the bands b lacks add nothing
    assert len(a.append(a)) == 20
    assert len(o3d.t.geometry.PointCloud() + a) == 10
    with pytest.raises(o3d.Open3DError, match="attribute '.*' is in one cloud only"):
        a + o3d.t.geometry.PointCloud(np.zeros((2, 3)))


def test_bounds_and_center(playbot):
    pcd, _ = playbot
    p = pcd.point.positions
    np.testing.assert_array_equal(pcd.get_min_bound(), p.min(0))
    np.testing.assert_array_equal(pcd.get_max_bound(), p.max(0))
    np.testing.assert_allclose(pcd.get_center(), p.astype(np.float64).mean(0), rtol=1e-12)
    box = pcd.get_axis_aligned_bounding_box()
    np.testing.assert_array_equal(box.min_bound, p.min(0))
    np.testing.assert_array_equal(box.max_bound, p.max(0))
    np.testing.assert_allclose(box.get_extent(), p.max(0) - p.min(0))
    assert o3d.t.geometry.PointCloud().get_min_bound().tolist() == [0, 0, 0]


def test_rotate_defaults_to_the_center(playbot):
    # Open3D's Geometry3D.rotate(R) turns about get_center(); t.geometry's needs a centre.
    pcd, _ = playbot
    R = rotation([0, 0, 1], 30)
    a = pcd.clone().rotate(R)
    b = pcd.clone().rotate(R, pcd.get_center())
    for name in GAUSSIAN:
        np.testing.assert_array_equal(a.point[name], b.point[name], err_msg=name)
    np.testing.assert_allclose(a.get_center(), pcd.get_center(), atol=1e-5)
