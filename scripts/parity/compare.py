#!/usr/bin/env python3
"""Measures how closely gs-render matches the original 3DGS CUDA rasterizer.

For every scene and view, the original's render (render_original.py, in this process)
is compared with gs-render's (one process per view and backend, --float-output to a
temp dir) on RGB: PSNR with peak 1, max abs error, the share of values off by more
than 1/255, and the worst pixel. Writes every view to --json and prints a markdown
summary per scene and backend (also written to --md with the per-view rows).

--crop-check re-cuts the crops of SHARED/data/parity from fresh renders of the
original and reports how far they are from the stored ones, which shows that the
inputs here follow the convention that produced them.
"""

import argparse
import json
import math
import shlex
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import render_original as ro  # noqa: E402

ONE_LSB = 1.0 / 255.0
PSNR_BAR_DB = 100.0


# ----------------------------------------------------------------------- metrics


def compare_images(ref, ours):
    """RGB error of ours against ref, both float [H, W, 3]."""
    if ref.shape != ours.shape:
        raise ValueError(f"shape mismatch: reference {ref.shape}, ours {ours.shape}")
    diff = ours.astype(np.float64) - ref.astype(np.float64)
    non_finite = int(np.count_nonzero(~np.isfinite(diff)))
    diff = np.nan_to_num(diff, nan=np.inf)  # a NaN must count as the worst error
    abs_err = np.abs(diff)
    mse = float(np.mean(diff * diff))
    per_pixel = abs_err.max(axis=2)
    y, x = np.unravel_index(int(np.argmax(per_pixel)), per_pixel.shape)
    return {
        # None when the images are identical (infinite PSNR); JSON has no infinity.
        "psnr_db": None if mse == 0.0 else 10.0 * math.log10(1.0 / mse),
        "mse": mse,
        "max_err": float(abs_err.max()),
        "share_above_1_255": float(np.mean(abs_err > ONE_LSB)),
        "worst_pixel_xy": [int(x), int(y)],
        "worst_pixel_ref": [float(v) for v in ref[y, x]],
        "worst_pixel_ours": [float(v) for v in ours[y, x]],
        "non_finite_values": non_finite,
    }


def psnr_value(record):
    """PSNR for sorting and thresholds: identical images rank as +inf."""
    return math.inf if record["psnr_db"] is None else record["psnr_db"]


def json_safe(value):
    """Infinite PSNRs (identical images) as null: JSON has no infinity."""
    if isinstance(value, float) and math.isinf(value):
        return None
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, list):
        return [json_safe(v) for v in value]
    return value


def fmt_db(value):
    return "inf" if math.isinf(value) else f"{value:.2f}"


# -------------------------------------------------------------------------- ours


def render_ours(gs_render, scene_path, cameras_path, view, backend, extra_args, tmp):
    """gs-render's RGB for one view, and its 'render:' stats line."""
    rgba_path = Path(tmp) / f"ours_{backend}.npy"
    rgba_path.unlink(missing_ok=True)
    cmd = [str(gs_render), "-i", str(scene_path), "--cameras", str(cameras_path),
           "--view", str(view), "--width", str(ro.IMAGE_SIZE), "--height", str(ro.IMAGE_SIZE),
           "--backend", backend, "-o", str(Path(tmp) / f"ours_{backend}.png"),
           "--float-output", str(rgba_path), *extra_args]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
    if proc.returncode != 0:
        raise RuntimeError(f"{shlex.join(cmd)} exited {proc.returncode}:\n{proc.stderr.strip()}")
    rgba = np.load(rgba_path)
    if rgba.dtype != np.float32 or rgba.ndim != 3 or rgba.shape[2] != 4:
        raise RuntimeError(f"{rgba_path}: expected float32 [H, W, 4], got {rgba.dtype} {rgba.shape}")
    # Premultiplied RGBA over the default black background: RGB is the final colour.
    stats = next((l for l in proc.stdout.splitlines() if l.startswith("render:")), "")
    return rgba[..., :3], stats


# ---------------------------------------------------------------------- summary


def summarise(records):
    """One row per (scene, backend) over the views that rendered."""
    rows = []
    keys = sorted({(r["scene"], r["backend"]) for r in records},
                  key=lambda k: ([*ro.SCENES, *ro.ORBIT_SCENES].index(k[0]), k[1]))
    for scene, backend in keys:
        group = [r for r in records if r["scene"] == scene and r["backend"] == backend]
        ok = [r for r in group if "error" not in r]
        row = {"scene": scene, "backend": backend, "views": len(ok),
               "failed_views": [r["view"] for r in group if "error" in r]}
        if ok:
            psnrs = [psnr_value(r) for r in ok]
            worst = min(ok, key=psnr_value)
            row.update(
                min_psnr_db=min(psnrs), median_psnr_db=statistics.median(psnrs),
                max_psnr_db=max(psnrs),
                views_under_100_db=sum(p < PSNR_BAR_DB for p in psnrs),
                worst_view=worst["view"], worst_view_psnr_db=psnr_value(worst),
                max_err=max(r["max_err"] for r in ok),
                # Every image has the same size, so the overall share is the mean share.
                share_above_1_255=statistics.fmean(r["share_above_1_255"] for r in ok),
            )
        rows.append(row)
    return rows


def summary_markdown(rows):
    lines = ["| scene | backend | views | min PSNR (dB) | median PSNR (dB) | max PSNR (dB) "
             "| views < 100 dB | worst view | max abs err | share > 1/255 | failed |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        failed = ",".join(map(str, r["failed_views"])) or "-"
        if not r["views"]:
            lines.append(f"| {r['scene']} | {r['backend']} | 0 | - | - | - | - | - | - | - "
                         f"| {failed} |")
            continue
        lines.append(
            f"| {r['scene']} | {r['backend']} | {r['views']} | {fmt_db(r['min_psnr_db'])} "
            f"| {fmt_db(r['median_psnr_db'])} | {fmt_db(r['max_psnr_db'])} "
            f"| {r['views_under_100_db']} "
            f"| {r['worst_view']} ({fmt_db(r['worst_view_psnr_db'])} dB) "
            f"| {r['max_err']:.3g} | {r['share_above_1_255']:.3e} | {failed} |")
    return "\n".join(lines)


def views_markdown(records):
    lines = ["| scene | view | backend | PSNR (dB) | max abs err | share > 1/255 "
             "| worst pixel (x, y) |", "|---|---|---|---|---|---|---|"]
    for r in records:
        if "error" in r:
            lines.append(f"| {r['scene']} | {r['view']} | {r['backend']} | error | | | |")
            continue
        x, y = r["worst_pixel_xy"]
        lines.append(f"| {r['scene']} | {r['view']} | {r['backend']} "
                     f"| {fmt_db(psnr_value(r))} | {r['max_err']:.3g} "
                     f"| {r['share_above_1_255']:.3e} | ({x}, {y}) |")
    return "\n".join(lines)


def crops_markdown(results):
    lines = ["| crop | scene | view | PSNR fresh vs stored (dB) | max abs diff |",
             "|---|---|---|---|---|"]
    for c in results:
        lines.append(f"| {c['crop']} | {c['scene']} | {c['view']} | {fmt_db(psnr_value(c))} "
                     f"| {c['max_err']:.3g} |")
    return "\n".join(lines)


# ------------------------------------------------------------------- crop check


def crop_scene(prefix):
    """The scene a crop's key names: 'biker' is biker_152k, as parity/README.md says."""
    if prefix in ro.SCENES:
        return prefix
    matches = [s for s in ro.SCENES if s.startswith(prefix + "_")]
    if len(matches) != 1:
        raise ValueError(f"crop key '{prefix}' names no single scene")
    return matches[0]


def crop_specs(shared):
    parity = Path(shared) / "data" / "parity"
    with open(parity / "crops.json") as f:
        crops = json.load(f)
    for key, spec in crops.items():
        prefix, view = key.rsplit("_view", 1)
        yield key, crop_scene(prefix), int(view), spec, parity / f"{key}_ref_crop.npy"


def crop_check(shared, original):
    """Fresh crops of the original's renders against the stored ones."""
    results = []
    for key, scene, view, spec, path in crop_specs(shared):
        x0, y0 = spec["crop_origin_xy"]
        w, h = spec["crop_size"]
        fresh = original(scene, view)[y0:y0 + h, x0:x0 + w]
        stored = np.load(path)
        m = compare_images(stored, fresh)
        results.append({"crop": key, "scene": scene, "view": view, **m})
        ro.log(f"crop {key}: PSNR fresh vs stored {fmt_db(psnr_value(m))} dB, "
               f"max abs diff {m['max_err']:.3g}")
    return results


# -------------------------------------------------------------------------- main


class SceneCache:
    """Loads each scene and its cameras once."""

    def __init__(self, shared, cameras_dir):
        self.shared = shared
        self.cameras_dir = cameras_dir  # where orbit scenes' generated cameras.json go
        self._scenes = {}

    def get(self, name):
        if name not in self._scenes:
            self._scenes[name] = ro.scene_and_cameras(self.shared, name, self.cameras_dir)
        return self._scenes[name]


def repo_state():
    def git(*args):
        try:
            return subprocess.run(["git", *args], cwd=ro.REPO_ROOT, capture_output=True,
                                  text=True, timeout=30).stdout.strip() or None
        except (OSError, subprocess.SubprocessError):
            return None

    status = git("status", "--porcelain", "--untracked-files=no")
    return {"commit": git("rev-parse", "HEAD"), "dirty": bool(status) if status is not None
            else None}


def parse_args(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ro.add_common_args(parser)
    parser.add_argument("--gs-render", default=str(ro.REPO_ROOT / "build" / "bin" / "gs-render"),
                        help="our renderer (default: build/bin/gs-render)")
    parser.add_argument("--gs-render-args", default="",
                        help="extra gs-render arguments, passed verbatim (one shell-quoted "
                             "string, e.g. '--depth-order exact')")
    parser.add_argument("--backends", default="cpu,vulkan",
                        help="gs-render backends to compare, or 'none' (with --crop-check)")
    parser.add_argument("--json", help="write every view's numbers here")
    parser.add_argument("--md", help="write the markdown summary and per-view table here")
    parser.add_argument("--crop-check", action="store_true",
                        help="also compare fresh crops of the original with shared/data/parity")
    return parser.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    backends = [] if args.backends == "none" else [b for b in args.backends.split(",") if b]
    extra = shlex.split(args.gs_render_args)
    if backends and not Path(args.gs_render).is_file():
        sys.exit(f"gs-render not found at {args.gs_render}")
    scenes = ro.parse_scenes(args.scenes)
    cache = SceneCache(args.shared, tempfile.mkdtemp(prefix="parity-cameras-"))
    module, peer_info = ro.build_peer(args.peer, args.build_dir, args.compat)
    renderer = ro.OriginalRenderer(module)

    def original(scene, view):
        _, _, gaussians, cameras = cache.get(scene)
        return renderer.render(scene, gaussians, ro.view_camera(cameras[view]))

    records = []
    with tempfile.TemporaryDirectory(prefix="gs-parity-") as tmp:
        for scene in scenes if backends else []:  # --backends none: crop check only
            scene_path, cameras_path, gaussians, cameras = cache.get(scene)
            ro.log(f"{scene}: {len(gaussians.means)} splats, SH degree {gaussians.sh_degree}, "
                   f"{len(cameras)} views")
            for view in ro.parse_views(args.views, len(cameras)):
                start = time.time()
                ref = original(scene, view)
                line = [f"  view {view:2d}: original {time.time() - start:.2f} s"]
                for backend in backends:
                    record = {"scene": scene, "view": view, "backend": backend}
                    start = time.time()
                    try:
                        ours, stats = render_ours(args.gs_render, scene_path, cameras_path, view,
                                                  backend, extra, tmp)
                        record.update(compare_images(ref, ours), gs_render_stats=stats)
                        line.append(f"{backend} {fmt_db(psnr_value(record))} dB "
                                    f"max {record['max_err']:.3g} ({time.time() - start:.1f} s)")
                    except (RuntimeError, ValueError, OSError, subprocess.SubprocessError) as e:
                        record["error"] = str(e)
                        line.append(f"{backend} FAILED")
                        ro.log(f"    {backend}: {e}")
                    records.append(record)
                ro.log(", ".join(line))
    crops = crop_check(args.shared, original) if args.crop_check else None

    rows = summarise(records)
    summary = summary_markdown(rows) if records else ""
    if summary:
        ro.log("\n" + summary)
    if crops:
        ro.log("\n" + crops_markdown(crops))
    meta = {"peer": peer_info, "repo": repo_state(), "gs_render": str(args.gs_render),
            "gs_render_args": extra, "image_size": [ro.IMAGE_SIZE, ro.IMAGE_SIZE],
            "psnr_peak": 1.0, "channels": "RGB"}
    if args.json:
        with open(args.json, "w") as f:
            json.dump(json_safe({"meta": meta, "summary": rows, "views": records,
                                 "crop_check": crops}), f, indent=1)
    if args.md:
        parts = ["# Parity with the original 3DGS rasterizer", "",
                 f"gs-render arguments: `{shlex.join(extra) or '(none)'}`; "
                 f"peer: {peer_info['peer_commit'] or peer_info['peer_dir']}; "
                 f"repo: {meta['repo']['commit'] or 'unknown'}", ""]
        if records:
            parts += ["## Summary", "", summary, "", "## Views", "", views_markdown(records), ""]
        if crops:
            parts += ["## Crop check", "", crops_markdown(crops), ""]
        Path(args.md).write_text("\n".join(parts))
    return 1 if any("error" in r for r in records) else 0


if __name__ == "__main__":
    sys.exit(main())
