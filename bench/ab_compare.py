#!/usr/bin/env python3
"""A/B of two builds of cellrt_bench on the same rays: runs A and B alternately (A B B A A B ...), each
run a full `cellrt_bench --json`, and prints per scene and configuration the median time of B over
the median time of A (primary and shadow rays, and both). Interleaving whole runs spreads a noisy
machine's slow spells over both builds; the Embree configurations, the same code in both, show how
much noise is left.

    bench/ab_compare.py OLD/cellrt_bench NEW/cellrt_bench --rounds 4 --json out.json [--overwrite] -- \
        [cellrt_bench options]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

import bench_outputs
from bench_outputs import check_output


def run(binary, args):
    # A path that does not exist yet: cellrt_bench refuses to replace a file without --overwrite,
    # which older binaries, also compared here, do not take.
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "run.json")
        res = subprocess.run([binary, *args, "--json", path], stdout=subprocess.DEVNULL)
        if res.returncode != 0:  # its own message is on stderr already
            sys.exit(f"ab_compare.py: error: {binary} failed (status {res.returncode})")
        with open(path) as f:
            return json.load(f)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--json", help="write every run's rows and the ratios here")
    ap.add_argument("--overwrite", action="store_true", help="replace an existing --json file")
    argv = sys.argv[1:]
    split = argv.index("--") if "--" in argv else len(argv)
    o = ap.parse_args(argv[:split])
    args = argv[split + 1:]
    # Refused before the runs, which take minutes, as cellrt_bench refuses its own options.
    if o.rounds < 1:
        ap.error(f"--rounds {o.rounds}: must be 1 or more")
    if o.json:
        check_output(ap, "--json", o.json, o.overwrite)
    times = {"a": {}, "b": {}}
    runs = []
    for r in range(o.rounds):
        for side in ("ab" if r % 2 == 0 else "ba"):
            rows = run(o.a if side == "a" else o.b, args)
            runs.append({"side": side, "round": r, "rows": rows})
            for row in rows:
                key = (row["scene"], row["config"])
                times[side].setdefault(key, []).append((row["primary_seconds"], row["shadow_seconds"]))
            print(f"round {r + 1}/{o.rounds}: {side} done", file=sys.stderr)
    result = []
    print("| scene | config | primary B/A | shadow B/A | total B/A |\n|---|---|---|---|---|")
    for key in times["a"]:
        if key not in times["b"]:
            continue
        med = {s: [statistics.median(t[i] for t in times[s][key]) for i in (0, 1)] for s in ("a", "b")}
        p, sh = med["b"][0] / med["a"][0], med["b"][1] / med["a"][1]
        tot = sum(med["b"]) / sum(med["a"])
        result.append({"scene": key[0], "config": key[1], "primary": p, "shadow": sh, "total": tot})
        print(f"| {key[0]} | {key[1]} | {p:.3f} | {sh:.3f} | {tot:.3f} |")
    if o.json:
        with open(o.json, "w") as f:
            json.dump({"args": args, "rounds": o.rounds, "ratios": result, "runs": runs}, f, indent=1)


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "ab_compare"))
