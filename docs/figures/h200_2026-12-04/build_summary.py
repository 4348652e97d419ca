#!/usr/bin/env python3
"""Build times on 1 and 16 threads (builds_t1/t16.json, builds_forest_t1/t16.json) and the curve over
1 to 16 threads (build_curve_tN.json), from cellrt_bench's JSON (docs/BUILD_SPEED.md)."""
import json
import os

here = os.path.dirname(os.path.abspath(__file__))


def load(name):
    return {(r["scene"], r["config"]): r["build_seconds"] for r in json.load(open(os.path.join(here, name)))}


one = {**load("builds_t1.json"), **load("builds_forest_t1.json")}
many = {**load("builds_t16.json"), **load("builds_forest_t16.json")}
print("| scene | kd: 1 / 16 threads ms, speed-up | SAH BIH | Embree | kd ÷ Embree, 1 / 16 threads | SAH BIH ÷ Embree |")
print("|---|---|---|---|---|---|")
for scene in dict.fromkeys(s for s, _ in one):
    cells = []
    for c in ("kd", "bih@split=sah", "embree"):
        a, b = one[(scene, c)], many[(scene, c)]
        cells.append(f"{a * 1e3:.1f} / {b * 1e3:.1f}, **{a / b:.1f}**")
    for c in ("kd", "bih@split=sah"):
        cells.append(f"{one[(scene, c)] / one[(scene, 'embree')]:.1f} / {many[(scene, c)] / many[(scene, 'embree')]:.1f}")
    print(f"| {scene} | " + " | ".join(cells) + " |")
print()
curve = {t: load(f"build_curve_t{t}.json") for t in (1, 2, 4, 8, 16)}
print("| scene | structure | " + " | ".join(f"{t} threads" for t in curve) + " |")
print("|---|---|" + "---|" * len(curve))
for scene, config in sorted(curve[1]):
    base = curve[1][(scene, config)]
    print(f"| {scene} | {config} | " +
          " | ".join(f"{curve[t][(scene, config)] * 1e3:.1f} ms ({base / curve[t][(scene, config)]:.1f} ×)" for t in curve) + " |")
