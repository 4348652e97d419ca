#!/usr/bin/env python3
"""The issue's targets from cellrt_gpu_bench's JSON files (docs/GPU.md). The first file's configurations
give each structure's fastest in memory mode (a) (resident rays, Grays/s); every file is one run beside
its own Embree yardstick (--cpu-config: rtcIntersect1, packets of 8, packets of 16), and the ratio is
the lowest over the runs of (that run's fastest of the structure) / (that run's Embree), so that each
ratio is taken within one run. Then memory mode (b) against mode (a) in the first file.
Usage: gpu_summary.py gpu_bench.json [gpu_bench_packet8.json ...]"""
import json
import sys

runs = [json.load(open(f)) for f in sys.argv[1:]]


def fastest(row, kind, ray_set):
    mode_a = [g for g in row["gpu"] if g["config"].startswith(kind) and "memory=shared" not in g["config"]]
    return max(mode_a, key=lambda g: g[ray_set]["grays_per_s"]) if mode_a else None


def find(run, row):
    return next((r for r in run if r["scene"] == row["scene"] and r["rays"] == row["rays"]), None)


print("| scene | rays | kd: fastest, primary / secondary Grays/s | × Embree's fastest | "
      "BIH: fastest, primary / secondary Grays/s | × Embree's fastest | Embree's fastest, 16 cores |")
print("|---|---|---|---|---|---|---|")
for row in runs[0]:
    sec = row["secondary_kind"]
    cells = []
    for kind in ("kd", "bih"):
        p, s = fastest(row, kind, "primary"), fastest(row, kind, sec)
        ratios = {"primary": [], sec: []}
        for run in runs:
            other = find(run, row)
            for ray_set in ratios:
                g = other and fastest(other, kind, ray_set)
                if g:
                    ratios[ray_set].append(g[ray_set]["grays_per_s"] / other["cpu"][ray_set]["grays_per_s"])
        cells.append(f"{p['config']} {p['primary']['grays_per_s']:.2f} / {s['config']} {s[sec]['grays_per_s']:.2f}")
        cells.append(f"{min(ratios['primary']):.1f} / {min(ratios[sec]):.1f}")
    best = {k: max(find(run, row)["cpu"][k]["grays_per_s"] for run in runs if find(run, row)) for k in ("primary", sec)}
    print(f"| {row['scene']} | {row['rays']} ({sec}) | {' | '.join(cells)} | "
          f"{best['primary'] * 1e3:.0f} / {best[sec] * 1e3:.0f} Mrays/s |")
print()
print("| scene | rays | kd: mode (b)'s fastest ÷ mode (a)'s kd:branched, primary / secondary | BIH, the same |")
print("|---|---|---|---|")
for row in runs[0]:
    sec = row["secondary_kind"]
    cells = []
    for kind in ("kd", "bih"):
        a = next(g for g in row["gpu"] if g["config"] == f"{kind}:branched")
        b = [g for g in row["gpu"] if g["config"].startswith(kind) and "memory=shared" in g["config"]]
        bp = max(g["primary"]["grays_per_s"] for g in b)
        bs = max(g[sec]["grays_per_s"] for g in b)
        cells.append(f"{bp / a['primary']['grays_per_s']:.3f} / {bs / a[sec]['grays_per_s']:.3f}")
    print(f"| {row['scene']} | {row['rays']} | {' | '.join(cells)} |")
