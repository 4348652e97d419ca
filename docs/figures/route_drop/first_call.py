#!/usr/bin/env python3
"""The cost of the route's learning as a Python caller meets it: a fresh accelerator's first call
against its second on the same rays, one thread (1,024-ray chunks: 1,024 batches per call), CPU time.

    PYTHONPATH=BUILD/python /usr/bin/python3 docs/figures/route_drop/first_call.py SCENE OUT.json [--rounds 5]

Per kind (`default`: kind=None, and `auto`) and batch (camera rays, 1024 x 1024 in row order; as many
scattered rays, closest and any hit, bench/python_bench.py's), each round builds the accelerator anew
and times its first and second call; the medians and first ÷ second go to OUT.json."""
import argparse
import json
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "bench"))
import cellrt  # noqa: E402
from python_bench import incoherent_rays  # noqa: E402

parser = argparse.ArgumentParser()
parser.add_argument("scene")
parser.add_argument("out")
parser.add_argument("--rounds", type=int, default=5)
args = parser.parse_args()
scene = cellrt.load_scene(args.scene)
camera = scene.camera.rays(1024, 1024)
scattered = incoherent_rays(scene, 1024 * 1024)
loads = {"camera": lambda a: a.intersect(*camera), "scattered closest": lambda a: a.intersect(*scattered),
         "scattered any": lambda a: a.occluded(*scattered)}
times = {}
for _ in range(args.rounds):
    for kind in ("default", "auto"):
        for name, load in loads.items():
            acc = cellrt.Accelerator(scene.triangles, kind=None if kind == "default" else kind, threads=1)
            calls = []
            for _ in range(2):
                start = time.process_time()
                load(acc)
                calls.append(time.process_time() - start)
            times.setdefault((kind, name), []).append(calls)
result = []
for (kind, name), calls in times.items():
    first, second = statistics.median(c[0] for c in calls), statistics.median(c[1] for c in calls)
    result.append({"scene": scene.name, "kind": kind, "rays": name, "first_s": first, "second_s": second,
                   "first_over_second": statistics.median(c[0] / c[1] for c in calls)})
    print(f"{scene.name:8} {kind:8} {name:18} first {first:.3f} s, second {second:.3f} s, "
          f"first / second {result[-1]['first_over_second']:.3f}")
with open(args.out, "w") as f:
    json.dump(result, f, indent=1)
