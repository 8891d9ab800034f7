#!/usr/bin/env python3
"""The hostile-input corpus: files and command lines users and fuzzers found to crash, hang,
lose data or mislead the command-line tools, made here by script (no binary blobs), each run
with the exit status and the message it must give.

Every case must end with status 0 where it should succeed, or 1-125 where it should fail
(1: a named error, 105-109: a refused command line; never a signal, an abort or a sanitizer's
status), within a deadline only a real hang reaches, leave every input byte-for-byte as it was, and print what the case
names. Usage (ctest runs it as hostile_inputs.corpus):
    python3 tests/hostile/corpus.py --bin build/bin --work /tmp/hostile [--only NAME]
"""

import argparse
import gzip
import hashlib
import os
import re
import shutil
import struct
import subprocess
import sys
import zipfile
from pathlib import Path

HANG_DEADLINE_S = 300  # a busy 2-core machine renders these in seconds; only a hang gets here
SH_C0 = 0.28209479177387814


def ply_bytes(n, degree=0, rows=None, extra_header=""):
    """A binary little-endian 3DGS PLY of n plausible splats at an SH degree."""
    rest = 3 * ((degree + 1) ** 2 - 1)
    names = ["x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"]
    names += [f"f_rest_{k}" for k in range(rest)]
    names += ["opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"]
    header = "ply\nformat binary_little_endian 1.0\nelement vertex %d\n" % n
    header += "".join(f"property float {p}\n" for p in names) + extra_header + "end_header\n"
    body = bytearray()
    for i in range(n):
        row = rows(i) if rows else ([0.1 * (i % 4), 0.1 * (i // 4), 2.0, 0, 0, 0, 0.3, 0.2, 0.1]
                                    + [0.01] * rest + [2.0, -3.0, -3.0, -3.0, 1, 0, 0, 0])
        body += struct.pack("<%df" % len(row), *row)
    return header.encode() + bytes(body)


def spz_header(version, n, degree=0, fractional_bits=12, flags=0):
    return struct.pack("<IIIBBBB", 0x5053474E, version, n, degree, fractional_bits, flags, 0)


def cameras_json(width, height):
    return ('[{"id": 0, "img_name": "v", "width": %d, "height": %d, "position": [0, 0, 0], '
            '"rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "fx": 500, "fy": 500}]'
            % (width, height))


class Case:
    def __init__(self, name, tool, args, expect_rc, pattern, files=None, env=None, setup=None):
        self.name, self.tool, self.args = name, tool, args
        self.expect_rc, self.pattern = expect_rc, pattern
        self.files = files or {}  # relative path -> bytes (written before the run, then checked)
        self.env = env or {}
        self.setup = setup  # extra preparation in the case's folder (links, FIFOs, .lod files)


def build_cases():
    ply16 = ply_bytes(16)
    ply16_sh3 = ply_bytes(16, degree=3)
    glb_like_json = b'{"asset": {"version": "2.0"}}'
    cases = [
        # Crashes and lost data
        Case("stale_lod_is_refused", "gs-render", ["-i", "s.ply", "--lod-budget", "4",
                                                   "--width", "16", "--height", "16"],
             1, r"s\.ply\.lod.*(another|different|stale|does not match|built from)",
             {"s.ply": ply16_sh3, "s0.ply": ply16}, setup="stale_lod"),
        Case("stream_onto_the_input", "gs-bench", ["-i", "in.ply", "--stream", "in.ply"],
             1, r"in\.ply", {"in.ply": ply16}),
        Case("json_onto_a_gltf_input", "gs-bench", ["-i", "in.json", "--json", "in.json"],
             1, r"in\.json", {"in.json": glb_like_json}),
        Case("output_onto_the_cameras", "gs-render", ["--cameras", "cam.npy", "-o", "cam.npy"],
             1, r"cam\.npy", {"cam.npy": b"\x93NUMPY not really"}),
        Case("spz_claiming_2pow32_points", "gs-convert", ["big.spz", "out.ply"],
             1, r"big\.spz.*(needs|memory|numPoints)",
             {"big.spz": gzip.compress(spz_header(2, 0xFFFFFFFF))},
             env={"OPEN3D_HOST_MEMORY_LIMIT": "1G"}),
        Case("cpu_render_past_memory", "gs-render",
             ["-i", "s.ply", "--cameras", "cam.json", "--backend", "cpu", "-o", "o.png"],
             1, r"30000x30000.*needs.*memory",
             {"s.ply": ply16, "cam.json": cameras_json(30000, 30000).encode()},
             env={"OPEN3D_HOST_MEMORY_LIMIT": "2G"}),
        # Wrong results accepted silently
        Case("ascii_ply_1e999", "gs-convert", ["a.ply", "out.ply"], 1, r"a\.ply.*(1e999|finite)",
             {"a.ply": b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                       b"property float y\nproperty float z\nend_header\n1e999 0 0\n"}),
        Case("ply_two_vertex_elements", "gs-convert", ["two.ply", "out.ply"], 1,
             r"two\.ply.*element 'vertex' declared twice",
             {"two.ply": b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                         b"property float y\nproperty float z\nelement vertex 0\n"
                         b"property float x\nproperty float y\nproperty float z\n"
                         b"end_header\n1 2 3\n"}),
        Case("ply_2pow62_rows_after_vertex", "gs-convert", ["huge.ply", "out.ply"], 0,
             r"1 splats",
             {"huge.ply": b"ply\nformat binary_little_endian 1.0\nelement vertex 1\n"
                          b"property float x\nproperty float y\nproperty float z\n"
                          b"element face 4611686018427387904\nproperty float w\nend_header\n"
                          + bytes(20)}),
        Case("spz_fractional_bits_40", "gs-convert", ["fb.spz", "out.ply"], 1,
             r"fb\.spz.*fractionalBits.*40",
             {"fb.spz": gzip.compress(spz_header(2, 1, fractional_bits=40) + bytes(19))}),
        Case("depth_scale_inf", "gs-render", ["--depth-scale", "inf", "--width", "8"], 1,
             r"--depth-scale: 'inf' must be finite"),
        Case("resolution_with_junk", "gs-bench",
             ["-i", "s.ply", "--cameras", "cam.json", "--resolution", "64x64junk"], 1,
             r"--resolution.*64x64junk",
             {"s.ply": ply16, "cam.json": cameras_json(64, 64).encode()}),
        Case("device_memory_limit_with_suffix", "gs-render",
             ["-i", "s.ply", "--width", "16", "--height", "16", "--backend", "vulkan",
              "-o", "o.png"], 0, r"backend vulkan", {"s.ply": ply16},
             env={"OPEN3D_DEVICE_MEMORY_LIMIT": "1G"}),
        # Memory read before it is checked
        Case("spz_v4_claiming_1e8_splats", "gs-convert", ["rle.spz", "out.ply"], 1,
             r"rle\.spz.*100000000 splats.*decompressed streams needs",
             {"rle.spz": None}, env={"OPEN3D_HOST_MEMORY_LIMIT": "1G"}, setup="spz_v4_claim"),
        Case("gzip_bomb_named_spz", "gs-convert", ["bomb.spz", "out.ply"], 1,
             r"bomb\.spz.*(magic|header)",
             {"bomb.spz": gzip.compress(bytes(64 << 20), 9)},
             env={"OPEN3D_HOST_MEMORY_LIMIT": "1G"}),
        # Users' experience: messages name the file and the flag
        Case("symlink_loop_input", "gs-render", ["-i", "loop_a.ply"], 1,
             r"loop of symbolic links", setup="link_loop"),
        Case("non_finite_eye", "gs-render", ["--eye", "0,nan,1", "--width", "8"], 1,
             r"--eye: 'nan' must be a finite number"),
        Case("gpu_budget_not_a_size", "gs-bench",
             ["-i", "s.ply", "--cameras", "cam.json", "--stream", "s.gspages", "--gpu-budget",
              "abc"], 1, r"--gpu-budget.*abc",
             {"s.ply": ply16, "cam.json": cameras_json(64, 64).encode()}),
        Case("fifo_inside_a_sog_folder", "gs-convert", ["sog", "out.ply"], 1,
             r"sh0\.webp.*is a FIFO", setup="sog_with_fifo"),
        Case("ksplat_named_splat", "gs-convert", ["k.splat", "out.ply"], 1,
             r"k\.splat.*is a \.ksplat file", setup="ksplat_named_splat"),
        Case("view_past_the_cameras", "gs-render", ["-i", "s.ply", "--cameras", "cam.json",
                                                    "--view", "99"], 1, r"--view.*99",
             {"s.ply": ply16, "cam.json": cameras_json(64, 64).encode()}),
    ]
    return cases


def run_tool(bin_dir, tool, args, cwd, env):
    # Warnings and progress would also go to the log; errors must name their cause.
    full_env = dict(os.environ, OPEN3D_NUM_THREADS="2", **env)
    try:
        p = subprocess.run([str(bin_dir / tool), *args], cwd=cwd, env=full_env,
                           capture_output=True, timeout=HANG_DEADLINE_S)
    except subprocess.TimeoutExpired:
        return None, f"still running after {HANG_DEADLINE_S} s (a hang)"
    return p.returncode, (p.stdout + p.stderr).decode("utf-8", "backslashreplace")


def prepare(case, folder, bin_dir):
    """Writes the case's files and runs its setup; returns their digests to check later."""
    for rel, data in case.files.items():
        if data is not None:
            (folder / rel).write_bytes(data)
    if case.setup == "stale_lod":
        # s0.ply's hierarchy beside s.ply (SH 3): the .lod of another scene.
        rc, out = run_tool(bin_dir, "gs-convert", ["s0.ply", "t.ply", "--lod"], folder, {})
        if rc != 0:
            raise RuntimeError("making the stale .lod failed: " + out)
        (folder / "t.ply.lod").rename(folder / "s.ply.lod")
    elif case.setup == "link_loop":
        os.symlink("loop_b.ply", folder / "loop_a.ply")
        os.symlink("loop_a.ply", folder / "loop_b.ply")
    elif case.setup == "sog_with_fifo":
        sog = folder / "sog"
        sog.mkdir()
        (folder / "s.ply").write_bytes(ply_bytes(16))
        rc, out = run_tool(bin_dir, "gs-convert", ["s.ply", "s.sog"], folder, {})
        if rc != 0:
            raise RuntimeError("writing the SOG failed: " + out)
        with zipfile.ZipFile(folder / "s.sog") as bundle:
            bundle.extractall(sog)
        (folder / "s.sog").unlink()
        (sog / "sh0.webp").unlink()
        os.mkfifo(sog / "sh0.webp")
    elif case.setup == "ksplat_named_splat":
        # A .ksplat main header (version 0.1, mode 0, 1 splat, one section), zeros beyond
        # byte 44 as GaussianSplats3D writes it, then a short section.
        header = bytearray(4096)
        header[0:2] = bytes([0, 1])
        struct.pack_into("<IIII", header, 4, 1, 1, 1, 1)
        (folder / "k.splat").write_bytes(bytes(header) + bytes(1024 + 44))
    elif case.setup == "spz_v4_claim":
        # Header, TOC of five streams sized for 1e8 splats at the zstd bound, junk payload.
        n = 100000000
        blob = bytearray(struct.pack("<IIIBBBBI", 0x5053474E, 4, n, 0, 12, 0, 5, 32))
        blob += bytes(32 - len(blob))
        payload = 0
        for per_splat in (9, 1, 3, 3, 4):
            compressed = (per_splat * n + 32767) // 32768
            blob += struct.pack("<QQ", compressed, per_splat * n)
            payload += compressed
        blob += b"\x5a" * payload
        (folder / "rle.spz").write_bytes(bytes(blob))
    return {p.relative_to(folder): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in folder.rglob("*") if p.is_file() and not p.is_symlink()}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bin", required=True, help="folder of gs-render, gs-convert, gs-bench")
    parser.add_argument("--work", required=True, help="scratch folder (emptied first)")
    parser.add_argument("--only", help="run the one case of this name")
    args = parser.parse_args(argv)
    bin_dir, work = Path(args.bin).resolve(), Path(args.work)
    shutil.rmtree(work, ignore_errors=True)
    cases = [c for c in build_cases() if not args.only or c.name == args.only]
    if not cases:
        sys.exit(f"no case named {args.only}")
    failures = 0
    for i, case in enumerate(cases, 1):
        folder = work / case.name
        folder.mkdir(parents=True)
        digests = prepare(case, folder, bin_dir)
        rc, out = run_tool(bin_dir, case.tool, case.args, folder, case.env)
        problems = []
        if rc is None or rc < 0 or rc > 125:
            problems.append(f"exit status {rc} (a signal, an abort or a hang)")
        elif (rc == 0) != (case.expect_rc == 0):
            problems.append(f"exit status {rc}, expected "
                            + ("0" if case.expect_rc == 0 else "an error (1-125)"))
        if not re.search(case.pattern, out, re.S):
            problems.append(f"output does not match /{case.pattern}/")
        for rel, digest in digests.items():
            path = folder / rel
            if not path.is_file() or hashlib.sha256(path.read_bytes()).hexdigest() != digest:
                problems.append(f"input {rel} was changed or removed")
        status = "ok" if not problems else "FAILED: " + "; ".join(problems)
        print(f"[{i}/{len(cases)}] {case.name}: {status}", flush=True)
        if problems:
            failures += 1
            print("    " + " ".join([case.tool, *case.args]))
            print("    " + out.strip().replace("\n", "\n    ")[:2000])
    print(f"hostile inputs: {len(cases) - failures} of {len(cases)} cases behave")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
