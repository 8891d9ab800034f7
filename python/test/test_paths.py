"""File names as pathlib.Path (any os.PathLike) everywhere a file is named, and a missing
input file raised as an error that is both Open3DError and FileNotFoundError."""
import errno
import os
import pathlib

import numpy as np
import pytest

import open3d_gs as o3d


class Custom(os.PathLike):
    """An os.PathLike that is not a pathlib.Path."""

    def __init__(self, path):
        self.path = str(path)

    def __fspath__(self):
        return self.path


@pytest.mark.parametrize("wrap", [pathlib.Path, Custom])
def test_paths_everywhere(data, tmp_path, wrap):
    pcd = o3d.t.io.read_point_cloud(wrap(data("playbot/playbot_31k.ply")))
    assert len(pcd) == 31000
    o3d.t.io.write_point_cloud(wrap(tmp_path / "out.ply"), pcd)
    assert len(o3d.t.io.read_point_cloud(wrap(tmp_path / "out.ply"))) == 31000
    views = o3d.camera.read_cameras_json(wrap(data("playbot/cameras.json")))
    assert len(views) > 0
    small = pcd.select_by_index(np.arange(0, 31000, 100))
    o3d.t.io.write_splat_pages(wrap(tmp_path / "small.gspages"), small, page_capacity=64)
    assert (tmp_path / "small.gspages").stat().st_size > 0
    image = np.zeros((4, 5, 3), np.uint8)
    image[1, 2] = [10, 20, 30]
    for io in (o3d.io, o3d.t.io):
        assert io.write_image(wrap(tmp_path / "image.png"), image)
        np.testing.assert_array_equal(io.read_image(wrap(tmp_path / "image.png")), image)


def test_stream_splats_takes_a_path(tmp_path, backend):
    rng = np.random.default_rng(3)
    n = 300
    pcd = o3d.t.geometry.PointCloud(rng.uniform([-1, -1, 3], [1, 1, 5], (n, 3)))
    pcd.point["scale"] = np.full((n, 3), 0.05)
    pcd.point["rot"] = np.tile([1.0, 0, 0, 0], (n, 1))
    pcd.point["opacity"] = np.zeros(n)
    pcd.point["f_dc"] = rng.uniform(-1, 1, (n, 3))
    o3d.t.io.write_splat_pages(tmp_path / "s.gspages", pcd, page_capacity=64)
    r = o3d.visualization.rendering.OffscreenRenderer(32, 32, backend)
    if backend == "cpu":  # the path is taken; the backend refuses (only Vulkan streams)
        with pytest.raises(o3d.Open3DError, match="vulkan"):
            r.scene.stream_splats(tmp_path / "s.gspages")
        return
    r.scene.stream_splats(tmp_path / "s.gspages")
    assert r.scene.stream_progress["path"] == str(tmp_path / "s.gspages")


@pytest.mark.parametrize("read", [
    lambda p: o3d.t.io.read_point_cloud(p),
    lambda p: o3d.camera.read_cameras_json(p),
    lambda p: o3d.io.read_image(p),
    lambda p: o3d.t.io.read_image(p),
    lambda p: o3d.visualization.rendering.OffscreenRenderer(8, 8, "cpu").scene.stream_splats(p),
])
@pytest.mark.parametrize("wrap", [str, pathlib.Path])
def test_a_missing_input_is_both_open3d_error_and_file_not_found(tmp_path, read, wrap):
    missing = tmp_path / "no" / "such.file"
    with pytest.raises(FileNotFoundError) as info:
        read(wrap(missing))
    e = info.value
    assert isinstance(e, o3d.Open3DError) and isinstance(e, RuntimeError)
    assert isinstance(e, o3d.Open3DFileNotFoundError)
    assert str(missing) in str(e)
    assert e.errno == errno.ENOENT and e.filename == str(missing)
    # Caught as either, as code written for Open3D or for the standard library expects.
    with pytest.raises(o3d.Open3DError, match="no such file"):
        read(wrap(missing))


def test_a_missing_stream_in_draw_is_file_not_found(tmp_path):
    # Checked before the viewer opens, so no display is needed to see it.
    with pytest.raises(FileNotFoundError, match="no such file"):
        o3d.visualization.draw([tmp_path / "missing.gspages"])


def test_other_errors_are_not_file_not_found(tmp_path):
    bad = tmp_path / "bad.ply"
    bad.write_text("not a ply")
    with pytest.raises(o3d.Open3DError) as info:
        o3d.t.io.read_point_cloud(bad)
    assert not isinstance(info.value, FileNotFoundError)
