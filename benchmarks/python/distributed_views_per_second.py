#!/usr/bin/env python3
"""Views per second of open3d_gs.distributed against one process's batched path
(docs/distributed.md "Throughput"): JOBS jobs of the same scene, each VIEWS views of a
cameras.json, rendered (i) in this process by one OffscreenRenderer through render_batch in
batches of BATCH, and (ii) by render_jobs on a local Dask cluster of N worker processes (one
thread each), for each N of --workers.

Both count the same work: making the scene's renderer, reading the scene, rendering, and
writing the files (--formats; "none" renders into the batch array and writes nothing). (i)
times all of it; (ii) is render_jobs' wall time, from the first batch sent to the last result
(the cluster's and the actors' start-up are not counted; each worker's scene load is).

    PYTHONPATH=build/python python3 benchmarks/python/distributed_views_per_second.py \\
        ../shared/data/playbot/playbot_31k.ply ../shared/data/playbot/cameras.json \\
        --size 128 128 --jobs 4 --views 24 --workers 1,2
"""
import argparse
import logging
import os
import pathlib
import sys
import tempfile
import time

import open3d_gs as o3d
from open3d_gs._distributed_worker import write_npy, write_png
from open3d_gs.distributed import Job, render_jobs


def one_process(args, jobs, out):
    start = time.monotonic()
    r = o3d.visualization.rendering.OffscreenRenderer(args.size[0], args.size[1], args.backend)
    r.scene.add_geometry("scene", o3d.t.io.read_point_cloud(args.scene))
    views = o3d.camera.read_cameras_json(args.cameras)
    dtype = "float32" if args.formats == "npy-float32" else "uint8"
    buf = r.batch_array(args.batch, dtype)
    for job in jobs:
        for first in range(0, len(job.views), args.batch):
            chunk = job.views[first:first + args.batch]
            images = r.render_batch([views[v].camera for v in chunk], dtype, out=buf[:len(chunk)], rescale=True)
            if args.formats != "none":
                folder = out / "one" / job.name
                folder.mkdir(parents=True, exist_ok=True)
                for i, v in enumerate(chunk):
                    if args.formats == "png":
                        write_png(str(folder / f"view_{v:03d}.png"), images[i, ..., :3])
                    else:
                        write_npy(str(folder / f"view_{v:03d}.npy"), images[i])
    seconds = time.monotonic() - start
    n = sum(len(j.views) for j in jobs)
    print(f"(i) one process, render_batch in batches of {args.batch}: {n / seconds:.1f} views/s "
          f"({n} views in {seconds:.2f} s, {r.backend} backend)", flush=True)


def on_dask(args, jobs, workers, out):
    from dask.distributed import Client, LocalCluster

    folder_jobs = []
    for job in jobs:
        fmt = {"none": (), "png": ("png",), "npy": ("npy",), "npy-float32": ("npy",)}[args.formats]
        folder_jobs.append(Job(job.scene, job.cameras, views=job.views, width=args.size[0], height=args.size[1],
                               folder=str(out / f"dask{workers}" / job.name) if fmt else None, formats=fmt,
                               dtype="float32" if args.formats == "npy-float32" else "uint8", name=job.name))
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                      silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
        client.wait_for_workers(workers)
        report = render_jobs(client, folder_jobs, batch=args.batch, backend=args.backend, progress=lambda line: None)
    if not report.ok:
        sys.exit("dask run failed: " + "; ".join(f"{j.name}: {j.error}" for j in report.jobs if j.error))
    print(f"(ii) dask, {workers} worker processes, batches of {args.batch}: {report.views_per_second:.1f} views/s "
          f"({report.views} views in {report.seconds:.2f} s)", flush=True)
    for line in report.summary_lines()[:-1]:
        print("     " + line, flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene")
    parser.add_argument("cameras")
    parser.add_argument("--size", type=int, nargs=2, default=(800, 800), metavar=("W", "H"))
    parser.add_argument("--jobs", type=int, default=4, help="jobs of the same scene (default 4)")
    parser.add_argument("--views", type=int, default=24, help="views per job: the first VIEWS of cameras.json (default 24)")
    parser.add_argument("--batch", type=int, default=8, help="views per render_batch call (default 8)")
    parser.add_argument("--workers", default="1,2", help="worker counts to run, comma-separated (default 1,2)")
    parser.add_argument("--formats", default="none", choices=["none", "png", "npy", "npy-float32"],
                        help="what each view writes (default none: render only)")
    parser.add_argument("--output", help="folder for the files (default: a temporary folder, removed)")
    parser.add_argument("--backend", default="vulkan", choices=["vulkan", "cpu"])
    parser.add_argument("--skip-one-process", action="store_true", help="only the Dask runs")
    args = parser.parse_args()
    # The local cluster's workers are spawned processes: they import open3d_gs from here.
    parent = os.path.dirname(os.path.dirname(os.path.abspath(o3d.__file__)))
    os.environ["PYTHONPATH"] = os.pathsep.join([parent, os.environ.get("PYTHONPATH", "")])
    count = len(o3d.camera.read_cameras_json(args.cameras))
    if args.views > count:
        parser.error(f"--views {args.views}: {args.cameras} has {count} views")
    jobs = [Job(os.path.abspath(args.scene), os.path.abspath(args.cameras), views=list(range(args.views)),
                name=f"job{k:03d}") for k in range(args.jobs)]
    with tempfile.TemporaryDirectory() as tmp:
        out = pathlib.Path(args.output or tmp)
        print(f"{args.jobs} jobs x {args.views} views of {os.path.basename(args.scene)} at "
              f"{args.size[0]}x{args.size[1]}, formats {args.formats}, {os.cpu_count()} cores", flush=True)
        if not args.skip_one_process:
            one_process(args, jobs, out)
        for workers in (int(w) for w in args.workers.split(",") if w):
            on_dask(args, jobs, workers, out)


if __name__ == "__main__":
    main()
