#!/usr/bin/env python3
"""The table of one A/B run of scripts/device/sort-ab.sh: one row per scene, size and value of
the switch compared, from the gs-bench JSON files it wrote (NAME-VALUE.json in OUT_DIR).

Usage: python3 scripts/device/ab_table.py OUT_DIR VALUE [VALUE ...]
Columns: GPU ms (the sum of the passes' median GPU times) with project / sort / composite,
the sort's parts (depth, scan + emit, tiles), wall ms per frame with frames in flight, and the
frame's dependent dispatches.
"""
import json
import pathlib
import sys


def rows_of(path):
    with open(path) as f:
        data = json.load(f)
    return data if isinstance(data, list) else [data]


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out = pathlib.Path(sys.argv[1])
    values = sys.argv[2:]
    names = sorted({p.name[: -len(f"-{v}.json")] for v in values
                    for p in out.glob(f"*-{v}.json")})
    if not names:
        sys.exit(f"ab_table: no NAME-VALUE.json files for {values} in {out}")
    print("| scene | size | value | GPU ms (p / s / c) | sort parts (depth, scan + emit, tiles) "
          "| in flight ms | dependent dispatches |")
    print("|---|---|---|---|---|---|---|")
    for name in names:
        for value in values:
            path = out / f"{name}-{value}.json"
            if not path.exists():
                print(f"| {name} | - | {value} | missing | | | |")
                continue
            for r in rows_of(path):
                if r.get("knob", "default") != "default":
                    continue

                def ms(key):
                    value = r.get(key)
                    return f"{value:.3f}" if isinstance(value, (int, float)) else "-"

                print(f"| {name} | {r.get('resolution', '-')} | {value} | "
                      f"{ms('gpu_total_ms')} ({ms('gpu_project_ms')} / {ms('gpu_sort_ms')} / "
                      f"{ms('gpu_composite_ms')}) | {ms('gpu_depth_sort_ms')}, "
                      f"{ms('gpu_scan_emit_ms')}, {ms('gpu_tile_sort_ms')} | "
                      f"{ms('pipelined_frame_ms')} | {r.get('frame_dependent_dispatches', '-')} |")

if __name__ == "__main__":
    main()
