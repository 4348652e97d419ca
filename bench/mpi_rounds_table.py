#!/usr/bin/env python3
"""The table of docs/DISTRIBUTED.md from tools/device-check.sh's MPI rounds.

Reads the --stats files of `mpi_rounds` (a folder of NAME.ROUND.json, as the device check writes under
mpi/, mpi_png/ and mpi_sweep/) or one JSON object of them keyed "NAME.ROUND" (as
docs/figures/h200_2026-12-04/mpi16_after.json). For each configuration: the median frame seconds
(from the frame's memory to its last pixel, the span both programs share; files from binaries before
frame_seconds existed give render seconds, which for the plain program leave out its frame's memory
and renderer) and their range, the efficiency (the plain one-thread frame over the cores used times
the frame), the plain program's frame on as many threads over it, and the ranks' mean busy share.

  python3 bench/mpi_rounds_table.py RESULTS/mpi [--plain1 plain_t1] [--plainN plain_t16]
"""
import argparse
import glob
import os
import statistics
import bench_outputs
import sys


def load(path):
    runs = {}
    if os.path.isdir(path):
        for f in sorted(glob.glob(os.path.join(path, "*.json"))):
            name = os.path.basename(f)[: -len(".json")]
            runs[name] = bench_outputs.load_json(f)
    else:
        runs = bench_outputs.load_json(path)
    by_config = {}
    for key, stats in runs.items():
        config, _, round_ = key.rpartition(".")
        if config and round_.isdigit():
            by_config.setdefault(config, []).append(stats)
    return by_config


def cores(stats):
    ranks = stats.get("ranks")
    return sum(r["threads"] for r in ranks) if ranks else stats["threads"]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("results", help="a folder of NAME.ROUND.json, or one JSON object of them")
    p.add_argument("--plain1", default="plain_t1", help="the plain program on one thread")
    p.add_argument("--plainN", default="plain_t16", help="the plain program on every core")
    a = p.parse_args()
    by_config = load(a.results)
    med = statistics.median
    every = [s for runs in by_config.values() for s in runs]
    key = "frame_seconds" if all("frame_seconds" in s for s in every) else "render_seconds"
    frame = {c: med(s[key] for s in runs) for c, runs in by_config.items()}
    one = frame.get(a.plain1)
    many = frame.get(a.plainN)
    print(f"| configuration | rounds | {key}, median (min-max) | efficiency | ÷ plain on all cores | busy share |")
    print("|---|--:|---|--:|--:|--:|")
    for c, runs in sorted(by_config.items(), key=lambda kv: -frame[kv[0]]):
        s = [r[key] for r in runs]
        n = cores(runs[0])
        eff = f"{one / (n * frame[c]):.2f}" if one else ""
        rel = f"{many / frame[c]:.2f}" if many else ""
        busy = [r["busy_seconds"] / st[key] for st in runs for r in st.get("ranks", [])]
        share = f"{statistics.mean(busy):.2f}" if busy else ""
        print(f"| {c} | {len(runs)} | {frame[c]:.4f} ({min(s):.4f}-{max(s):.4f}) | {eff} | {rel} | {share} |")


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "mpi_rounds_table"))
