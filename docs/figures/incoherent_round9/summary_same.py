#!/usr/bin/env python3
"""The ninth round's same-run table (run_same_binary.sh): the BVH without spatial splits
(split_budget=0) and with them (the default), single rays and packets, over Embree's fastest in the
same run; median over the runs, and the median over the runs of each run's time ratio."""
import glob
import json
import os
import statistics

here = os.path.dirname(os.path.abspath(__file__))
scenes = ["sponza", "sibenik", "bunny", "teapot"]
t = lambda x: x["primary_seconds"] + x["shadow_seconds"]
med = statistics.median

print("| rays | scene | `bvh` without ÷ Embree | with | speed-up | `bvh:packet` without | with | speed-up |")
print("|---|---|--:|--:|--:|--:|--:|--:|")
builds = {}
for kind in ["frame", "ao", "diffuse", "random"]:
    runs = [json.load(open(p)) for p in sorted(glob.glob(os.path.join(here, f"same_{kind}_*.json")))]
    if not runs:
        continue
    for s in scenes:
        cells = []
        for c in ["bvh", "bvh:packet"]:
            old, new, gain = [], [], []
            for run in runs:
                rows = {r["config"]: r for r in run if r["scene"] == s}
                best = min(t(rows["embree:single"]), t(rows["embree:packet8"]))
                o, n = rows[f"{c}@split_budget=0"], rows[c]
                old.append(best / t(o))
                new.append(best / t(n))
                gain.append(t(o) / t(n))
                builds.setdefault(s, []).append((1e3 * o["build_seconds"], 1e3 * n["build_seconds"], 1e3 * rows["embree:single"]["build_seconds"],
                                                 o["memory_mib"], n["memory_mib"]))
            cells += [f"{med(old):.2f}", f"{med(new):.2f}", f"{med(gain):.2f}"]
        print(f"| {kind} | {s} | " + " | ".join(cells) + " |")
print()
print("| scene | build ms without → with (÷ Embree's) | memory MiB without → with |")
print("|---|---|---|")
for s, b in builds.items():
    print(f"| {s} | {med(x[0] for x in b):.1f} → {med(x[1] for x in b):.1f} "
          f"({med(x[0] / x[2] for x in b):.2f} → {med(x[1] / x[2] for x in b):.2f}) | "
          f"{med(x[3] for x in b):.2f} → {med(x[4] for x in b):.2f} |")
