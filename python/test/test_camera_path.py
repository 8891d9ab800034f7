"""Camera paths from Python (docs/camera-paths.md): a cameras.json's views as keyframes, frames
at keyframe times equal to those views exactly, and a path's frames rendered in one batch equal
to rendering the same cameras one by one."""
import numpy as np
import pytest

import open3d_gs as o3d

from conftest import DATA


def test_a_cameras_json_is_a_path_through_its_views(playbot):
    _, views = playbot
    path = o3d.camera.CameraPath.from_cameras_json(DATA / "playbot/cameras.json", seconds_per_keyframe=0.5)
    assert path.duration == pytest.approx(0.5 * (len(views) - 1))
    frames = path.frames(fps=4)  # keyframes every second frame
    assert len(frames) == 2 * (len(views) - 1) + 1
    for k, view in enumerate(views):
        np.testing.assert_array_equal(frames[2 * k].world_to_camera, view.camera.world_to_camera)
    # Between two keyframes the centre lies off both.
    mid = path.at(0.25).get_center()
    assert np.linalg.norm(mid - views[0].camera.get_center()) > 1e-3
    assert np.linalg.norm(mid - views[1].camera.get_center()) > 1e-3


def test_frames_render_in_a_batch_as_one_by_one(playbot):
    pcd, views = playbot
    path = o3d.camera.CameraPath([0.0, 1.0], [views[0].camera, views[3].camera])
    frames = [c.resized(48, 48) for c in path.frames(fps=3)]
    r = o3d.visualization.rendering.OffscreenRenderer(48, 48, "cpu")
    r.scene.add_geometry("scene", pcd)
    batch = r.render_batch(frames)
    for i, camera in enumerate(frames):
        r.setup_camera(camera)
        np.testing.assert_array_equal(batch[i], r.render_to_image(), err_msg=f"frame {i}")


def test_bad_keyframes_are_refused(playbot):
    _, views = playbot
    with pytest.raises(o3d.Open3DError, match="keyframe 1 is at 0 s"):
        o3d.camera.CameraPath([0.0, 0.0], [views[0].camera, views[1].camera])
    with pytest.raises(o3d.Open3DError, match="2 times for 1 cameras"):
        o3d.camera.CameraPath([0.0, 1.0], [views[0].camera])


def test_a_path_renders_into_a_video(playbot, tmp_path):
    """A batch of a path's frames into an MP4 through io.VideoWriter: the file appears only when
    the writer closes, holds one sample per frame (its stsz box), and a raising block leaves
    nothing. What the samples decode to is tests_io's H264VideoWriterTest."""
    pcd, views = playbot
    path = o3d.camera.CameraPath([0.0, 1.0], [views[0].camera, views[3].camera])
    frames = [c.resized(34, 30) for c in path.frames(fps=6)]
    r = o3d.visualization.rendering.OffscreenRenderer(34, 30, "cpu")
    r.scene.add_geometry("scene", pcd)
    out = tmp_path / "path.mp4"
    with o3d.io.VideoWriter(out, 34, 30, fps=6) as video:
        for image in r.render_batch(frames):
            video.write(image)
        assert not out.exists()
    data = out.read_bytes()
    stsz = data.index(b"stsz")
    assert int.from_bytes(data[stsz + 12:stsz + 16], "big") == len(frames)
    with pytest.raises(o3d.Open3DError, match="frame 0 is 10x30 with 3 channels"):
        with o3d.io.VideoWriter(tmp_path / "bad.mp4", 34, 30) as video:
            video.write(np.zeros((30, 10, 3), np.uint8))
    with pytest.raises(o3d.Open3DError, match="--crf 0: the constant rate factor is 1"):
        o3d.io.VideoWriter(tmp_path / "bad.mp4", 34, 30, crf=0)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["path.mp4"]
