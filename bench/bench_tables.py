#!/usr/bin/env python3
"""Markdown tables of cellrt_bench's JSON for docs/BENCHMARKS.md: one table per scene, every
configuration's build time, memory, rays per second and its ratios to Embree's rtcIntersect1 and to
Embree's fastest configuration in the same run.

usage: bench/bench_tables.py bench.json [CONFIG ...]   (only the named configurations, if given)
"""
import sys
import bench_outputs


def total(r):
    return (r["primary_rays"] + r["shadow_rays"]) / (r["primary_seconds"] + r["shadow_seconds"]) * 1e-6


def main() -> int:
    if len(sys.argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    rows = bench_outputs.load_json(sys.argv[1], rows=True)
    only = set(sys.argv[2:])
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    for scene in scenes:
        rs = [r for r in rows if r["scene"] == scene]
        embree = [r for r in rs if r["config"].startswith("embree")]
        # rtcIntersect1: `embree:single`, or `embree` alone (its default); the first, as cellrt_bench takes it.
        single = next((r for r in embree if r["config"] in ("embree:single", "embree")), None)
        best = max(embree, key=total, default=None)
        r0 = rs[0]
        second = r0.get("shadow_kind", "shadow")  # the second kind of rays: shadow, ao or bounce
        print(f"\n**{scene}** ({r0['triangles']:,} triangles, {r0['width']}x{r0['height']}, "
              f"{r0['primary_rays']:,} primary + {r0['shadow_rays']:,} {second} rays)\n")
        print(f"| config | build ms | memory MiB | primary Mrays/s | {second} Mrays/s | total Mrays/s | "
              "× rtcIntersect1 | × Embree best | nodes / leaves / tris per primary ray |")
        print("|---|---|---|---|---|---|---|---|---|")
        for r in rs:
            if only and r["config"] not in only:
                continue
            w = r["primary_per_ray"]
            work = "–" if r["config"].startswith("embree") else \
                f"{w['nodes']:.1f} / {w['leaves']:.1f} / {w['triangles']:.1f}"
            ratio = lambda y: f"{total(r) / total(y):.2f}" if y else "–"
            print(f"| {r['config']} | {r['build_seconds'] * 1e3:.1f} | {r['memory_mib']:.2f} | "
                  f"{r['primary_rays'] / r['primary_seconds'] * 1e-6:.2f} | "
                  f"{r['shadow_rays'] / r['shadow_seconds'] * 1e-6:.2f} | {total(r):.2f} | {ratio(single)} | "
                  f"{ratio(best)} | {work} |")
    return 0


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "bench_tables"))
