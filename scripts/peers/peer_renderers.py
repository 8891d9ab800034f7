#!/usr/bin/env python3
"""The peers as frame calls on one GPU scene, and the timing of one call.

For time_peers.py. GpuScene holds the decoded splats on the GPU once per scene; each peer
(OriginalPeer, GsplatPeer, HigsPeer) is set up on it and returns, for a camera of
render_original.view_camera, a call that renders one frame as [H, W, 3] on the GPU, so that
time_call can time exactly one forward call with CUDA events (warm-up as gs-bench's). All
peers get the original's near cull (NEAR_PLANE) and dilation (EPS2D), a black background and
no antialiasing. torch and the peers' modules are passed in: importing this needs only numpy.
"""

import math
import statistics
import time

import numpy as np

# The original culls view z <= 0.2 on its own and so does our renderer
# (RenderConfig::near_plane); gsplat and HiGS get it as near_plane (their default is 0.01).
NEAR_PLANE = 0.2
EPS2D = 0.3  # gsplat's and HiGS's default: the original's 0.3 px^2 dilation


class GpuScene:
    """The decoded splats on the GPU, shared by the peers (float32)."""

    def __init__(self, torch, g, device):
        def t(a):
            return torch.from_numpy(np.ascontiguousarray(a)).to(device)

        self.means = t(g.means)
        self.shs = t(g.shs)  # [N, (D+1)^2, 3]
        self.opacities = t(g.opacities)  # [N, 1]
        self.scales = t(g.scales)
        self.rotations = t(g.rotations)  # (w, x, y, z), normalised
        self.degree = g.sh_degree
        self.count = len(g.means)


class OriginalPeer:
    """The original's raw forward binding, called as render_original.OriginalRenderer does."""

    name = "original"

    def __init__(self, torch, module):
        self.torch, self.module = torch, module

    def setup(self, scene):
        self.scene = scene

    def frame(self, cam):
        torch, s = self.torch, self.scene
        device = s.means.device

        def t(a):
            return torch.from_numpy(np.ascontiguousarray(a)).to(device)

        empty = torch.Tensor([])
        args = (torch.zeros(3, dtype=torch.float32, device=device),  # bg
                s.means, empty, s.opacities, s.scales, s.rotations,
                1.0, empty,  # scale_modifier, cov3D_precomp
                t(cam.viewmatrix), t(cam.projmatrix), float(cam.tanfovx), float(cam.tanfovy),
                cam.height, cam.width, s.shs, s.degree, t(cam.campos),
                False, False)  # prefiltered, debug
        module = self.module
        # color [3, H, W] -> [H, W, 3]
        return lambda: module.rasterize_gaussians(*args)[1].permute(1, 2, 0)

    def release(self):
        self.scene = None


def gsplat_camera(torch, cam, device):
    """viewmat [4, 4] (world to camera, OpenCV axes) and K [3, 3] for gsplat and HiGS.

    gsplat puts pixel (x, y)'s centre at (x + 0.5, y + 0.5); ours and the original's at
    (x, y): so cx = (W - 1) / 2 + 0.5 = W / 2 and cy = H / 2.
    """
    viewmat = np.eye(4, dtype=np.float32)
    viewmat[:3, :3], viewmat[:3, 3] = cam.R, cam.t
    K = np.array([[cam.fx, 0.0, cam.width / 2.0], [0.0, cam.fy, cam.height / 2.0],
                  [0.0, 0.0, 1.0]], dtype=np.float32)
    return torch.from_numpy(viewmat).to(device), torch.from_numpy(K).to(device)


class GsplatPeer:
    """gsplat.rasterization() with its defaults but the near plane (SH evaluated inside)."""

    name = "gsplat"

    def __init__(self, torch, gsplat):
        self.torch, self.gsplat = torch, gsplat

    def setup(self, scene):
        self.scene = scene
        self.opacities = scene.opacities[:, 0].contiguous()

    def frame(self, cam):
        s = self.scene
        viewmat, K = gsplat_camera(self.torch, cam, s.means.device)
        viewmats, Ks = viewmat[None], K[None]
        rasterization = self.gsplat.rasterization
        width, height = cam.width, cam.height

        def call():
            colors, _, _ = rasterization(
                s.means, s.rotations, s.scales, self.opacities, s.shs, viewmats, Ks,
                width, height, near_plane=NEAR_PLANE, eps2d=EPS2D, sh_degree=s.degree,
                render_mode="RGB", rasterize_mode="classic")
            return colors[0]

        return call

    def release(self):
        self.scene = self.opacities = None


class HigsPeer:
    """HiGS: gsplat.experimental.GaussianInferenceRenderer (stateful), one macro-tile size."""

    def __init__(self, torch, tile_size):
        from gsplat.experimental import GaussianInferenceRenderer, GaussianInferenceScene

        self.torch, self.tile_size = torch, tile_size
        self.name = f"higs{tile_size}"
        self.Scene, self.Renderer = GaussianInferenceScene, GaussianInferenceRenderer
        self.renderer = None
        self.notes = []

    def setup(self, scene):
        torch = self.torch
        self.notes = []
        scales = scene.scales
        # from_gaussian_tensors refuses scales <= 0 (a float32 exp() can underflow to 0).
        bad = int((scales <= 0).any(dim=1).sum())
        if bad:
            scales = scales.clamp_min(torch.finfo(torch.float32).tiny)
            self.notes.append(f"{bad} splats with a scale <= 0 given the smallest float32 instead")
        packed = self.Scene.from_gaussian_tensors(
            scene.means, scene.rotations, scales, scene.opacities[:, 0].contiguous(), scene.shs,
            scene.degree, "none", id="bench")
        self.renderer = self.Renderer(packed, tile_size=self.tile_size)
        self.device = scene.means.device

    def frame(self, cam):
        viewmat, K = gsplat_camera(self.torch, cam, self.device)
        render = self.renderer.render
        width, height, tile = cam.width, cam.height, self.tile_size
        # frame: [1, H, W, 4] float16 {R, G, B, transmittance}, black background by default
        return lambda: render(viewmat=viewmat, K=K, width=width, height=height, tile_size=tile,
                              near_plane=NEAR_PLANE, eps2d=EPS2D).frame[0, :, :, :3]

    def release(self):
        if self.renderer is not None:
            self.renderer.release()
        self.renderer = None


# ------------------------------------------------------------------------- timing


def time_call(torch, fn, repeat, warmup_min_s, warmup_max_s, window=10):
    """GPU ms (CUDA events around one call, waited for) and wall ms of `fn`.

    Warm-up as gs-bench's: windows of `window` calls until a window's median is no longer
    2% below the best before it, at least warmup_min_s seconds, at most warmup_max_s.
    """
    start, end = torch.cuda.Event(enable_timing=True), torch.cuda.Event(enable_timing=True)

    def one():
        t0 = time.perf_counter()
        start.record()
        fn()
        end.record()
        end.synchronize()
        return start.elapsed_time(end), 1000.0 * (time.perf_counter() - t0)

    torch.cuda.synchronize()
    warm_start = time.perf_counter()
    best, warm_calls = math.inf, 0
    while True:
        median = statistics.median(one()[0] for _ in range(window))
        warm_calls += window
        elapsed = time.perf_counter() - warm_start
        if elapsed >= warmup_max_s or (elapsed >= warmup_min_s and median > 0.98 * best):
            break
        best = min(best, median)
    gpu, wall = zip(*(one() for _ in range(repeat)))
    return {"gpu_ms_median": statistics.median(gpu), "gpu_ms_min": min(gpu),
            "gpu_ms_mean": statistics.fmean(gpu), "wall_ms_median": statistics.median(wall),
            "calls": repeat, "warmup_calls": warm_calls, "warmup_s": round(elapsed, 3)}
