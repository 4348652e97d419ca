#!/usr/bin/env python3
"""The figures docs/LOCALSTORE.md quotes in its text, derived from cache-study's CSV.

usage: derive.py cache_study_*.csv   (the per-scene, per-structure files of this folder, or the whole CSV)
"""
import csv
import sys
from collections import defaultdict

rows = []
for path in sys.argv[1:]:
    with open(path, encoding="utf-8") as f:
        rows += list(csv.DictReader(f))
for r in rows:
    for k in ("node_line", "node_sets", "node_ways", "tri_line", "tri_sets", "tri_ways", "node_misses", "cycles",
              "stall_cycles"):
        r[k] = int(r[k])
    for k in ("node_hit_ratio", "tri_hit_ratio", "cycles_per_ray", "wall_s"):
        r[k] = float(r[k]) if r[k] else float("nan")  # empty: a cache the sampled rays never read

SCENES = ["teapot", "bunny", "sponza", "sibenik"]
STUDY_NODE = {"kd": "128x128", "bih": "256x64"}
key = lambda r: (r["scene"], r["structure"], r["traversal"], r["access"], r["sweep"], r["node_layout"], r["tri_layout"])
by = {key(r): r for r in rows}


def rng(vals, fmt="{:.1f}"):
    return (fmt + " .. " + fmt).format(min(vals), max(vals)) if vals else "-"


print("## wall seconds per scene (sum of runs, i.e. CPU seconds of the tracing threads)")
for s in SCENES:
    w = sum(r["wall_s"] for r in rows if r["scene"] == s)
    print(f"  {s}: {w:.1f} s = {w / 60:.2f} min")

print("\n## node sweep, sync: hit ratio of a 16 KiB direct-mapped node cache, 4096x4 and 64x256 (both traversals)")
for st in ("kd", "bih"):
    for s in SCENES:
        a = [100 * r["node_hit_ratio"] for r in rows if r["scene"] == s and r["structure"] == st and r["sweep"] == "node"
             and r["access"] == "sync" and r["node_layout"] == "4096x4"]
        b = [100 * r["node_hit_ratio"] for r in rows if r["scene"] == s and r["structure"] == st and r["sweep"] == "node"
             and r["access"] == "sync" and r["node_layout"] == "64x256"]
        print(f"  {s} {st}: 4096x4 {rng(a)} %, 64x256 {rng(b)} %")

print("\n## kd at the study's node layout (128x128, node sweep): share of cycles stalled")
for acc in ("sync", "async"):
    for s in SCENES:
        v = [100 * r["stall_cycles"] / r["cycles"] for r in rows if r["scene"] == s and r["structure"] == "kd"
             and r["sweep"] == "node" and r["access"] == acc and r["node_layout"] == "128x128"]
        print(f"  {acc} {s}: {rng(v)} %")

print("\n## async / sync cycles per node layout (node sweep), by structure and ways")
for st in ("kd", "bih"):
    for ways in (1, 4):
        ratios = []
        for r in rows:
            if r["structure"] != st or r["sweep"] != "node" or r["access"] != "async" or r["node_ways"] != ways:
                continue
            k = list(key(r)); k[3] = "sync"
            q = by[tuple(k)]
            ratios.append((r["cycles"] / q["cycles"], r["scene"], r["traversal"], r["node_layout"]))
        ratios.sort()
        print(f"  {st} ways={ways}: min {ratios[0]}, max {ratios[-1]}")
        for line in (16, 32, 64, 128, 256, 512, 1024, 2048, 4096):
            sub = [x[0] for x in ratios if int(x[3].split("x")[0]) == line]
            if sub:
                print(f"      line {line}: {rng(sub, '{:.3f}')}")

print("\n## branchless / branched cycles at the study's layouts (both caches at the study's, node sweep)")
for st in ("kd", "bih"):
    for acc in ("sync", "async"):
        for s in SCENES:
            nl = STUDY_NODE[st]
            a = by.get((s, st, "branchless", acc, "node", nl, "128x128"))
            b = by.get((s, st, "branched", acc, "node", nl, "128x128"))
            if a and b:
                print(f"  {st} {acc} {s}: {a['cycles'] / b['cycles']:.4f}")
    ratios = []
    for r in rows:
        if r["structure"] == st and r["traversal"] == "branchless":
            k = list(key(r)); k[2] = "branched"
            q = by.get(tuple(k))
            if q:
                ratios.append(r["cycles"] / q["cycles"])
    print(f"  {st}, every run: branchless/branched {rng(ratios, '{:.4f}')}")

print("\n## misses removed by 4 ways at 128 B lines: 1 - misses(128x32x4) / misses(128x128), node sweep, sync")
for st in ("kd", "bih"):
    for s in SCENES:
        for t in ("branched", "branchless"):
            a = by.get((s, st, t, "sync", "node", "128x32x4", "128x128"))
            b = by.get((s, st, t, "sync", "node", "128x128", "128x128"))
            if a and b:
                print(f"  {st} {s} {t}: {100 * (1 - a['node_misses'] / b['node_misses']):.1f} %")

print("\n## best layout the same for both traversals and access modes?")
best = defaultdict(dict)
for r in rows:
    g = (r["scene"], r["structure"], r["sweep"])
    v = (r["traversal"], r["access"])
    lay = r["node_layout"] if r["sweep"] == "node" else r["tri_layout"]
    cur = best[g].get(v)
    if cur is None or r["cycles"] < cur[0]:
        best[g][v] = (r["cycles"], lay)
    dm = best[g].get(v + ("dm",))
    ways = r["node_ways"] if r["sweep"] == "node" else r["tri_ways"]
    if ways == 1 and (dm is None or r["cycles"] < dm[0]):
        best[g][v + ("dm",)] = (r["cycles"], lay)
for g, d in sorted(best.items()):
    b = sorted({x[1] for k, x in d.items() if len(k) == 2})
    dm = sorted({x[1] for k, x in d.items() if len(k) == 3})
    flag = "" if len(b) == 1 and len(dm) == 1 else "   <-- differs"
    print(f"  {g}: best {b}, best direct-mapped {dm}{flag}")
