#!/usr/bin/env python3
"""The ninth round's table: auto and bvh:packet over Embree's fastest in the same run, before
(a: main without spatial splits) and after (b), median (range) over the runs of each side."""
import json
import os
import statistics

here = os.path.dirname(os.path.abspath(__file__))
scenes = ["sponza", "sibenik"]
configs = ["auto", "bvh:packet"]


def f(v):
    return f"{statistics.median(v):.2f} ({min(v):.2f}–{max(v):.2f})" if len(v) > 1 else f"{v[0]:.2f}"


print("| rays | scene | " + " | ".join(f"`{c}` before | after" for c in configs) + " |")
print("|---|---|" + "--:|--:|" * len(configs))
for kind in ["frame", "ao", "diffuse", "random"]:
    path = os.path.join(here, f"ab_{kind}.json")
    if not os.path.exists(path):
        continue
    res = {}
    for r in json.load(open(path))["runs"]:
        rows = {(x["scene"], x["config"]): x for x in r["rows"]}
        for s in scenes:
            t = lambda x: x["primary_seconds"] + x["shadow_seconds"]
            best = min(t(rows[(s, c)]) for c in ["embree:single", "embree:packet8"])
            for c in configs:
                res.setdefault((s, c, r["side"]), []).append(best / t(rows[(s, c)]))
    for s in scenes:
        cells = [f"{f(res[(s, c, 'a')])} | {f(res[(s, c, 'b')])}" for c in configs]
        print(f"| {kind} | {s} | " + " | ".join(cells) + " |")
