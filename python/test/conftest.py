"""Shared fixtures of the open3d_gs tests: where the shared scenes and gs-render are, the
project's rule for tests that cannot run here (skip locally, fail in CI: CI=true), and the
PNG reader the tests share."""
import os
import pathlib

import numpy as np
import pytest

import open3d_gs as o3d

DATA = pathlib.Path(os.environ.get("OPEN3D_DATA_DIR", pathlib.Path(__file__).parents[3] / "shared" / "data"))


def unavailable(reason):
    """Skips the test, or fails it in CI, where a skip would hide a failure."""
    if os.environ.get("CI") == "true":
        pytest.fail("CI=true, so this test may not skip: " + reason)
    pytest.skip(reason)


@pytest.fixture
def data():
    def path(relative):
        p = DATA / relative
        if not p.exists():
            unavailable(f"shared scene {p} is absent")
        return p

    return path


@pytest.fixture(scope="module")
def playbot():
    """playbot_31k (SH degree 2) and its cameras, read once per test module."""
    path = DATA / "playbot/playbot_31k.ply"
    if not path.exists():
        unavailable(f"shared scene {path} is absent")
    return o3d.t.io.read_point_cloud(str(path)), o3d.camera.read_cameras_json(str(DATA / "playbot/cameras.json"))


@pytest.fixture
def gs_render():
    exe = os.environ.get("GS_RENDER", "")
    if not exe or not os.path.exists(exe):
        unavailable("GS_RENDER does not name the gs-render binary (ctest sets it)")
    return exe


@pytest.fixture
def display():
    """An X server: Filament (meshes, the viewer) needs one."""
    if not os.environ.get("DISPLAY"):
        unavailable("DISPLAY is not set: meshes and the viewer need an X server (run under xvfb-run; ctest does)")


@pytest.fixture(params=["vulkan", "cpu"])
def backend(request):
    """Both backends; the Vulkan one needs a device (lavapipe without a GPU)."""
    if request.param == "vulkan":
        try:
            o3d.visualization.rendering.OffscreenRenderer(1, 1, "vulkan")
        except o3d.Open3DError as e:
            unavailable(f"no Vulkan device: {e}")
    return request.param


def read_png_rgb(path):
    """An 8-bit RGB PNG the examples and open3d_gs.distributed write (o3d.io.write_image)."""
    image = o3d.io.read_image(path)
    assert image.dtype == np.uint8 and image.ndim == 3 and image.shape[2] == 3
    return image
