#!/usr/bin/env python3
"""What a Python user gets from each kind: build time and rays per second, Embree beside them.

    PYTHONPATH=build/python python3 bench/python_kinds.py [SCENE] [--kinds default,auto,kd,bvh,embree]
                                                          [--threads 1] [--repeats 5] [--side 512]
                                                          [--json F [--overwrite]]

Per kind (`default` is kind=None, the library's default), the build is timed --repeats times and one
accelerator then traces, in rounds that take the kinds in turn: the camera's primary rays (SIDE x SIDE,
row-major, as `scene.camera.rays` gives them) with `intersect`, and as many incoherent rays (random
origins in the scene's box toward random triangles, as bench/python_bench.py makes them) with
`intersect` and with `occluded`. Each accelerator traces every batch once before the rounds (its
route, where it has one, learns there). With --render, each round also renders the scene at SIDE x SIDE
with `cellrt.render(scene, kind=...)`, its build included, as a caller of render meets it. Medians; the
process's CPU time (all threads)."""
import json
import statistics
import time

import cellrt
import bench_outputs
from bench_outputs import check_output
from python_bench import arguments, checked, incoherent_rays
import sys


def main():
    parser = arguments(__doc__, "default,auto,kd,bvh,embree,embree:packet16", 5, 1, 512)
    parser.add_argument("--json", help="write the medians as JSON")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing --json file")
    parser.add_argument("--render", action="store_true", help="also time a whole render, build included")
    args = checked(parser, parser.parse_args(), default_kind=True)
    if args.json:
        check_output(parser, "--json", args.json, args.overwrite)
    clock = time.process_time
    scene = cellrt.load_scene(args.scene)
    camera = scene.camera.rays(args.side, args.side)
    incoherent = incoherent_rays(scene, args.side * args.side)
    loads = {"camera": lambda a: a.intersect(*camera),
             "incoherent closest": lambda a: a.intersect(*incoherent),
             "incoherent any": lambda a: a.occluded(*incoherent)}
    kinds = args.kinds

    def build(kind):
        return cellrt.Accelerator(scene.triangles, kind=None if kind == "default" else kind, threads=args.threads)

    builds = {k: [] for k in kinds}
    for _ in range(args.repeats):
        for k in kinds:
            start = clock()
            build(k)
            builds[k].append(clock() - start)
    accels = {k: build(k) for k in kinds}
    for a in accels.values():
        for load in loads.values():
            load(a)
    times = {(k, name): [] for k in kinds for name in loads}
    renders = {k: [] for k in kinds}
    for _ in range(args.repeats):
        for k in kinds:
            for name, load in loads.items():
                start = clock()
                load(accels[k])
                times[(k, name)].append(clock() - start)
            if args.render:
                start = clock()
                cellrt.render(scene, kind=None if k == "default" else k, size=(args.side, args.side),
                              threads=args.threads)
                renders[k].append(clock() - start)
    rays = args.side * args.side
    result = []
    for k in kinds:
        row = {"kind": k, "config": accels[k].stats.name, "settings": dict(accels[k].stats.settings),
               "build_seconds": statistics.median(builds[k])}
        for name in loads:
            row[name] = rays / statistics.median(times[(k, name)]) * 1e-6
        if args.render:
            row["render_seconds"] = statistics.median(renders[k])
        result.append(row)
    embree = [r for r in result if r["kind"].startswith("embree")]
    print(f"{scene.name}: {len(scene.triangles)} triangles, {rays} rays a batch, threads {args.threads}, "
          f"median of {args.repeats}, CPU time")
    print("| kind | build ms | " + " | ".join(f"{n} Mrays/s" for n in loads) +
          (" | " + " | ".join(f"{n} ÷ Embree's best" for n in loads) if embree else "") +
          (" | render s |" if args.render else " |"))
    print("|---|--:|" + "--:|" * (len(loads) * (2 if embree else 1) + (1 if args.render else 0)))
    for r in result:
        cells = [f"{1e3 * r['build_seconds']:.1f}"] + [f"{r[n]:.2f}" for n in loads]
        if embree:
            cells += [f"{r[n] / max(e[n] for e in embree):.2f}" for n in loads]
        if args.render:
            cells.append(f"{r['render_seconds']:.3f}")
        print(f"| {r['kind']} | " + " | ".join(cells) + " |")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "python_kinds"))
