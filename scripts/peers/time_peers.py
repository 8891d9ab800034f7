#!/usr/bin/env python3
"""Times peer CUDA rasterizers on the views gs-bench renders, beside gs-bench itself.

Peers, all driven from this process through PyTorch:
  original  graphdeco-inria/diff-gaussian-rasterization 59f5f77, built and called as
            scripts/parity/render_original.py does (its raw forward binding);
  gsplat    gsplat 1.6.0's gsplat.rasterization() with its defaults (packed, 16-pixel
            tiles, classic mode);
  higs8 / higs16
            NVIDIA's HiGS as gsplat 1.6.0 ships it in gsplat.experimental: the stateful
            GaussianInferenceRenderer over a GaussianInferenceScene (fp16 packing, no SH
            compression) with macro tiles of 8 or 16 pixels.

Each scene and resolution renders view 0 the way gs-bench does (cpp/apps/gs_bench:
ScaleViewTo for cameras.json scenes, MakeGridScene / MakeGridCamera for --grid K, both
reproduced in peer_scenes.py). Every peer gets the same decoded splats
(render_original.load_scene), the original's near cull of 0.2, eps2d 0.3, a black
background, no antialiasing.

Timing: CUDA events recorded around one forward call on the current stream, waited for
after each call; warm-up calls until the time settles; then --repeat calls: median, min and
mean GPU ms, and the median wall-clock ms of the call with its wait. Each peer's view-0
image is compared with the original's (PSNR, float RGB, peak 1). With --gs-bench the same
scenes and resolutions are timed by gs-bench afterwards and merged into the table; with
--gs-render our view-0 image is compared with the original's too (cameras.json scenes).

--build-only builds (JIT) every peer's extension and exits: scripts/peers/run.sh runs it
first, so that no two processes ever build or import the JIT extensions at once.

This file is the entry point and the run itself: the command line, the loop over scenes, sizes
and peers, nvidia-smi, our gs-render / gs-bench runs and the outputs (peers.json, peers.md).
Beside it: peer_scenes.py (the scenes and views, as gs-bench renders them), peer_build.py (the
JIT builds and gsplat's import), peer_renderers.py (the peers' frame calls and their timing),
parity_imports.py (scripts/parity's render_original and compare).
"""

import argparse
import json
import math
import os
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from parity_imports import cmp, log, ro
from peer_build import (GSPLAT_LEAN_BUILD_ENV, build_all, build_gsplat_main, build_gsplat_scene,
                        build_higs, clear_stale_locks, configure_build_env, import_gsplat,
                        peer_commit)
from peer_renderers import (EPS2D, NEAR_PLANE, GpuScene, GsplatPeer, HigsPeer, OriginalPeer,
                            time_call)
from peer_scenes import (DEFAULT_GRID_TILE, DEFAULT_SCENES, SCENES, load_scenes,
                         parse_resolutions, parse_scene_specs)

REPO_ROOT = ro.REPO_ROOT
DEFAULT_ORIGINAL = REPO_ROOT / ".parity-peer" / "diff-gaussian-rasterization"
DEFAULT_GSPLAT = REPO_ROOT / ".parity-peer" / "gsplat"
PEERS = ("original", "gsplat", "higs8", "higs16")


# ------------------------------------------------------------------------ nvidia-smi


def nvidia_smi(query, device_uuid=None):
    """nvidia-smi's CSV for the GPU torch uses (every GPU when its id is not accepted)."""
    cmd = ["nvidia-smi", f"--query-gpu={query}", "--format=csv"]
    for ident in ([device_uuid] if device_uuid else []) + [None]:
        try:
            out = subprocess.run(cmd[:1] + ([f"--id={ident}"] if ident else []) + cmd[1:],
                                 capture_output=True, text=True, timeout=30)
        except (OSError, subprocess.SubprocessError) as e:
            return f"nvidia-smi failed: {e}"
        if out.returncode == 0 or ident is None:
            return (out.stdout or out.stderr).strip()
    return ""


def torch_device_uuid(torch):
    try:
        uuid = str(torch.cuda.get_device_properties(torch.cuda.current_device()).uuid)
        return uuid if uuid.startswith("GPU-") else f"GPU-{uuid}"
    except Exception:  # noqa: BLE001 - older torch: no uuid, query every GPU
        return None


# ----------------------------------------------------------------------- ours


def write_camera_file(entry, folder):
    path = Path(folder) / "bench_view.json"
    path.write_text(json.dumps([entry]))
    return path


def ours_view(gs_render, scene, entry, extra, tmp):
    """gs-render's RGB of the bench view: a one-view cameras.json with the bench camera
    (gs-render's --width/--height would scale fx and fy separately, gs-bench does not)."""
    cams = write_camera_file(entry, tmp)
    rgba_path = Path(tmp) / "ours.npy"
    rgba_path.unlink(missing_ok=True)
    cmd = [str(gs_render), "-i", str(scene.path), "--cameras", str(cams), "--view", "0",
           "--backend", "vulkan", "-o", str(Path(tmp) / "ours.png"),
           "--float-output", str(rgba_path), *extra]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
    if proc.returncode != 0:
        raise RuntimeError(f"{shlex.join(cmd)} exited {proc.returncode}: {proc.stderr.strip()}")
    return np.load(rgba_path)[..., :3]


def run_gs_bench(args, scenes, resolutions, out_dir):
    """gs-bench on the same scenes, view 0, at the same sizes: one run for the cameras.json
    scenes, one per grid. Returns (rows of knob 'default', run records); the JSON files keep
    every knob of --knobs."""
    common = ["--views", "0", "--knobs", args.knobs, "--repeat", str(args.repeat),
              "--reference-max-splats", "0"]
    for w, h in resolutions:
        common += ["--resolution", f"{w}x{h}"]
    runs = []
    files = [s for s in scenes if s.grid is None and s.first is None]
    if files:
        cmd = [str(args.gs_bench)]
        for s in files:
            cmd += ["-i", str(s.path), "--cameras", str(s.cameras_path)]
        runs.append(("gs-bench", cmd + common))
    for s in scenes:
        if s.first is not None:
            runs.append((f"gs-bench-first{s.first}",
                         [str(args.gs_bench), "-i", str(s.path), "--cameras", str(s.cameras_path),
                          "--first", str(s.first)] + common))
        if s.grid is not None:
            runs.append((f"gs-bench-grid{s.grid}",
                         [str(args.gs_bench), "-i", str(s.path), "--cameras", str(s.cameras_path),
                          "--grid", str(s.grid)] + common))
    rows, records = [], []
    extra = shlex.split(args.gs_bench_args)
    for name, cmd in runs:
        json_path = Path(out_dir) / f"{name}.json"
        cmd = cmd + ["--json", str(json_path)] + extra
        log(f"ours: {shlex.join(cmd)}")
        start = time.time()
        with open(Path(out_dir) / f"{name}.log", "w") as f:
            proc = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT, text=True)
        record = {"command": cmd, "exit_status": proc.returncode, "log": f"{name}.log",
                  "seconds": round(time.time() - start, 1)}
        records.append(record)
        if proc.returncode != 0 or not json_path.is_file():
            log(f"ours: {name} exited {proc.returncode} (see {name}.log)")
            continue
        record["json"] = json_path.name
        rows += [r for r in json.loads(json_path.read_text()) if r.get("knob") == "default"]
    return rows, records


# ------------------------------------------------------------------------ tables


def fmt_ms(r):
    if r is None or "error" in r:
        return "-" if r is None else "error"
    return f"{r['gpu_ms_median']:.3f} ({r['gpu_ms_min']:.3f})"


def fmt_psnr(r):
    if r is None or "psnr_db" not in r:
        return "-"
    return cmp.fmt_db(math.inf if r["psnr_db"] is None else r["psnr_db"])


def markdown(results, peers, ours_rows):
    ours = {(r["scene"], r["resolution"]): r for r in ours_rows}
    higs = [p for p in peers if p.startswith("higs")]
    head = ["scene", "size", "splats"] + [f"{p} GPU ms" for p in peers]
    if higs:
        head.append("HiGS best")
    head += ["ours GPU ms (passes / submission)"]
    head += [f"{p} PSNR" for p in peers if p != "original"] + ["ours PSNR"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for key, group in results.items():
        scene, bench_name, resolution, splats = key
        row = [scene, resolution, f"{splats:,}"] + [fmt_ms(group.get(p)) for p in peers]
        if higs:
            ok = [(group[p]["gpu_ms_median"], p) for p in higs if p in group and "error" not in group[p]]
            row.append(f"{min(ok)[0]:.3f} ({min(ok)[1]})" if ok else "-")
        o = ours.get((bench_name, resolution))
        row.append(f"{o['gpu_total_ms']:.3f} / {o.get('frame_gpu_submission_ms', 0):.3f}"
                   if o else "-")
        row += [fmt_psnr(group.get(p)) for p in peers if p != "original"]
        row.append(fmt_psnr(group.get("ours")))
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def write_outputs(out_dir, meta, records, results, peers, ours_rows, ours_runs):
    out_dir = Path(out_dir)
    data = {"meta": meta, "rows": records, "gs_bench_rows": ours_rows, "gs_bench_runs": ours_runs}
    (out_dir / "peers.json").write_text(json.dumps(cmp.json_safe(data), indent=1))
    table = markdown(results, peers, ours_rows)
    text = ["# Peer rasterizers beside gs-bench", "",
            f"Device: {meta['gpu']}; SM clock after the first timed call: "
            f"{meta['sm_clock'].replace(chr(10), '; ')}",
            f"Peers: original {meta['original_commit'] or '-'}; gsplat {meta['gsplat_commit'] or '-'}",
            f"Repository: {meta['repo']['commit'] or 'unknown'}"
            f"{' (dirty)' if meta['repo']['dirty'] else ''}", "",
            "GPU ms: CUDA events around one forward call, median (min) of "
            f"{meta['repeat']} calls after warm-up. Ours: gs-bench's `gpu_total_ms` (sum of the "
            "per-pass medians) / `frame_gpu_submission_ms` (one submission, first to last "
            "command). PSNR: view 0 against the original rasterizer, float RGB, black "
            "background, peak 1 (inf: identical).", "", table, ""]
    notes = [f"- {r['scene']} {r['resolution']} {r['peer']}: {n}" for r in records
             for n in r.get("notes", [])]
    notes += [f"- {r['scene']} {r['resolution']} {r['peer']}: error: {r['error']}"
              for r in records if "error" in r]
    if notes:
        text += ["## Notes", ""] + notes + [""]
    (out_dir / "peers.md").write_text("\n".join(text))
    return table


# --------------------------------------------------------------------------- main


def parse_args(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", help="folder for peers.json, peers.md (and gs-bench's output)")
    parser.add_argument("--build-only", action="store_true",
                        help="build every peer's extension and exit (no timing)")
    parser.add_argument("--original-peer", default=str(DEFAULT_ORIGINAL),
                        help="diff-gaussian-rasterization source folder (scripts/parity/README.md)")
    parser.add_argument("--original-build-dir",
                        help="where to build the original (default: render_original's temp dir)")
    parser.add_argument("--compat", action="store_true",
                        help="build the original from its renamed copy (render_original --compat)")
    parser.add_argument("--gsplat-peer", default=str(DEFAULT_GSPLAT),
                        help="folder that fetch-gsplat.sh filled (holds gsplat/)")
    parser.add_argument("--gsplat-full-build", action="store_true",
                        help="build all of gsplat's modules and channel counts, not only 3DGS "
                             "for 3 channels (give it to the build and the timing run alike)")
    parser.add_argument("--shared", default=str(ro.DEFAULT_SHARED),
                        help="shared folder with data/ (default: ../shared beside the repo)")
    parser.add_argument("--scenes", default=DEFAULT_SCENES,
                        help=f"comma list: names ({', '.join(SCENES)}), gridK (K x K copies of "
                             "--grid-tile, as gs-bench --grid K), or PATH[:CAMERAS] "
                             f"(default {DEFAULT_SCENES})")
    parser.add_argument("--grid-tile", default=DEFAULT_GRID_TILE,
                        help="the tile of gridK scenes: a name or PATH[:CAMERAS]")
    parser.add_argument("--resolutions", default="1920x1080,3840x2160", help="comma list of WxH")
    parser.add_argument("--peers", default=",".join(PEERS), help=f"comma list of {', '.join(PEERS)}")
    parser.add_argument("--repeat", type=int, default=50, help="timed calls per peer and size")
    parser.add_argument("--warmup-min", type=float, default=1.0,
                        help="seconds of warm-up calls at least (then until the time settles)")
    parser.add_argument("--warmup-max", type=float, default=10.0,
                        help="seconds of warm-up calls at most")
    parser.add_argument("--no-psnr", action="store_true", help="skip the view-0 PSNR")
    parser.add_argument("--gs-bench", help="also time these scenes with this gs-bench")
    parser.add_argument("--knobs", default="default",
                        help="gs-bench knobs to time (the table compares 'default')")
    parser.add_argument("--gs-bench-args", default="",
                        help="extra gs-bench arguments (one shell-quoted string)")
    parser.add_argument("--gs-render",
                        help="also compare this gs-render's view 0 (Vulkan) with the original's "
                             "(cameras.json scenes; a grid has no scene file to give it)")
    parser.add_argument("--gs-render-args", default="",
                        help="extra gs-render arguments (one shell-quoted string)")
    args = parser.parse_args(argv)
    args.peers = [p for p in args.peers.split(",") if p]
    for p in args.peers:
        if p not in PEERS:
            parser.error(f"unknown peer '{p}' (known: {', '.join(PEERS)})")
    if not args.build_only and not args.out:
        parser.error("--out is required (unless --build-only)")
    if args.repeat < 1:
        parser.error("--repeat must be at least 1")
    return args


def make_peers(torch, gsplat, args, meta):
    """The peers of --peers, in that order; a peer that fails to load is left out with its
    error in meta['peer_errors']."""
    peers = {}
    for name in args.peers:
        try:
            if name == "original":
                module, info = ro.build_peer(args.original_peer, args.original_build_dir,
                                             args.compat)
                meta["original"] = info
                peers[name] = OriginalPeer(torch, module)
            elif name == "gsplat":
                build_gsplat_main()
                peers[name] = GsplatPeer(torch, gsplat)
            else:
                build_gsplat_scene()
                build_higs(direct=False)
                peers[name] = HigsPeer(torch, int(name[4:]))
        except Exception as e:  # noqa: BLE001 - time the other peers
            meta["peer_errors"][name] = f"{type(e).__name__}: {e}"
            log(f"peer {name}: unavailable: {type(e).__name__}: {e}")
    return peers


def main(argv=None):
    args = parse_args(argv)
    configure_build_env(args.gsplat_full_build)
    if args.build_only:
        os.environ.setdefault("VERBOSE", "1")  # gsplat's compiler output in the log
    clear_stale_locks(args)
    gsplat = None
    if any(p != "original" for p in args.peers):
        gsplat = import_gsplat(args.gsplat_peer)
        log(f"gsplat {gsplat.__version__} from {Path(gsplat.__file__).parent} "
            f"({peer_commit(args.gsplat_peer) or 'no PEER_COMMIT'}); "
            f"TORCH_EXTENSIONS_DIR={os.environ['TORCH_EXTENSIONS_DIR']}")
    if args.build_only:
        return build_all(args, gsplat)

    import torch

    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    resolutions = parse_resolutions(args.resolutions)
    scenes = load_scenes(parse_scene_specs(args.scenes), args.shared, args.grid_tile)
    device = torch.device("cuda")
    meta = {
        "gpu": torch.cuda.get_device_name(), "torch": torch.__version__,
        "torch_cuda": torch.version.cuda,
        "cuda_arch_list": os.environ.get("TORCH_CUDA_ARCH_LIST"),
        "gsplat_build_env": {k: os.environ.get(k) for k in GSPLAT_LEAN_BUILD_ENV},
        "original_commit": peer_commit(args.original_peer) if "original" in args.peers else None,
        "gsplat_commit": peer_commit(args.gsplat_peer),
        "repo": cmp.repo_state(), "repeat": args.repeat,
        "warmup_s": [args.warmup_min, args.warmup_max], "near_plane": NEAR_PLANE, "eps2d": EPS2D,
        "timing": "CUDA events around one forward call (waited for), after warm-up",
        "psnr": "view 0 against the original, RGB float64 MSE, peak 1, black background",
        "sm_clock": "not read", "peer_errors": {},
    }
    uuid = torch_device_uuid(torch)
    meta["gpu_smi"] = nvidia_smi("name,driver_version,clocks.max.sm", uuid)
    log(f"device: {meta['gpu']} ({meta['gpu_smi'].splitlines()[-1] if meta['gpu_smi'] else ''}); "
        f"torch {torch.__version__}, CUDA {torch.version.cuda}")
    peers = make_peers(torch, gsplat, args, meta)
    if args.gs_render and not Path(args.gs_render).is_file():
        log(f"ours: no gs-render at {args.gs_render}; no PSNR for ours")
        args.gs_render = None

    records, results = [], {}
    clock_read = False
    with torch.inference_mode(), tempfile.TemporaryDirectory(prefix="gs-peers-") as tmp:
        for scene in scenes:
            g = scene.gaussians
            log(f"{scene.label}: {len(g.means):,} splats, SH degree {g.sh_degree}")
            gpu_scene = GpuScene(torch, g, device)
            for peer in peers.values():
                peer.setup(gpu_scene)
            for w, h in resolutions:
                resolution = f"{w}x{h}"
                entry = scene.entry_at(w, h)
                cam = ro.view_camera(entry, w, h)
                key = (scene.label, scene.bench_name, resolution, len(g.means))
                group = results.setdefault(key, {})
                reference = None
                if not args.no_psnr and "original" in peers:
                    reference = peers["original"].frame(cam)().float().cpu().numpy()
                for name, peer in peers.items():
                    record = {"scene": scene.label, "gs_bench_scene": scene.bench_name,
                              "resolution": resolution, "peer": name, "splats": len(g.means),
                              "camera": entry}
                    try:
                        fn = peer.frame(cam)
                        if reference is not None and name != "original":
                            image = fn().float().cpu().numpy()
                            m = cmp.compare_images(reference, image)
                            record.update(psnr_db=m["psnr_db"], max_err=m["max_err"],
                                          non_finite_values=m["non_finite_values"])
                        record.update(time_call(torch, fn, args.repeat, args.warmup_min,
                                                args.warmup_max))
                        if not clock_read:
                            meta["sm_clock"] = nvidia_smi("clocks.sm", uuid)
                            log(f"SM clock: {meta['sm_clock']}")
                            clock_read = True
                    except Exception as e:  # noqa: BLE001 - keep timing the rest
                        record["error"] = f"{type(e).__name__}: {e}"
                    if getattr(peer, "notes", None):
                        record["notes"] = list(peer.notes)
                    records.append(record)
                    group[name] = record
                    log(f"  {resolution} {name:8s} " + (
                        f"error: {record['error']}" if "error" in record else
                        f"{record['gpu_ms_median']:.3f} ms (min {record['gpu_ms_min']:.3f}, "
                        f"wall {record['wall_ms_median']:.3f})"
                        + (f", PSNR {fmt_psnr(record)} dB" if "psnr_db" in record else "")))
                # gs-render reads whole files: no PSNR of ours for a grid or a file's first splats.
                if (args.gs_render and reference is not None and scene.grid is None
                        and scene.first is None):
                    record = {"scene": scene.label, "gs_bench_scene": scene.bench_name,
                              "resolution": resolution, "peer": "ours", "splats": len(g.means)}
                    try:
                        m = cmp.compare_images(reference, ours_view(
                            args.gs_render, scene, entry, shlex.split(args.gs_render_args), tmp))
                        record.update(psnr_db=m["psnr_db"], max_err=m["max_err"],
                                      non_finite_values=m["non_finite_values"])
                        log(f"  {resolution} ours     PSNR {fmt_psnr(record)} dB (gs-render)")
                    except (RuntimeError, ValueError, OSError, subprocess.SubprocessError) as e:
                        record["error"] = str(e)
                        log(f"  {resolution} ours     gs-render failed: {e}")
                    records.append(record)
                    group["ours"] = record
            for peer in peers.values():
                peer.release()
            del gpu_scene
            torch.cuda.empty_cache()
    meta["higs_notes"] = sorted({n for p in peers.values() for n in getattr(p, "notes", [])})
    names = list(peers)
    table = write_outputs(out_dir, meta, records, results, names, [], [])
    log("\n" + table)
    if args.gs_bench:
        if Path(args.gs_bench).is_file():
            ours_rows, ours_runs = run_gs_bench(args, scenes, resolutions, out_dir)
            table = write_outputs(out_dir, meta, records, results, names, ours_rows, ours_runs)
            log("\n" + table)
        else:
            log(f"ours: no gs-bench at {args.gs_bench}; peers only")
    log(f"\nwrote {out_dir / 'peers.json'} and {out_dir / 'peers.md'}")
    return 1 if meta["peer_errors"] or any("error" in r for r in records) else 0


if __name__ == "__main__":
    sys.exit(main())
