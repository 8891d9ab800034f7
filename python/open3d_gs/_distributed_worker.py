"""The worker side of open3d_gs.distributed: SceneRenderer, the Dask actor that lives on a
worker, keeps its OffscreenRenderers (one per scene and size) across calls and renders a
job's views in batches, writing PNG / .npy files or returning the arrays.

Pickled by reference (open3d_gs._distributed_worker.SceneRenderer), so a worker needs the
package importable (PYTHONPATH) but not the client's job files.
"""
import collections
import ctypes
import os
import socket
import tempfile
import time

import numpy as np

from ._core import io as _io


def write_png(path, rgb):
    """An 8-bit RGB PNG (open3d_gs.io.write_image), written atomically."""
    _write_atomically(path, lambda tmp: _io.write_image(tmp, np.ascontiguousarray(rgb)))


def write_npy(path, array):
    _write_atomically(path, lambda tmp: np.save(tmp, array))


def _write_atomically(path, write):
    """Into a temporary file beside `path` (its name ends with `path`'s, so the writer picks the
    same format), then renamed over it: a worker killed mid-write leaves no truncated image,
    and the retry's rename replaces whatever was there."""
    folder = os.path.dirname(path)
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=os.path.basename(path), dir=folder)
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def keep_freed_memory():
    """Undoes, for this worker process, the MALLOC_TRIM_THRESHOLD_=65536 that Dask's nanny
    starts workers with (distributed.nanny.pre-spawn-environ): glibc then hands the top of the
    heap back to the system whenever 64 KiB are free there and stops raising its mmap
    threshold, so the buffers that lavapipe and the renderer allocate per batch fault in afresh
    every batch (lavapipe, playbot_125k at 400 x 400: 1.6 views/s against 2.3). The thresholds
    set here (256 MiB, 32 MiB, glibc's largest dynamic one) keep them. Returns whether it did."""
    if "MALLOC_TRIM_THRESHOLD_" not in os.environ:
        return False
    try:
        libc = ctypes.CDLL("libc.so.6")
    except OSError:  # not glibc: the variable meant nothing
        return False
    m_trim_threshold, m_mmap_threshold = -1, -3  # malloc.h
    return bool(libc.mallopt(m_trim_threshold, 256 << 20) and libc.mallopt(m_mmap_threshold, 32 << 20))


class SceneRenderer:
    """A Dask actor: one per worker, holding up to `cache_scenes` loaded scenes.

    backend: "vulkan" (lavapipe where there is no GPU) or "cpu". hook: a callable run before
    each batch as hook(job_name, views) (instrumentation; the tests use it to kill a worker
    mid-job). Creating it makes and drops a 1x1 renderer, so a worker without a usable
    device fails here, with the reason, instead of at its first job.
    """

    def __init__(self, backend="vulkan", cache_scenes=2, hook=None):
        """Made on the worker by client.submit(SceneRenderer, ..., actor=True)."""
        import open3d_gs

        self._rendering = open3d_gs.visualization.rendering
        self._o3d = open3d_gs
        self._backend = backend
        self._cache_scenes = max(1, int(cache_scenes))
        self._hook = hook
        self._scenes = collections.OrderedDict()  # (scene, width, height) -> renderer, buffers
        self._cameras = {}  # cameras.json path -> (mtime, views)
        self._rendering.OffscreenRenderer(1, 1, backend)
        self.kept_freed_memory = keep_freed_memory()
        self.pid = os.getpid()
        self.host = socket.gethostname()
        self.loads = 0

    def describe(self):
        """Where it runs and what it holds (for progress lines and tests)."""
        return {"pid": self.pid, "host": self.host, "backend": self._backend, "loads": self.loads,
                "kept_freed_memory": self.kept_freed_memory,
                "scenes": [list(k) for k in self._scenes]}

    def _views(self, path):
        mtime = os.stat(path).st_mtime_ns
        cached = self._cameras.get(path)
        if cached is None or cached[0] != mtime:
            cached = (mtime, self._o3d.camera.read_cameras_json(path))
            self._cameras[path] = cached
        return cached[1]

    def _scene(self, job):
        """The renderer holding job's scene at job's size: loaded on first use, then reused;
        the least recently used one goes when more than cache_scenes are held."""
        key = (job["scene"], job["width"], job["height"])
        entry = self._scenes.get(key)
        if entry is not None:
            self._scenes.move_to_end(key)
            return entry, False
        renderer = self._rendering.OffscreenRenderer(job["width"], job["height"], self._backend)
        renderer.scene.add_geometry("scene", self._o3d.t.io.read_point_cloud(job["scene"]))
        entry = {"renderer": renderer, "buffers": {}}
        self._scenes[key] = entry
        while len(self._scenes) > self._cache_scenes:
            self._scenes.popitem(last=False)
        self.loads += 1
        return entry, True

    def _render(self, entry, cameras, dtype):
        """render_batch into a batch_array kept per scene and dtype (on Vulkan the GPU writes
        it directly; RGBA in both dtypes), grown when a batch is longer than the last. Cameras
        of another size than the job's are scaled to it (rescale)."""
        buffers = entry["buffers"]
        buf = buffers.get(dtype)
        if buf is None or len(buf) < len(cameras):
            buf = buffers[dtype] = entry["renderer"].batch_array(len(cameras), dtype)
        return entry["renderer"].render_batch(cameras, dtype, out=buf[:len(cameras)], rescale=True)

    def render(self, job, views, return_arrays=False):
        """Renders `views` (indices into job["cameras"]) of `job` (a dict of Job's fields with
        width and height set). Never raises: a failure comes back as its message with the
        phase it happened in ("load": the scene or cameras; "render"; "write")."""
        out = {"views": list(views), "loaded": False, "load_s": 0.0, "render_s": 0.0, "write_s": 0.0,
               "arrays": None, "error": None, "phase": None}
        phase = "load"
        try:
            start = time.perf_counter()
            all_views = self._views(job["cameras"])
            entry, out["loaded"] = self._scene(job)
            cameras = [all_views[v].camera for v in views]
            rendered = time.perf_counter()
            out["load_s"] = rendered - start
            phase = "render"
            if self._hook is not None:
                self._hook(job["name"], list(views))
            formats, dtype = job["formats"], job["dtype"]
            arrays = rgb8 = None
            if "npy" in formats or return_arrays or "png" not in formats:
                arrays = self._render(entry, cameras, dtype)
            if "png" in formats:
                rgb8 = arrays if dtype == "uint8" and arrays is not None else self._render(entry, cameras, "uint8")
            written = time.perf_counter()
            out["render_s"] = written - rendered
            phase = "write"
            if job["folder"] is not None and formats:
                os.makedirs(job["folder"], exist_ok=True)
                for i, v in enumerate(views):
                    if "png" in formats:
                        write_png(os.path.join(job["folder"], f"view_{v:03d}.png"), rgb8[i, ..., :3])
                    if "npy" in formats:
                        write_npy(os.path.join(job["folder"], f"view_{v:03d}.npy"), arrays[i])
            if return_arrays:
                out["arrays"] = arrays.copy()  # the batch_array is reused by the next call
            out["write_s"] = time.perf_counter() - written
        except Exception as e:  # noqa: BLE001 - every failure goes back to the client as text
            out["error"] = f"{type(e).__name__}: {e}"
            out["phase"] = phase
        return out
