#!/usr/bin/env python3
"""Rays per second from Python against the same C++ call without Python, in one run.

    PYTHONPATH=build/python python3 bench/python_bench.py [SCENE] [--kinds kd,bvh] [--repeats 9] [--clock cpu]

For each kind, `acc.intersect(origins, directions)` on a batch of 1024 x 1024 rays (the camera's
primary rays, and the same number of incoherent rays: random origins in the scene's box toward random
triangles) is timed from Python (arguments checked, rays assembled from the numpy arrays, four result
arrays allocated and filled), interleaved with `cellrt._native_intersect_seconds`: the very chunks and
threads traced from Ray records built beforehand into a Hit array kept between calls, as a C++ program
would. Medians of --repeats runs of each; the ratio is Python's rays/s over C++'s (docs/PYTHON.md)."""
import argparse
import os
import statistics
import sys
import time

import numpy as np

import cellrt
import bench_outputs


def incoherent_rays(scene, count, seed=1):
    rng = np.random.default_rng(seed)
    tris = scene.triangles
    lo, hi = tris.reshape(-1, 3).min(0), tris.reshape(-1, 3).max(0)
    origins = rng.uniform(lo, hi, size=(count, 3)).astype(np.float32)
    targets = tris[rng.integers(0, len(tris), size=count)].mean(1)
    return origins, (targets - origins).astype(np.float32)


def arguments(doc, kinds, repeats, threads, side):
    """The options of the Python benchmarks (this one and python_kinds.py), with their defaults."""
    default_scene = "../shared/scenes/sponza/sponza.json"
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("scene", nargs="?", default=default_scene if os.path.exists(default_scene) else "builtin:city")
    parser.add_argument("--kinds", default=kinds)
    parser.add_argument("--repeats", type=int, default=repeats)
    parser.add_argument("--threads", type=int, default=threads)
    parser.add_argument("--side", type=int, default=side, help="batch of SIDE x SIDE rays")
    return parser


def checked(parser, args, default_kind=False):
    """`args` with --kinds as a list, refused before the scene loads: a kind the library does not take
    (its own message, from a build over one triangle, so a bad traversal is caught too), a kind named
    twice, --repeats or --side below 1. `default_kind`: `default` names kind=None. Embree's kinds are
    skipped with a note where the library has no Embree, as cellrt_bench skips them."""
    for name in ("repeats", "side"):
        if getattr(args, name) < 1:
            parser.error(f"--{name} {getattr(args, name)}: must be 1 or more")
    kinds = args.kinds.split(",")
    twice = sorted({k for k in kinds if kinds.count(k) > 1})
    if twice:
        parser.error(f"--kinds names {', '.join(twice)} more than once")
    triangle = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], np.float32)
    args.kinds = []
    for k in kinds:
        if k.split(":")[0] == "embree" and "embree" not in cellrt.kinds():
            print(f"skipping {k}: this cellrt has no Embree", file=sys.stderr)
            continue
        try:
            cellrt.Accelerator(triangle, kind=None if default_kind and k == "default" else k)
        except ValueError as e:
            parser.error(f"--kinds {k}: {e}")
        args.kinds.append(k)
    if not args.kinds:
        parser.error("--kinds: none left to measure")
    return args


def main():
    parser = arguments(__doc__, "kd,bvh", 9, 0, 1024)
    parser.add_argument("--clock", choices=["wall", "cpu"], default="wall",
                        help="cpu: the process's CPU time, all threads (steadier on a shared machine)")
    args = checked(parser, parser.parse_args())
    clock = time.process_time if args.clock == "cpu" else time.perf_counter
    scene = cellrt.load_scene(args.scene)
    batches = {"camera": scene.camera.rays(args.side, args.side),
               "incoherent": incoherent_rays(scene, args.side * args.side)}
    print(f"{scene.name}: {len(scene.triangles)} triangles, batches of {args.side * args.side} rays, "
          f"threads {args.threads or os.cpu_count()}, median of {args.repeats}, {args.clock} clock")
    print(f"{'kind':6} {'rays':11} {'Python Mrays/s':>15} {'C++ Mrays/s':>12} {'ratio':>7}")
    for kind in args.kinds:
        acc = cellrt.Accelerator(scene.triangles, kind=kind, threads=args.threads)
        for name, (o, d) in batches.items():
            n = len(o)
            acc.intersect(o, d)  # warm: pages of the result arrays, the team's threads
            py, cpp = [], []
            for _ in range(args.repeats):
                start = clock()
                acc.intersect(o, d)
                py.append(clock() - start)
                cpp.extend(cellrt._native_intersect_seconds(acc, o, d, 1, args.clock))
            p, c = n / statistics.median(py) * 1e-6, n / statistics.median(cpp) * 1e-6
            print(f"{kind:6} {name:11} {p:15.2f} {c:12.2f} {p / c:7.3f}", flush=True)


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "python_bench"))
