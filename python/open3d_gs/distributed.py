"""Renders sets of views of many scenes across a Dask `distributed` cluster (docs/distributed.md).

    from dask.distributed import Client
    from open3d_gs.distributed import Job, render_jobs
    with Client("tcp://scheduler:8786") as client:
        report = render_jobs(client, [Job("scene.ply", "cameras.json", width=800, height=800,
                                          folder="out/scene", formats=("png",))])
    print("\\n".join(report.summary_lines()))

Each usable worker gets one long-lived actor (SceneRenderer) holding an OffscreenRenderer per
scene, so a scene is read and uploaded once per worker and reused for all its views. A job's
views go out in batches (render_batch), at most `calls_per_worker` batches queued per actor;
an idle actor takes a batch of a scene it holds first. A worker that leaves the cluster (a
crash, a kill) loses its batches, which go back to the queue and are rendered by another
worker (or the restarted one), up to `retries` times. A job whose scene or cameras cannot be
read fails alone with the message; the other jobs finish.

Command line: python3 -m open3d_gs.distributed --help.
"""
import dataclasses
import os
import sys
import time
import uuid

from ._distributed_jobs import Job, JobFileError, check_jobs, read_jobs
from ._distributed_worker import SceneRenderer

__all__ = ["Job", "JobFileError", "JobResult", "Report", "SceneRenderer", "read_jobs", "render_jobs", "main"]


@dataclasses.dataclass
class JobResult:
    """How one job ended: error is None when every view was rendered; images (with
    return_arrays) is (N, H, W, 4) in the order of `views`."""

    job: Job
    views: list
    error: str = None
    seconds: float = 0.0
    images: object = None

    @property
    def name(self):
        """The job's name."""
        return self.job.name


@dataclasses.dataclass
class WorkerStats:
    """What one worker did. busy_s is the time inside its render calls (scene loads, renders
    and file writes); views_per_second is views / busy_s."""

    address: str
    pid: int = None
    host: str = None
    views: int = 0
    batches: int = 0
    loads: int = 0
    load_s: float = 0.0
    busy_s: float = 0.0
    lost: str = None  # why the worker was lost, if it was

    @property
    def views_per_second(self):
        """Views over the seconds inside this worker's render calls."""
        return self.views / self.busy_s if self.busy_s > 0 else 0.0


@dataclasses.dataclass
class Report:
    """The outcome of render_jobs: per job, per worker, and in total (views / wall seconds from
    the first batch sent to the last result)."""

    jobs: list
    workers: dict
    seconds: float = 0.0
    views: int = 0
    retried_views: int = 0

    @property
    def ok(self):
        """Whether every job rendered all its views."""
        return all(j.error is None for j in self.jobs)

    @property
    def views_per_second(self):
        """Views over the run's wall time (from the first batch sent to the last result)."""
        return self.views / self.seconds if self.seconds > 0 else 0.0

    @property
    def lost_workers(self):
        """The addresses of the workers lost during the run."""
        return [w.address for w in self.workers.values() if w.lost]

    def summary_lines(self):
        """A line per worker that rendered or was lost, a line per failed job, and the total."""
        lines = []
        for w in self.workers.values():
            if not w.batches and not w.lost:
                continue  # joined too late to get work (a restarted worker, say)
            lost = f", lost: {w.lost}" if w.lost else ""
            lines.append(f"worker {w.address} (pid {w.pid} on {w.host}): {w.views} views in {w.busy_s:.2f} s busy "
                         f"({w.views_per_second:.1f} views/s), {w.loads} scene loads ({w.load_s:.2f} s){lost}")
        failed = sum(j.error is not None for j in self.jobs)
        lines.extend(f"FAILED {j.name}: {j.error}" for j in self.jobs if j.error is not None)
        lines.append(f"total: {self.views} views in {self.seconds:.2f} s ({self.views_per_second:.1f} views/s) on "
                     f"{sum(w.views > 0 for w in self.workers.values())} workers; {len(self.jobs) - failed} jobs done, {failed} failed; "
                     f"{len(self.lost_workers)} workers lost, {self.retried_views} views rendered again")
        return lines

    def to_dict(self):
        """The report as JSON-ready values (the command's --report file)."""
        return {"ok": self.ok, "seconds": self.seconds, "views": self.views,
                "views_per_second": self.views_per_second, "retried_views": self.retried_views,
                "jobs": [{"name": j.name, "views": len(j.views), "error": j.error, "seconds": j.seconds,
                          "folder": j.job.folder} for j in self.jobs],
                "workers": [dict(dataclasses.asdict(w), views_per_second=w.views_per_second)
                            for w in self.workers.values()]}


# The dataclasses' generated constructors say what they take (the package documents every
# public callable, python/test/test_package.py).
for _cls in (JobResult, WorkerStats, Report):
    _cls.__init__.__doc__ = f"A {_cls.__name__} from its fields, as the class describes them."


class _Batch:
    def __init__(self, state, views):
        self.state, self.views, self.attempts = state, views, 0


class _JobState:
    def __init__(self, job, index):
        self.job, self.index = job, index
        self.spec = None  # Job's fields as a dict, width and height set, for the actor
        self.result = JobResult(job=job, views=[])
        self.remaining = 0
        self.images = None
        self.started = None

    @property
    def key(self):
        return (self.spec["scene"], self.spec["width"], self.spec["height"])

    @property
    def finished(self):
        return self.result.error is not None or (self.spec is not None and self.remaining == 0)


def _plan(state, protected):
    """Reads the job's cameras.json here (the client) to know its views and default size;
    a failure fails this job alone."""
    from . import camera

    job = state.job
    try:
        cameras = camera.read_cameras_json(job.cameras)
    except Exception as e:  # noqa: BLE001 - the job fails with the library's message
        state.result.error = f"cameras: {type(e).__name__}: {e}"
        return False
    views = list(range(len(cameras))) if job.views == "all" else job.views
    bad = [v for v in views if v >= len(cameras)]
    if bad:
        state.result.error = f"views: {job.cameras} has {len(cameras)} views (0..{len(cameras) - 1}); asked for {bad}"
        return False
    for v in views:
        for f in job.output_files(v):
            if os.path.realpath(f) in protected:
                state.result.error = f"output {f} would overwrite {protected[os.path.realpath(f)]}"
                return False
    width = job.width or cameras[views[0]].camera.width
    height = job.height or cameras[views[0]].camera.height
    # Absolute paths: a worker's working folder need not be the client's.
    absolute = {k: os.path.abspath(getattr(job, k)) for k in ("scene", "cameras", "folder") if getattr(job, k)}
    state.spec = dict(dataclasses.asdict(job), views=None, width=width, height=height, **absolute)
    state.result.views = views
    state.remaining = len(views)
    return True


class _Pool:
    """The actors, one per usable worker, made as workers appear and dropped as they leave."""

    def __init__(self, client, backend, cache_scenes, hook, resources, say):
        self.client, self.backend, self.cache_scenes, self.hook = client, backend, cache_scenes, hook
        self.resources, self.say = resources, say
        self.members = {}  # address -> dict(actor, future, inflight, scenes, stats)
        self.unusable = {}  # address -> why its actor could not be made
        self.stats = {}

    def _wanted(self, info):
        """The workers to use and the resources to ask of each: with resources="auto", the
        workers that declare a GPU resource if any does, else all."""
        declared = {a: w.get("resources") or {} for a, w in info.items()}
        if self.resources == "auto":
            gpu = {a for a, r in declared.items() if r.get("GPU", 0) >= 1}
            return (gpu, {"GPU": 1}) if gpu else (set(declared), None)
        if not self.resources:
            return set(declared), None
        ok = {a for a, r in declared.items() if all(r.get(k, 0) >= v for k, v in self.resources.items())}
        return ok, dict(self.resources)

    def refresh(self):
        try:  # every worker: Dask since 2025 lists 5 unless told (older Dask ignores the argument)
            info = self.client.scheduler_info(n_workers=-1)["workers"]
        except TypeError:
            info = self.client.scheduler_info()["workers"]
        lost = []
        for address in list(self.members):
            if address not in info:
                lost.append(self.lose(address, "it left the cluster"))
        wanted, resources = self._wanted(info)
        for address in sorted(wanted - set(self.members) - set(self.unusable)):
            future = self.client.submit(SceneRenderer, self.backend, self.cache_scenes, self.hook, actor=True,
                                        workers=[address], allow_other_workers=False, resources=resources,
                                        pure=False, key=f"open3d-gs-renderer-{uuid.uuid4().hex}")
            self.members[address] = {"actor": None, "future": future, "inflight": {}, "scenes": []}
            self.stats[address] = WorkerStats(address=address)
        for address, m in list(self.members.items()):
            if m["actor"] is None and m["future"].status == "finished":
                try:
                    m["actor"] = m["future"].result(timeout=60)
                    m["describe"] = m["actor"].describe()
                except Exception as e:  # noqa: BLE001 - gone between the status and the result
                    lost.append(self.lose(address, f"{type(e).__name__}: {e}"))
                    continue
            elif m.get("describe") is not None and m["describe"].done():
                try:
                    where = m.pop("describe").result()
                except Exception:  # noqa: BLE001 - its loss shows in the next refresh or call
                    continue
                self.stats[address].pid, self.stats[address].host = where["pid"], where["host"]
                self.say(f"worker {address} ready (pid {where['pid']} on {where['host']}, {self.backend} backend)")
            elif m["actor"] is None and m["future"].status == "error":
                why = f"{type(m['future'].exception()).__name__}: {m['future'].exception()}"
                self.unusable[address] = why
                del self.members[address]
                del self.stats[address]
                self.say(f"worker {address} cannot render, not used: {why}")
        return [b for batches in lost for b in batches]

    def lose(self, address, why):
        """Drops a worker's actor; returns the batches it had not finished."""
        m = self.members.pop(address)
        batches = [batch for batch, _ in m["inflight"].values()]
        self.stats[address].lost = why
        self.client.cancel([m["future"]])
        views = sum(len(b.views) for b in batches)
        self.say(f"worker {address} lost ({why}): {len(batches)} batches ({views} views) go back to the queue")
        return batches

    def ready(self):
        return [(a, m) for a, m in self.members.items() if m["actor"] is not None]


def _pick(queue, member, pool, cache_scenes):
    """The next batch for a worker: one of a scene it holds, else one of the scene that the
    fewest workers hold (so that workers spread over jobs before sharing one)."""
    for i, batch in enumerate(queue):
        if batch.state.key in member["scenes"]:
            member["scenes"].remove(batch.state.key)
            member["scenes"].append(batch.state.key)  # most recently used, as in the actor
            return queue.pop(i)
    holders = {}
    for _, m in pool.ready():
        for key in m["scenes"]:
            holders[key] = holders.get(key, 0) + 1
    best = min(range(len(queue)), key=lambda i: (holders.get(queue[i].state.key, 0), i))
    batch = queue.pop(best)
    member["scenes"].append(batch.state.key)
    del member["scenes"][:-cache_scenes]  # the actor keeps the most recent cache_scenes
    return batch


def render_jobs(client, jobs, *, batch=8, retries=3, backend="vulkan", resources="auto",
                return_arrays=False, progress=None, worker_hook=None, cache_scenes=2,
                calls_per_worker=4, worker_wait=600.0, timeout=None, poll=0.005, protect=()):
    """Renders `jobs` (Job records) on the workers of `client`; returns a Report.

    batch: views per render_batch call; retries: how often a batch lost with its worker (or
    failed in rendering or writing) is sent again before its job fails; resources: "auto"
    (use the workers that declare a GPU resource, one GPU each, if any does, else all), None
    (all workers) or a dict such as {"GPU": 1}; return_arrays: put each job's images in its
    JobResult (they travel to the client); progress: called with each progress line (None:
    printed to stderr); worker_hook: see SceneRenderer; worker_wait: seconds to wait for a
    usable worker when there is none before failing what is left; timeout: seconds after which
    unfinished jobs fail (None: no limit); protect: files no output may overwrite (the job
    lists). A job whose scene or cameras cannot be read fails alone.
    """
    say = progress or (lambda line: print(line, file=sys.stderr, flush=True))
    protected = check_jobs(list(jobs), protect)
    states = [_JobState(job, i) for i, job in enumerate(jobs)]
    queue = []
    for s in states:
        if _plan(s, protected):
            views = s.result.views
            queue.extend(_Batch(s, views[i:i + batch]) for i in range(0, len(views), batch))
        else:
            say(f"job {s.job.name} FAILED: {s.result.error}")
    pool = _Pool(client, backend, cache_scenes, worker_hook, resources, say)
    report = Report(jobs=[s.result for s in states], workers=pool.stats)
    start = time.monotonic()
    first_sent = None  # the report's seconds run from here: actor start-up is not rendering
    next_refresh, no_worker_since = 0.0, None

    def requeue(batches):
        for b in batches:
            if b.state.finished:
                continue
            b.attempts += 1
            report.retried_views += len(b.views)
            if b.attempts > retries:
                fail(b.state, f"views {b.views} were lost {b.attempts} times (last: its worker left)")
            else:
                queue.insert(0, b)

    def fail(state, error):
        if state.result.error is None:
            state.result.error = error
            state.result.seconds = time.monotonic() - (state.started or start)
            queue[:] = [b for b in queue if b.state is not state]
            say(f"job {state.job.name} FAILED: {error}")

    def finish(b, address, out):
        st = pool.stats[address]
        st.busy_s += out["load_s"] + out["render_s"] + out["write_s"]
        if out["loaded"]:
            st.loads += 1
            st.load_s += out["load_s"]
        state = b.state
        if out["error"] is not None:
            if out["phase"] == "load":
                fail(state, f"{out['phase']}: {out['error']}")
            elif not state.finished:
                b.attempts += 1
                report.retried_views += len(b.views)
                if b.attempts > retries:
                    fail(state, f"{out['phase']}: {out['error']} ({b.attempts} attempts)")
                else:
                    say(f"job {state.job.name}: views {b.views} failed on {address} ({out['error']}), sent again")
                    queue.insert(0, b)
            return
        st.views += len(out["views"])
        st.batches += 1
        if state.finished:
            return
        report.views += len(out["views"])
        if return_arrays:
            if state.images is None:
                import numpy as np

                shape = (len(state.result.views),) + out["arrays"].shape[1:]
                state.images = np.empty(shape, out["arrays"].dtype)
            at = {v: i for i, v in enumerate(state.result.views)}
            for i, v in enumerate(out["views"]):
                state.images[at[v]] = out["arrays"][i]
        state.remaining -= len(out["views"])
        if state.remaining == 0:
            state.result.seconds = time.monotonic() - state.started
            state.result.images = state.images
            n, spec = len(state.result.views), state.spec
            where = f" into {spec['folder']}" if spec["folder"] and spec["formats"] else ""
            say(f"job {state.job.name}: {n} views at {spec['width']}x{spec['height']} done in "
                f"{state.result.seconds:.2f} s ({n / max(state.result.seconds, 1e-9):.1f} views/s){where}")

    while not all(s.finished for s in states):
        now = time.monotonic()
        if now >= next_refresh:
            requeue(pool.refresh())
            next_refresh = now + 0.5
        progressed = False
        for address, m in pool.ready():
            for key, (b, future) in list(m["inflight"].items()):
                if not future.done():
                    continue
                del m["inflight"][key]
                try:
                    out = future.result()
                except Exception as e:  # noqa: BLE001 - the worker is unreachable or gone
                    m["inflight"][key] = (b, future)  # counted with the worker's other batches
                    requeue(pool.lose(address, f"{type(e).__name__}: {e}"))
                    break
                finish(b, address, out)
                progressed = True
        for address, m in pool.ready():
            while queue and len(m["inflight"]) < calls_per_worker:
                b = _pick(queue, m, pool, cache_scenes)
                if b.state.started is None:
                    b.state.started = time.monotonic()
                first_sent = first_sent or b.state.started
                try:
                    future = m["actor"].render(b.state.spec, b.views, return_arrays)
                except Exception as e:  # noqa: BLE001 - "Worker holding Actor was lost"
                    queue.insert(0, b)
                    requeue(pool.lose(address, f"{type(e).__name__}: {e}"))
                    break
                m["inflight"][uuid.uuid4().hex] = (b, future)
                progressed = True
        if pool.members:
            no_worker_since = None
        elif no_worker_since is None:
            no_worker_since = now
        elif now - no_worker_since > worker_wait:
            why = "; ".join(f"{a}: {w}" for a, w in pool.unusable.items()) or "the cluster has no workers"
            for s in states:
                if not s.finished:
                    fail(s, f"no worker could render for {worker_wait:.0f} s ({why})")
        if timeout is not None and now - start > timeout:
            for s in states:
                if not s.finished:
                    fail(s, f"not finished after {timeout:g} s")
        if not progressed:
            time.sleep(poll)
    report.seconds = time.monotonic() - (first_sent or start)
    for address, m in list(pool.members.items()):
        client.cancel([m["future"]])
    return report


def main(argv=None):
    """The command `python3 -m open3d_gs.distributed` (its --help); returns the exit status."""
    from ._distributed_cli import main as cli_main

    return cli_main(argv)


if __name__ == "__main__":
    # Through the package's module (not this __main__ copy), so that pickled classes name it.
    from open3d_gs.distributed import main as _main

    sys.exit(_main())
