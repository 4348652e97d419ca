#!/usr/bin/env python3
"""The eighth round's tables: auto (and bvh:packet) over Embree's fastest in the same run, per run,
median (range), old route (a) against new (b)."""
import glob
import json
import os
import statistics

here = os.path.dirname(os.path.abspath(__file__))
scenes = ["sponza", "sibenik", "bunny", "teapot"]


def f(v):
    return f"{statistics.median(v):.2f} ({min(v):.2f}–{max(v):.2f})"


print("| rays | scene | `auto` before | `auto` after | `bvh:packet` |")
print("|---|---|--:|--:|--:|")
for kind in ["frame", "ao", "diffuse", "random"]:
    d = json.load(open(os.path.join(here, f"ab_{kind}.json")))
    res = {}
    for r in d["runs"]:
        rows = {(x["scene"], x["config"]): x for x in r["rows"]}
        for s in scenes:
            t = lambda x: x["primary_seconds"] + x["shadow_seconds"]
            best = min(t(rows[(s, c)]) for c in ["embree:single", "embree:packet8"])
            for c in ["auto", "bvh:packet"]:
                res.setdefault((s, c, r["side"]), []).append(best / t(rows[(s, c)]))
    for s in scenes:
        packets = res[(s, "bvh:packet", "a")] + res[(s, "bvh:packet", "b")]
        print(f"| {kind} | {s} | {f(res[(s, 'auto', 'a')])} | {f(res[(s, 'auto', 'b')])} | {f(packets)} |")

print()
print("| shading | scene | `auto` before | `auto` after |")
print("|---|---|--:|--:|")
for shading in ["direct", "ao", "diffuse"]:
    res = {}
    for path in sorted(glob.glob(os.path.join(here, f"two_{shading}_*.json"))):
        side = os.path.basename(path).split("_")[2]
        for row in json.load(open(path)):
            if row["config"] == "auto":
                res.setdefault((row["scene"], side), []).append(row["embree_seconds"] / row["seconds"])
    for s in scenes:
        print(f"| {shading} | {s} | {f(res[(s, 'a')])} | {f(res[(s, 'b')])} |")
