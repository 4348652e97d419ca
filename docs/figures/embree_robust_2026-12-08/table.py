#!/usr/bin/env python3
"""Embree robust (cellrt's yardstick) against Embree's own default (robust=false), and cellrt's paths
against both: total rays per second (primary + second kind) of each configuration in each run,
medians over the runs. Usage: table.py frame_?.json ao_?.json diffuse_?.json random_?.json (prints
Markdown; not kdsingle_?.json, whose frame runs hold other configurations beside Embree's)."""
import json
import statistics
import sys
from collections import defaultdict

rate = defaultdict(list)  # (rays, scene, config) -> [Mrays/s per run]
for path in sys.argv[1:]:
    for r in json.load(open(path)):
        seconds = r["primary_seconds"] + r["shadow_seconds"]
        rate[(r["rays"], r["scene"], r["config"])].append((r["primary_rays"] + r["shadow_rays"]) / seconds * 1e-6)

def best(rays, scene, configs):
    return max(statistics.median(rate[(rays, scene, c)]) for c in configs if (rays, scene, c) in rate)

robust = ["embree:single", "embree:packet8", "embree:packet16"]
plain = [c + "@robust=false" for c in robust]
cellrt = ["bvh:paired", "bvh:packet", "bvh:stream", "auto"]
print("| rays | scene | Embree's best, robust=false ÷ robust | rtcIntersect1/rtcOccluded1, robust=false ÷ robust | "
      "cellrt's best ÷ Embree's best, robust (the yardstick) | the same ÷ Embree's best, robust=false | which cellrt path |")
print("|---|---|--:|--:|--:|--:|---|")
for rays in ("frame", "ao", "diffuse", "random"):
    for scene in ("sponza", "sibenik", "bunny", "teapot"):
        if (rays, scene, "auto") not in rate:
            continue
        e_r, e_p = best(rays, scene, robust), best(rays, scene, plain)
        single = statistics.median(rate[(rays, scene, plain[0])]) / statistics.median(rate[(rays, scene, robust[0])])
        c = best(rays, scene, cellrt)
        which = max((k for k in cellrt if (rays, scene, k) in rate), key=lambda k: statistics.median(rate[(rays, scene, k)]))
        print(f"| {rays} | {scene} | {e_p / e_r:.2f} | {single:.2f} | {c / e_r:.2f} | {c / e_p:.2f} | `{which}` |")
