"""PointCloud attributes from Python: equal to an independent parse of the PLY, numpy views
that write through, copies in, round trips through the writers, and the C++ errors."""
import re

import numpy as np
import pytest

import open3d_gs as o3d


def parse_ply(path):
    """A binary little-endian 3DGS PLY read with numpy alone (not the library's reader)."""
    raw = path.read_bytes()
    end = raw.index(b"end_header\n") + len(b"end_header\n")
    header = raw[:end].decode().splitlines()
    count = int(next(l for l in header if l.startswith("element vertex")).split()[2])
    names = [l.split()[2] for l in header if l.startswith("property float")]
    table = np.frombuffer(raw, dtype=[(n, "<f4") for n in names], count=count, offset=end)
    return {n: table[n] for n in names}, count


def test_attributes_equal_an_independent_parse(data):
    path = data("playbot/playbot_31k.ply")
    cols, count = parse_ply(path)
    pcd = o3d.t.io.read_point_cloud(str(path))
    assert len(pcd) == count == 31000
    assert pcd.is_gaussian_splat() and pcd.get_sh_degree() == 2
    np.testing.assert_array_equal(pcd.point.positions, np.stack([cols["x"], cols["y"], cols["z"]], 1))
    np.testing.assert_array_equal(pcd.point["opacity"][:, 0], cols["opacity"])
    np.testing.assert_array_equal(pcd.point.f_dc, np.stack([cols[f"f_dc_{c}"] for c in range(3)], 1))
    # f_rest: the file is channel-major (f_rest_{c * 8 + k}), the cloud [N, 8, 3].
    rest = np.stack([np.stack([cols[f"f_rest_{c * 8 + k}"] for c in range(3)], 1) for k in range(8)], 1)
    np.testing.assert_array_equal(pcd.point.f_rest, rest)
    # The file holds log-scales and unnormalised quaternions; the cloud linear scales and
    # unit quaternions, computed in float32 there (1 ulp from numpy's exp and norm).
    log_scale = np.stack([cols[f"scale_{c}"] for c in range(3)], 1)
    np.testing.assert_allclose(pcd.point.scale, np.exp(log_scale), rtol=2.5e-7)
    q = np.stack([cols[f"rot_{c}"] for c in range(4)], 1).astype(np.float64)
    np.testing.assert_allclose(pcd.point.rot, q / np.linalg.norm(q, axis=1, keepdims=True), rtol=0, atol=3e-7)


def test_views_write_through_and_guard_their_memory():
    pcd = o3d.t.geometry.PointCloud(np.zeros((4, 3), np.float32))
    view = pcd.point.positions
    view[2] = [1, 2, 3]  # no copy: the cloud sees it
    assert pcd.point["positions"][2].tolist() == [1, 2, 3]
    with pytest.raises(o3d.Open3DError, match="numpy view"):
        pcd.point["positions"] = np.ones((4, 3), np.float32)
    del view
    pcd.point["positions"] = np.ones((4, 3), np.float32)  # a copy in
    assert pcd.point.positions.sum() == 12
    with pytest.raises(o3d.Open3DError, match="dtype complex128 is not supported"):
        pcd.point["scale"] = np.ones((4, 3), complex)
    with pytest.raises(AttributeError, match="no attribute 'scale'"):
        pcd.point.scale
    with pytest.raises(o3d.Open3DError):
        pcd.point["scale"] = np.ones((5, 3), np.float32)  # 5 rows for 4 points


@pytest.mark.parametrize("extension", [".ply", ".splat", ".spz", ".glb"])
def test_write_then_read(data, tmp_path, extension):
    pcd = o3d.t.io.read_point_cloud(str(data("playbot/playbot_31k.ply")))
    out = tmp_path / ("scene" + extension)
    o3d.t.io.write_point_cloud(str(out), pcd)
    back = o3d.t.io.read_point_cloud(str(out))
    assert len(back) == len(pcd)
    if extension == ".ply":  # lossless
        for name in ("positions", "scale", "rot", "opacity", "f_dc", "f_rest"):
            np.testing.assert_array_equal(back.point[name], pcd.point[name], err_msg=name)
    elif extension == ".glb":  # float32, but opacity goes through sigmoid and back
        for name in ("positions", "scale", "rot", "opacity", "f_dc", "f_rest"):
            # Measured: 2.4e-7 at most (opacity logits near 5.5: one float32 ulp is 4.8e-7).
            np.testing.assert_allclose(back.point[name], pcd.point[name], rtol=0, atol=5e-7, err_msg=name)
    else:  # positions within the format's quantisation (SPZ: 12 fractional bits here)
        np.testing.assert_allclose(back.point.positions, pcd.point.positions, atol=2e-3)


def test_errors_carry_the_cpp_messages(tmp_path):
    with pytest.raises(o3d.Open3DError, match=re.escape("Cannot open '/no/such.ply': no such file")):
        o3d.t.io.read_point_cloud("/no/such.ply")
    bad = tmp_path / "bad.txt"
    bad.write_text("hello")
    with pytest.raises(o3d.Open3DError, match="bad.txt"):
        o3d.t.io.read_point_cloud(str(bad))
    with pytest.raises(o3d.Open3DError, match="ply_format"):
        o3d.t.io.write_point_cloud(str(tmp_path / "x.ply"), o3d.t.geometry.PointCloud(), "binary")
    with pytest.raises(o3d.Open3DError, match="cameras"):
        o3d.camera.read_cameras_json(str(tmp_path / "cameras.json"))


def test_error_messages_with_bytes_that_are_not_utf8(tmp_path):
    # The JSON parser quotes the byte it stopped at; 0xff is no UTF-8, and pybind11's own
    # translation turned such a message into an empty one.
    bad = tmp_path / "cameras.json"
    bad.write_bytes(b'[{"id": "\xff"}]')
    with pytest.raises(o3d.Open3DError) as info:
        o3d.camera.read_cameras_json(str(bad))
    assert "cameras.json: malformed JSON" in str(info.value)
    assert "\\xff" in str(info.value)


def test_cameras_three_ways(data):
    views = o3d.camera.read_cameras_json(str(data("playbot/cameras.json")))
    c = views[0].camera
    same = o3d.camera.PinholeCamera.from_intrinsics_extrinsics(c.intrinsic_matrix, c.world_to_camera, c.width, c.height)
    assert (same.fx, same.cx, same.width) == (c.fx, c.cx, c.width)
    np.testing.assert_array_equal(same.world_to_camera, c.world_to_camera)
    look = o3d.camera.PinholeCamera.look_at([0, 0, -3], [0, 0, 0], [0, -1, 0], 60.0, 320, 240)
    np.testing.assert_allclose(look.get_center(), [0, 0, -3], atol=1e-12)
    # The centre of the image looks at the target: it projects to the principal point.
    p = look.world_to_camera @ np.array([0, 0, 0, 1.0])
    assert p[2] > 0 and abs(look.fx * p[0] / p[2]) < 1e-9
    with pytest.raises(o3d.Open3DError, match="skew"):
        o3d.camera.PinholeCamera.from_intrinsics_extrinsics(np.array([[1, 0.5, 0], [0, 1, 0], [0, 0, 1.0]]), np.eye(4), 10, 10)
