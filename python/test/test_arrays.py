"""Arrays the way researchers have them: float64 and float16 arrays and plain lists become
float32, opacity (N,) is taken as (N, 1), and NaN or infinity is refused naming the
attribute and the row (with an explicit opt-out)."""
import numpy as np
import pytest

import open3d_gs as o3d

PointCloud = o3d.t.geometry.PointCloud


@pytest.mark.parametrize("dtype", [np.float64, np.float16, np.int64, np.int32])
def test_other_dtypes_become_float32(dtype):
    values = np.arange(12).reshape(4, 3).astype(dtype) / (2 if np.dtype(dtype).kind == "f" else 1)
    pcd = PointCloud(values)
    assert pcd.point.positions.dtype == np.float32
    np.testing.assert_array_equal(pcd.point.positions, values.astype(np.float32))
    pcd.point["scale"] = values
    assert pcd.point.scale.dtype == np.float32
    np.testing.assert_array_equal(pcd.point.scale, values.astype(np.float32))


def test_lists_become_float32():
    pcd = PointCloud([[0, 0, 1], [0.5, 2, 3]])
    assert pcd.point.positions.dtype == np.float32
    assert pcd.point.positions.tolist() == [[0, 0, 1], [0.5, 2, 3]]
    pcd.point.f_dc = [[1, 2, 3], [4, 5, 6]]  # Open3D's TensorMap attribute assignment
    assert pcd.point.f_dc.dtype == np.float32 and pcd.point.f_dc[1, 2] == 6
    # The dict form of Open3D's constructor.
    same = PointCloud({"positions": [[0, 0, 1], [0.5, 2, 3]], "opacity": [0.5, -1.0]})
    assert same.point.opacity.shape == (2, 1)


def test_uint8_and_uint16_stay_as_they_are():
    pcd = PointCloud(np.zeros((3, 3), np.float32))
    pcd.point["labels"] = np.array([1, 2, 3], np.uint8)
    pcd.point["ids"] = np.array([1, 2, 70000 % 65536], np.uint16)
    assert pcd.point.labels.dtype == np.uint8 and pcd.point.ids.dtype == np.uint16


def test_opacity_of_shape_n_is_taken_as_n_by_1():
    pcd = PointCloud(np.zeros((5, 3), np.float32))
    pcd.point["opacity"] = np.linspace(-1, 1, 5)  # float64 (N,): converted and reshaped
    assert pcd.point.opacity.shape == (5, 1) and pcd.point.opacity.dtype == np.float32
    np.testing.assert_array_equal(pcd.point.opacity[:, 0], np.linspace(-1, 1, 5).astype(np.float32))
    # Only opacity: another (N,) attribute keeps its shape.
    pcd.point["weight"] = np.ones(5)
    assert pcd.point.weight.shape == (5,)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_values_are_refused_naming_attribute_and_row(bad):
    pcd = PointCloud(np.zeros((6, 3), np.float32))
    scale = np.ones((6, 3), np.float32)
    scale[4, 1] = bad
    with pytest.raises(o3d.Open3DError, match=r"attribute 'scale': row 4 holds"):
        pcd.point["scale"] = scale
    assert "scale" not in pcd.point  # nothing was set
    positions = np.zeros((3, 3))
    positions[2, 0] = bad
    with pytest.raises(o3d.Open3DError, match=r"attribute 'positions': row 2 holds"):
        PointCloud(positions)
    # The opt-out keeps them, as read_point_cloud(drop_non_finite=...) is explicit too.
    pcd.set_point_attr("scale", scale, allow_non_finite=True)
    assert np.isnan(pcd.point.scale[4, 1]) or np.isinf(pcd.point.scale[4, 1])


def test_float64_beyond_float32_is_named_not_made_infinite():
    values = np.zeros((3, 3))
    values[1, 2] = 1e39
    with pytest.raises(o3d.Open3DError, match=r"attribute 'positions': row 1 holds 1e\+39, beyond float32"):
        PointCloud(values)


def test_unsupported_dtypes_name_the_attribute():
    pcd = PointCloud(np.zeros((2, 3), np.float32))
    with pytest.raises(o3d.Open3DError, match="attribute 'flags': dtype bool is not supported"):
        pcd.point["flags"] = np.array([True, False])
    with pytest.raises(o3d.Open3DError, match="attribute 'x': not an array"):
        pcd.point["x"] = [[1, 2], [3]]
    with pytest.raises(o3d.Open3DError, match="above 2.24"):
        pcd.point["big"] = np.array([2**40 + 1, 1], np.int64)
