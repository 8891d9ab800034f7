"""Job lists of open3d_gs.distributed: the Job record and the JSON / CSV readers.

Kept apart from the Dask code so that a job file can be checked (and its errors reported with
the file and the field) without a cluster, and so that worker processes unpickle Job from a
module that does not import dask.distributed's client side.
"""
import csv
import dataclasses
import json
import os
import pathlib
import re

FORMATS = ("png", "npy")
DTYPES = ("uint8", "float32")
MAX_SIDE = 16384  # far above any real view; stops a typo such as 80000 from allocating GBs
JOB_KEYS = ("name", "scene", "cameras", "views", "resolution", "output")
OUTPUT_KEYS = ("folder", "formats", "dtype")
CSV_COLUMNS = ("name", "scene", "cameras", "views", "resolution", "folder", "formats", "dtype")


class JobFileError(ValueError):
    """A job list that cannot be used; the message names the file and the field."""


@dataclasses.dataclass
class Job:
    """One scene and the views to render of it.

    scene: a splat file (any format open3d_gs.t.io.read_point_cloud reads); cameras: a 3DGS
    cameras.json; views: "all" or view indices into cameras.json; width, height: the image
    size (None: the first view's size; cameras of another size are scaled); folder: where
    view_NNN.png / view_NNN.npy go (None: nothing is written); formats: any of "png" (8-bit
    RGB) and "npy" (the (H, W, 4) array of dtype); dtype: "uint8" or "float32" for the npy
    files and the returned arrays.
    """

    scene: str
    cameras: str
    views: object = "all"
    width: int = None
    height: int = None
    folder: str = None
    formats: tuple = ("png",)
    dtype: str = "uint8"
    name: str = None

    def output_files(self, view):
        """The files this job writes for one view (none without a folder)."""
        if self.folder is None:
            return []
        return [os.path.join(self.folder, f"view_{view:03d}.{fmt}") for fmt in self.formats]


Job.__init__.__doc__ = "A Job from its fields, as the class describes them."


def _parse_views(value, where):
    if value is None or value == "all" or value == "":  # "": an empty CSV cell
        return "all"
    if isinstance(value, str):
        # "0 1 2", "0;1;2", "0,1,2" and ranges "0-7" (inclusive), as written in a CSV cell.
        views = []
        for part in re.split(r"[\s;,]+", value.strip()):
            m = re.fullmatch(r"(\d+)(?:-(\d+))?", part)
            if not m or (m.group(2) is not None and int(m.group(2)) < int(m.group(1))):
                raise JobFileError(f'{where}: expected "all", view indices or ranges such as "0-7", got {value!r}')
            last = int(m.group(2) if m.group(2) is not None else m.group(1))
            views.extend(range(int(m.group(1)), last + 1))
        value = views
    if not isinstance(value, list) or not value or not all(isinstance(v, int) and not isinstance(v, bool) and v >= 0 for v in value):
        raise JobFileError(f'{where}: expected "all" or a non-empty list of view indices (integers >= 0), got {value!r}')
    if len(set(value)) != len(value):
        raise JobFileError(f"{where}: view {next(v for v in value if value.count(v) > 1)} is listed twice")
    return list(value)


def _parse_resolution(value, where):
    if value is None or value == "":
        return None, None
    if isinstance(value, str):
        m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", value)
        value = [int(m.group(1)), int(m.group(2))] if m else value
    if (not isinstance(value, list) or len(value) != 2
            or not all(isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= MAX_SIDE for v in value)):
        raise JobFileError(f'{where}: expected [width, height] or "WIDTHxHEIGHT" with sides 1..{MAX_SIDE}, got {value!r}')
    return value[0], value[1]


def _parse_formats(value, where):
    if value is None:
        return ("png",)
    if isinstance(value, str):
        value = [f for f in re.split(r"[\s;,]+", value.strip()) if f]
    if not isinstance(value, list) or any(f not in FORMATS for f in value) or len(set(value)) != len(value):
        raise JobFileError(f"{where}: expected a list of distinct formats from {list(FORMATS)}, got {value!r}")
    return tuple(value)


def _string(value, where, required):
    if value is None or value == "":
        if required:
            raise JobFileError(f"{where}: missing (a path is required)")
        return None
    if not isinstance(value, str):
        raise JobFileError(f"{where}: expected a string, got {value!r}")
    return value


def _resolve(path, base):
    """Relative paths in a job file are relative to the job file's folder."""
    return None if path is None else str((base / os.path.expanduser(path)).resolve())


def make_job(fields, where, base):
    """A Job from one entry's fields (JSON object or CSV row); `where` prefixes every error."""
    scene = _resolve(_string(fields.get("scene"), f"{where}.scene", True), base)
    cameras = _resolve(_string(fields.get("cameras"), f"{where}.cameras", True), base)
    width, height = _parse_resolution(fields.get("resolution"), f"{where}.resolution")
    out = fields.get("output", {})
    if not isinstance(out, dict):
        raise JobFileError(f"{where}.output: expected an object with {list(OUTPUT_KEYS)}, got {out!r}")
    for key in out:
        if key not in OUTPUT_KEYS:
            raise JobFileError(f"{where}.output.{key}: unknown field (known: {', '.join(OUTPUT_KEYS)})")
    formats = _parse_formats(out.get("formats"), f"{where}.output.formats")
    dtype = out.get("dtype") or "uint8"
    if dtype not in DTYPES:
        raise JobFileError(f"{where}.output.dtype: expected one of {list(DTYPES)}, got {dtype!r}")
    folder = _resolve(_string(out.get("folder"), f"{where}.output.folder", bool(formats)), base)
    name = _string(fields.get("name"), f"{where}.name", False)
    return Job(scene=scene, cameras=cameras, views=_parse_views(fields.get("views"), f"{where}.views"),
               width=width, height=height, folder=folder, formats=formats, dtype=dtype, name=name)


def _read_json(path):
    try:
        doc = json.loads(path.read_text())
    except json.JSONDecodeError as e:
        raise JobFileError(f"{path}: not valid JSON: {e}") from None
    entries, prefix = doc, "jobs"
    if isinstance(doc, dict):
        for key in doc:
            if key != "jobs":
                raise JobFileError(f"{path}: {key}: unknown top-level field (expected a list of jobs or {{\"jobs\": [...]}})")
        entries = doc.get("jobs")
    else:
        prefix = ""
    if not isinstance(entries, list) or not entries:
        raise JobFileError(f"{path}: expected a non-empty list of jobs or {{\"jobs\": [...]}}")
    jobs = []
    for i, entry in enumerate(entries):
        where = f"{path}: {prefix}[{i}]"
        if not isinstance(entry, dict):
            raise JobFileError(f"{where}: expected an object with {list(JOB_KEYS)}, got {entry!r}")
        for key in entry:
            if key not in JOB_KEYS:
                raise JobFileError(f"{where}.{key}: unknown field (known: {', '.join(JOB_KEYS)})")
        jobs.append(make_job(entry, where, path.parent))
    return jobs


def _read_csv(path):
    with path.open(newline="") as f:
        rows = list(csv.DictReader(f))
        header = rows[0].keys() if rows else []
    if not rows:
        raise JobFileError(f"{path}: no jobs (a header row {','.join(CSV_COLUMNS)} and a row per job)")
    for column in header:
        if column not in CSV_COLUMNS:
            raise JobFileError(f"{path}: column {column!r}: unknown (known: {', '.join(CSV_COLUMNS)})")
    jobs = []
    for i, row in enumerate(rows):
        if None in row:
            raise JobFileError(f"{path}: row {i + 2}: more cells than the header has columns")
        fields = {k: (v.strip() if isinstance(v, str) else v) for k, v in row.items() if k in JOB_KEYS}
        fields["output"] = {k: row[k].strip() for k in OUTPUT_KEYS if row.get(k) is not None and row[k].strip()}
        if row.get("formats") is not None and not row["formats"].strip():
            fields["output"]["formats"] = []  # an empty cell: render without writing
        jobs.append(make_job(fields, f"{path}: row {i + 2}", path.parent))
    return jobs


def read_jobs(path):
    """The jobs of a .json or .csv job list (docs/distributed.md "Job lists")."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise JobFileError(f"{path}: no such job file")
    if path.suffix.lower() == ".csv":
        return _read_csv(path)
    return _read_json(path)


def check_jobs(jobs, inputs=()):
    """Names every job uniquely and refuses outputs that would overwrite an input or another
    job's output. `inputs` are further files that must not be written (the job lists)."""
    seen = {}
    for i, job in enumerate(jobs):
        if job.name is None:
            stem = pathlib.Path(job.scene).stem
            job.name = stem if stem not in seen else f"{stem}-{i}"
        if job.name in seen:
            raise JobFileError(f"job {i}: name {job.name!r} is also job {seen[job.name]}'s")
        seen[job.name] = i
    protected = {os.path.realpath(p): f"job list {p}" for p in inputs}
    for job in jobs:
        protected[os.path.realpath(job.scene)] = f"job {job.name!r}'s scene"
        protected[os.path.realpath(job.cameras)] = f"job {job.name!r}'s cameras"
    writers = {}
    for job in jobs:
        if job.folder is not None and os.path.exists(job.folder) and not os.path.isdir(job.folder):
            raise JobFileError(f"job {job.name!r}: output.folder {job.folder} is a file, not a folder")
        views = job.views if job.views != "all" else None
        if job.folder is None:
            continue
        for fmt in job.formats:
            # Every job writes view_NNN.<fmt>: two jobs with one folder and a format in common
            # would write the same names (with "all" views, any view may collide).
            key = (os.path.realpath(job.folder), fmt)
            for other, other_views in writers.get(key, []):
                if views is None or other_views is None or set(views) & set(other_views):
                    raise JobFileError(f"jobs {other!r} and {job.name!r} write the same {fmt} files into {job.folder}")
            writers.setdefault(key, []).append((job.name, views))
        for view in views or []:
            for f in job.output_files(view):
                if os.path.realpath(f) in protected:
                    raise JobFileError(f"job {job.name!r}: output {f} would overwrite {protected[os.path.realpath(f)]}")
    # With "all" views the names are only known once cameras.json is read: the same check
    # runs again per view before rendering (distributed.plan_jobs).
    return protected
