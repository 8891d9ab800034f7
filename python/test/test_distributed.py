"""open3d_gs.distributed on a LocalCluster of 2 worker processes (one thread each) with the
Vulkan backend (lavapipe without a GPU): images equal this process's renders bit for bit, a
worker killed mid-job has its views rendered again, a bad scene fails alone with its message,
and the command line runs a job list end to end. Nothing waits on timing: every wait has a
deadline (DEADLINE) that only a hang reaches."""
import json
import logging
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import open3d_gs as o3d
from conftest import DATA, read_png_rgb, unavailable

try:
    from dask.distributed import Client, LocalCluster
except ImportError:  # checked in the fixture: a skip locally, a failure in CI
    Client = LocalCluster = None

Renderer = o3d.visualization.rendering.OffscreenRenderer
SIZE = 64
DEADLINE = 600  # seconds; only a hang reaches it
SCENE, CAMERAS = "playbot/playbot_31k.ply", "playbot/cameras.json"
# Worker processes and the command import open3d_gs from where this process did.
PACKAGE_PARENT = os.path.dirname(os.path.dirname(os.path.abspath(o3d.__file__)))


@pytest.fixture(scope="module")
def client():
    if Client is None:
        unavailable("dask.distributed is not installed (Debian: python3-distributed, scripts/setup.sh)")
    try:
        Renderer(1, 1, "vulkan")
    except o3d.Open3DError as e:
        unavailable(f"no Vulkan device: {e}")
    with pytest.MonkeyPatch.context() as mp:  # the workers are spawned processes
        mp.setenv("PYTHONPATH", os.pathsep.join([PACKAGE_PARENT, os.environ.get("PYTHONPATH", "")]))
        cluster = LocalCluster(n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None,
                               silence_logs=logging.ERROR)
    with Client(cluster) as c:
        yield c
    cluster.close()


@pytest.fixture(scope="module")
def reference():
    """This process's renders of every view at SIZE: the float32 RGBA image of each view alone
    (render_to_image) and render_batch's uint8 RGBA images (a PNG holds their RGB)."""
    scene, cameras = DATA / SCENE, DATA / CAMERAS
    if not scene.exists() or not cameras.exists():
        unavailable(f"shared scene {scene} or {cameras} is absent")
    try:
        r = Renderer(SIZE, SIZE, "vulkan")
    except o3d.Open3DError as e:
        unavailable(f"no Vulkan device: {e}")
    r.scene.add_geometry("scene", o3d.t.io.read_point_cloud(str(scene)))
    views = o3d.camera.read_cameras_json(str(cameras))
    floats = []
    for v in views:
        r.setup_camera(v.camera, rescale=True)  # 800 x 800 cameras, scaled to SIZE as the jobs ask
        floats.append(r.render_to_image().copy())
    return {"scene": str(scene), "cameras": str(cameras), "float32": np.stack(floats),
            "uint8": r.render_batch([v.camera for v in views], "uint8", alpha=True, rescale=True)}


def check_outputs(folder, views, reference, formats=("png",), dtype="uint8"):
    for v in views:
        if "png" in formats:
            np.testing.assert_array_equal(read_png_rgb(folder / f"view_{v:03d}.png"),
                                          reference["uint8"][v, ..., :3], err_msg=f"{folder} view {v} png")
        if "npy" in formats:
            np.testing.assert_array_equal(np.load(folder / f"view_{v:03d}.npy"), reference[dtype][v],
                                          err_msg=f"{folder} view {v} npy")
    assert not list(folder.glob(".tmp-*")), "a temporary file was left behind"


def run(client, jobs, **kwargs):
    from open3d_gs.distributed import render_jobs

    lines = []
    report = render_jobs(client, jobs, progress=lines.append, timeout=DEADLINE, **kwargs)
    return report, lines


def test_cluster_images_equal_single_process_renders(client, reference, tmp_path):
    from open3d_gs.distributed import Job

    jobs = [Job(reference["scene"], reference["cameras"], views=list(range(7)), width=SIZE, height=SIZE,
                folder=str(tmp_path / "a"), formats=("png", "npy"), name="a"),
            Job(reference["scene"], reference["cameras"], views=[9, 8, 12, 20], width=SIZE, height=SIZE,
                folder=str(tmp_path / "b"), formats=("npy",), dtype="float32", name="b")]
    report, lines = run(client, jobs, batch=3, return_arrays=True)
    assert report.ok, [j.error for j in report.jobs]
    check_outputs(tmp_path / "a", range(7), reference, ("png", "npy"))
    check_outputs(tmp_path / "b", [9, 8, 12, 20], reference, ("npy",), "float32")
    np.testing.assert_array_equal(report.jobs[0].images, reference["uint8"][:7])
    np.testing.assert_array_equal(report.jobs[1].images, reference["float32"][[9, 8, 12, 20]])
    # One scene at one size: each worker read it at most once and reused it for its views.
    assert report.views == 11 and all(w.loads <= 1 for w in report.workers.values())
    assert sum(w.views for w in report.workers.values()) == 11
    assert any(line.startswith("job a: 7 views at 64x64 done") for line in lines), lines
    assert any(line.startswith("job b: 4 views at 64x64 done") for line in lines), lines
    assert report.summary_lines()[-1].startswith("total: 11 views in ")


def test_a_bad_scene_fails_alone_with_its_message(client, reference, tmp_path):
    from open3d_gs.distributed import Job

    corrupt = tmp_path / "corrupt.ply"
    corrupt.write_bytes(pathlib.Path(reference["scene"]).read_bytes()[:3000])  # header and 12 splats
    common = dict(width=SIZE, height=SIZE, formats=("png",))
    jobs = [Job(str(tmp_path / "missing.ply"), reference["cameras"], views=[0], folder=str(tmp_path / "m"),
                name="missing", **common),
            Job(reference["scene"], reference["cameras"], views=[1, 2, 3], folder=str(tmp_path / "good"),
                name="good", **common),
            Job(str(corrupt), reference["cameras"], views=[0, 1], folder=str(tmp_path / "c"), name="corrupt",
                **common),
            Job(reference["scene"], str(tmp_path / "no-cameras.json"), views=[0], folder=str(tmp_path / "n"),
                name="no-cameras", **common),
            Job(reference["scene"], reference["cameras"], views=[3, 24], folder=str(tmp_path / "r"),
                name="out-of-range", **common)]
    report, lines = run(client, jobs, batch=2)
    errors = {j.name: j.error for j in report.jobs}
    assert errors["good"] is None
    check_outputs(tmp_path / "good", [1, 2, 3], reference)
    assert "Cannot open" in errors["missing"] and "missing.ply" in errors["missing"], errors
    assert "corrupt.ply" in errors["corrupt"] and "truncated" in errors["corrupt"], errors
    assert "no-cameras.json" in errors["no-cameras"], errors
    assert "has 24 views" in errors["out-of-range"] and "[24]" in errors["out-of-range"], errors
    for name in ("missing", "corrupt", "no-cameras", "out-of-range"):
        assert any(line == f"job {name} FAILED: {errors[name]}" for line in lines), (name, lines)
        assert not (tmp_path / name[0]).exists() or not list((tmp_path / name[0]).glob("*.png"))
    assert not report.ok and report.views == 3


def test_a_killed_workers_views_are_rendered_again(client, reference, tmp_path):
    """The first batch any worker starts makes that worker process exit (os._exit) before
    it returns: its batches are lost with it and must be rendered by the other worker or the
    one its nanny restarts. A marker file makes the kill happen exactly once."""
    from open3d_gs.distributed import Job

    marker = str(tmp_path / "killed")

    def exit_once(job_name, views):  # runs on the worker (cloudpickled: a local function)
        try:
            fd = os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except FileExistsError:
            return
        os.write(fd, f"{os.getpid()} {views}".encode())
        os.close(fd)
        os._exit(1)

    jobs = [Job(reference["scene"], reference["cameras"], views=list(range(12)), width=SIZE, height=SIZE,
                folder=str(tmp_path / "k"), formats=("png", "npy"), name="k")]
    report, lines = run(client, jobs, batch=2, worker_hook=exit_once)
    assert report.ok, report.jobs[0].error
    pid, _ = pathlib.Path(marker).read_text().split(" ", 1)
    lost = [w for w in report.workers.values() if w.lost]
    assert len(lost) == 1 and lost[0].views == 0 and report.retried_views >= 2, report.summary_lines()
    assert lost[0].pid in (None, int(pid))  # None: it died before telling its pid
    assert any("lost" in line and "go back to the queue" in line for line in lines), lines
    check_outputs(tmp_path / "k", range(12), reference, ("png", "npy"))
    assert report.views == 12


def cli(*args, cwd):
    """The command, run in `cwd` and importing this process's open3d_gs."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([PACKAGE_PARENT, os.environ.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, "-m", "open3d_gs.distributed", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=DEADLINE, env=env)


def test_command_line_renders_a_job_list_end_to_end(client, reference, tmp_path):
    """A JSON list on a local cluster of its own (--local-workers) and a CSV list on the
    test's cluster (--scheduler), into tmp_path; relative paths are the list's folder's."""
    (tmp_path / "lists").mkdir()
    (tmp_path / "lists" / "jobs.json").write_text(json.dumps({"jobs": [
        {"name": "robot", "scene": reference["scene"], "cameras": reference["cameras"], "views": "0-4",
         "resolution": f"{SIZE}x{SIZE}", "output": {"folder": "../out/robot", "formats": ["png", "npy"]}},
        {"scene": reference["scene"], "cameras": reference["cameras"], "views": [5, 6],
         "resolution": [SIZE, SIZE], "output": {"folder": "../out/floats", "formats": ["npy"], "dtype": "float32"}},
    ]}))
    done = cli("lists/jobs.json", "--local-workers", 2, "--batch", 2, "--report", "report.json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    check_outputs(tmp_path / "out" / "robot", range(5), reference, ("png", "npy"))
    check_outputs(tmp_path / "out" / "floats", [5, 6], reference, ("npy",), "float32")
    assert "job robot: 5 views at 64x64 done" in done.stderr and "job playbot_31k: 2 views" in done.stderr
    assert done.stdout.splitlines()[-1].startswith("total: 7 views in "), done.stdout
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["ok"] and report["views"] == 7 and [j["name"] for j in report["jobs"]] == ["robot", "playbot_31k"]

    (tmp_path / "jobs.csv").write_text(
        "name,scene,cameras,views,resolution,folder,formats\n"
        f"csv,{reference['scene']},{reference['cameras']},7 9,{SIZE}x{SIZE},csv-out,png\n"
        f"broken,{tmp_path / 'nothing.ply'},{reference['cameras']},0,{SIZE}x{SIZE},broken-out,png\n")
    done = cli("jobs.csv", "--scheduler", client.scheduler.address, cwd=tmp_path)
    assert done.returncode == 1, done.stderr  # one job failed
    check_outputs(tmp_path / "csv-out", [7, 9], reference)
    assert "job broken FAILED: load: Open3DFileNotFoundError: Cannot open" in done.stderr, done.stderr
    assert "1 jobs done, 1 failed" in done.stdout and "FAILED broken: load: Open3DFileNotFoundError" in done.stdout


def test_command_line_errors_name_the_file_and_the_field(data, tmp_path):
    """Refused before any cluster is used (exit status 2): the message names the job list
    and the field; an output that would overwrite an input is refused."""
    reference = {"scene": str(data(SCENE)), "cameras": str(data(CAMERAS))}
    def job_list(**fields):
        job = {"scene": reference["scene"], "cameras": reference["cameras"], "output": {"folder": "out"}}
        job.update(fields)
        path = tmp_path / "jobs.json"
        path.write_text(json.dumps([{"scene": reference["scene"], "cameras": reference["cameras"],
                                     "output": {"folder": "first"}}, job]))
        return path

    cases = [
        (dict(resolutoin=[8, 8]), "jobs.json: [1].resolutoin: unknown field"),
        (dict(views="some"), "jobs.json: [1].views: expected \"all\""),
        (dict(resolution=[0, 8]), "jobs.json: [1].resolution: expected [width, height]"),
        (dict(output={"folder": "o", "formats": ["jpg"]}), "jobs.json: [1].output.formats: expected"),
        (dict(output={"folder": "o", "dtype": "float64"}), "jobs.json: [1].output.dtype: expected one of"),
        (dict(output={"formats": ["png"]}), "jobs.json: [1].output.folder: missing"),
        (dict(scene=None), "jobs.json: [1].scene: missing"),
        (dict(output={"folder": "first"}), "write the same png files into"),
    ]
    for fields, message in cases:
        done = cli(job_list(**fields), "--local-workers", 1, cwd=tmp_path)
        assert done.returncode == 2 and message in done.stderr, (fields, done.stderr)
    # An output that would be the scene itself: the input is left alone.
    scene = tmp_path / "view_000.png"
    scene.write_bytes(b"not a scene")
    path = tmp_path / "own.json"
    path.write_text(json.dumps([{"scene": "view_000.png", "cameras": reference["cameras"], "views": [0],
                                 "output": {"folder": "."}}]))
    done = cli(path, "--local-workers", 1, cwd=tmp_path)
    assert done.returncode == 2 and "would overwrite job 'view_000''s scene" in done.stderr, done.stderr
    assert scene.read_bytes() == b"not a scene"
    (tmp_path / "bad.csv").write_text("scene,cameras,colour\na.ply,c.json,red\n")
    done = cli(tmp_path / "bad.csv", "--local-workers", 1, cwd=tmp_path)
    assert done.returncode == 2 and "bad.csv: column 'colour': unknown" in done.stderr, done.stderr
    # --check reads and checks, prints the jobs, and needs no cluster.
    done = cli(job_list(views=[3, 4]), "--check", "--scheduler", "tcp://127.0.0.1:1", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    checked = [json.loads(line) for line in done.stdout.splitlines()]
    assert [j["views"] for j in checked] == ["all", [3, 4]] and checked[1]["folder"] == str(tmp_path / "out")
    done = cli("--help", cwd=tmp_path)
    assert done.returncode == 0
    for option in ("--scheduler", "--local-workers", "--batch", "--retries", "--resources", "--report", "view_NNN.png"):
        assert option in done.stdout, option


def test_workers_that_declare_a_gpu_are_the_ones_used():
    """resources="auto": the workers declaring GPU (dask worker --resources GPU=1) if any does,
    each asked for one GPU; else every worker. None: every worker; a dict: those that have it."""
    from open3d_gs.distributed import _Pool

    info = {"cpu": {"resources": {}}, "gpu0": {"resources": {"GPU": 1}}, "gpu1": {"resources": {"GPU": 2.0}},
            "big": {"resources": {"MEMORY": 64e9}}}

    def wanted(resources, workers=info):  # the scheduler's worker records, as scheduler_info gives them
        return _Pool(None, "vulkan", 2, None, resources, print)._wanted(workers)

    assert wanted("auto") == ({"gpu0", "gpu1"}, {"GPU": 1})
    assert wanted("auto", {"cpu": {"resources": {}}, "other": {}}) == ({"cpu", "other"}, None)
    assert wanted(None) == (set(info), None)
    assert wanted({"GPU": 2}) == ({"gpu1"}, {"GPU": 2})
    assert wanted({"MEMORY": 1e9}) == ({"big"}, {"MEMORY": 1e9})


def test_a_worker_picks_its_vulkan_device_by_index():
    """OPEN3D_VULKAN_DEVICE_INDEX (a process per GPU, docs/distributed.md): 0 is lavapipe
    here; an index past the devices and a non-number are refused with the reason."""
    try:
        Renderer(1, 1, "vulkan")
    except o3d.Open3DError as e:
        unavailable(f"no Vulkan device: {e}")
    code = ("import open3d_gs as o3d\n"
            "try:\n    print(o3d.visualization.rendering.OffscreenRenderer(8, 8, 'vulkan').backend)\n"
            "except o3d.Open3DError as e:\n    print('error:', e)\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([PACKAGE_PARENT, os.environ.get("PYTHONPATH", "")]))
    outputs = {}
    for index in ("0", "7", "first"):
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=DEADLINE,
                              env=dict(env, OPEN3D_VULKAN_DEVICE_INDEX=index))
        outputs[index] = done.stdout
    assert outputs["0"].strip() == "vulkan", outputs
    assert "no usable device" in outputs["7"] and "not OPEN3D_VULKAN_DEVICE_INDEX=7" in outputs["7"], outputs
    assert "OPEN3D_VULKAN_DEVICE_INDEX must be a device number" in outputs["first"], outputs
