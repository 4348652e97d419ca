#!/usr/bin/env python3
"""Markdown tables of cellrt_scaling's JSON, one per dispatch mode and packet size: rows scenes,
columns every configuration at every worker count, each cell its rays per second over the
yardstick's (the JSON's embree_seconds: the first embree configuration of the run, same workers,
dispatch and packet size).

usage: bench/scaling_tables.py scaling.json [CONFIG ...]   (only the named configurations, if given)
"""
import sys
import bench_outputs


def main() -> int:
    if len(sys.argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    points = bench_outputs.load_json(sys.argv[1], rows=True)
    only = sys.argv[2:]
    configs = only or list(dict.fromkeys(p["config"] for p in points))
    workers = sorted({p["workers"] for p in points})
    scenes = list(dict.fromkeys(p["scene"] for p in points))
    # One table per (dispatch, packet): a run of several of each has a point per combination, and a
    # table keyed without them would show whichever came last.
    setups = list(dict.fromkeys((p["dispatch"], p["packet"]) for p in points))
    ratio = {(p["dispatch"], p["packet"], p["scene"], p["config"], p["workers"]): p["embree_seconds"] / p["seconds"]
             for p in points if "embree_seconds" in p}
    columns = [(c, w) for c in configs for w in workers]
    for n, (dispatch, packet) in enumerate(setups):
        if n:
            print()
        print(f"{dispatch} dispatch, {packet}x{packet} packets:\n")
        print("| scene | " + " | ".join(f"{c}, {w} worker{'s' if w > 1 else ''}" for c, w in columns) + " |")
        print("|---|" + "---|" * len(columns))
        for s in scenes:
            key = lambda c, w: (dispatch, packet, s, c, w)
            cells = [f"{ratio[key(c, w)]:.2f}" if key(c, w) in ratio else "–" for c, w in columns]
            print(f"| {s} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "scaling_tables"))
