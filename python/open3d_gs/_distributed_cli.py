"""The command `python3 -m open3d_gs.distributed` (docs/distributed.md)."""
import argparse
import json
import logging
import os
import pathlib
import sys

from ._distributed_jobs import JobFileError, check_jobs, read_jobs

DESCRIPTION = """\
Renders the views of every job in JOBS (.json or .csv job lists) on a Dask cluster: one
renderer (a Dask actor) per worker keeps each scene loaded across its views, views go out in
batches through render_batch, and each job writes view_NNN.png (8-bit RGB) and/or
view_NNN.npy (the (H, W, 4) array of its dtype) into its folder. Workers must see the scene,
cameras and output paths at the same names (a shared file system) and import open3d_gs.

Prints a line per finished or failed job and a summary (views/s per worker: views over the
seconds spent in its render calls; in total: views over the run's wall time). A batch lost
with its worker is rendered again elsewhere (--retries); a job whose scene or cameras cannot
be read fails alone (the summary repeats each failure). Exit status: 0 every job done, 1 a
job failed or the cluster could not be used, 2 a bad command line or job list (nothing
rendered).
"""

EPILOG = """\
JSON job list: a list of jobs, or {"jobs": [...]}. A job:
  {"name": "robot",                        optional; default: the scene's file name
   "scene": "playbot_31k.ply",             required; any format the library reads
   "cameras": "cameras.json",              required; a 3DGS cameras.json
   "views": "all",                         or [0, 5, 7] or "0-7 12"; default "all"
   "resolution": [800, 800],               or "800x800"; default: the first view's size
   "output": {"folder": "out/robot",       required when formats is not empty
              "formats": ["png", "npy"],   default ["png"]; [] renders without writing
              "dtype": "uint8"}}           or "float32" (for .npy); default "uint8"
CSV job list: a header row naming some of name,scene,cameras,views,resolution,folder,
formats,dtype and a row per job (views "all" or "0-7 12"; formats "png npy").
Relative paths are relative to the job list's folder. Unknown fields are errors. Outputs
that would overwrite an input (a scene, a cameras file, a job list) or another job's output
are refused before anything renders; with "views": "all" the file names are known once
cameras.json is read, and such a job fails alone.
"""


def _parser():
    p = argparse.ArgumentParser(prog="python3 -m open3d_gs.distributed", description=DESCRIPTION,
                                epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("jobs", nargs="+", metavar="JOBS", help="job lists (.json or .csv; format below)")
    where = p.add_mutually_exclusive_group(required=True)
    where.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask scheduler, e.g. tcp://host:8786")
    where.add_argument("--scheduler-file", metavar="FILE", help="the file `dask scheduler --scheduler-file FILE` wrote")
    where.add_argument("--local-workers", type=int, metavar="N",
                       help="start a local cluster of N worker processes (one thread each) for this run")
    p.add_argument("--batch", type=int, default=8, help="views per render_batch call (default 8)")
    p.add_argument("--retries", type=int, default=3,
                   help="times a batch lost with its worker, or failed in rendering or writing, is sent again "
                        "before its job fails (default 3)")
    p.add_argument("--backend", choices=["vulkan", "cpu"], default="vulkan",
                   help="vulkan (lavapipe where there is no GPU; default) or the CPU reference")
    p.add_argument("--resources", default="auto", metavar="auto|none|NAME=AMOUNT[,...]",
                   help="auto (default): if any worker declares a GPU resource (dask worker --resources GPU=1), "
                        "use only those, one GPU each, else every worker; none: every worker; NAME=AMOUNT: "
                        "only workers that declare at least that")
    p.add_argument("--cache-scenes", type=int, default=2, help="scenes each worker keeps loaded (default 2)")
    p.add_argument("--worker-wait", type=float, default=600.0, metavar="SECONDS",
                   help="how long to wait for a usable worker when there is none before failing the rest (default 600)")
    p.add_argument("--report", metavar="FILE", help="also write the summary as JSON to FILE")
    p.add_argument("--check", action="store_true", help="read and check the job lists, print the jobs, render nothing")
    p.add_argument("--quiet", action="store_true", help="no per-job or per-worker lines, only the summary")
    return p


def _resources(text, parser):
    if text == "auto":
        return "auto"
    if text == "none":
        return None
    out = {}
    for part in text.split(","):
        name, _, amount = part.partition("=")
        try:
            out[name.strip()] = float(amount)
        except ValueError:
            parser.error(f"--resources: {part!r} is not NAME=AMOUNT (or auto, none)")
        if not name.strip():
            parser.error(f"--resources: {part!r} has no name")
    return out


def _client(args):
    from dask.distributed import Client, LocalCluster

    if args.local_workers is not None:
        # Spawned workers import open3d_gs from where this process did.
        package_parent = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        paths = os.environ.get("PYTHONPATH", "").split(os.pathsep)
        if package_parent not in paths:
            os.environ["PYTHONPATH"] = os.pathsep.join([package_parent] + [p for p in paths if p])
        cluster = LocalCluster(n_workers=args.local_workers, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.ERROR)
        return Client(cluster), cluster
    if args.scheduler_file:
        return Client(scheduler_file=args.scheduler_file), None
    return Client(args.scheduler), None


def main(argv=None):
    parser = _parser()
    args = parser.parse_args(argv)
    for name in ("batch", "local_workers", "cache_scenes"):
        value = getattr(args, name)
        if value is not None and value < 1:
            parser.error(f"--{name.replace('_', '-')} must be at least 1, got {value}")
    if args.retries < 0:
        parser.error(f"--retries must be at least 0, got {args.retries}")
    resources = _resources(args.resources, parser)
    say = (lambda line: None) if args.quiet else (lambda line: print(line, file=sys.stderr, flush=True))
    try:
        jobs = [job for path in args.jobs for job in read_jobs(path)]
        protected = check_jobs(jobs, args.jobs)
        if args.report and os.path.realpath(args.report) in protected:
            raise JobFileError(f"--report {args.report} would overwrite {protected[os.path.realpath(args.report)]}")
    except JobFileError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if args.check:
        for job in jobs:
            print(json.dumps({k: v for k, v in vars(job).items()}))
        return 0

    from .distributed import render_jobs

    try:
        client, cluster = _client(args)
    except Exception as e:  # noqa: BLE001 - OSError, TimeoutError, ... with the address in it
        print(f"error: cannot use the Dask cluster: {type(e).__name__}: {e}", file=sys.stderr)
        return 1
    try:
        report = render_jobs(client, jobs, batch=args.batch, retries=args.retries, backend=args.backend,
                             resources=resources, progress=say, cache_scenes=args.cache_scenes,
                             worker_wait=args.worker_wait, protect=args.jobs)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    for line in report.summary_lines():
        print(line, flush=True)
    if args.report:
        pathlib.Path(args.report).write_text(json.dumps(report.to_dict(), indent=1) + "\n")
    return 0 if report.ok else 1
