#!/usr/bin/env python3
"""Before/after table of cellrt_bench builds for docs/BUILD_SPEED.md: per scene and configuration, the
build time of two binaries (each run with Embree's default build, whose ratio is given), the SAH costs
and the traversal speeds (primary + second kind of rays), from their --json files.

usage: bench/build_speed_table.py BEFORE.json AFTER.json   (several runs: BEFORE1.json,BEFORE2.json ...)
"""
import statistics
import sys
import bench_outputs


def load(arg):
    rows = []
    for path in arg.split(","):
        rows += bench_outputs.load_json(path, rows=True)
    return rows


def total(r):
    return (r["primary_rays"] + r["shadow_rays"]) / (r["primary_seconds"] + r["shadow_seconds"]) * 1e-6


def summary(rows):
    """(scene, config) -> medians over runs of build ms, ratio to Embree's build, Mrays/s, and the SAH cost."""
    runs = {}
    for r in rows:
        runs.setdefault((r["scene"], r["config"]), []).append(r)
    embree = {}
    for (scene, config), rs in runs.items():
        if config.startswith("embree") and scene not in embree:
            embree[scene] = statistics.median(x["build_seconds"] for x in rs)
    out = {}
    for (scene, config), rs in runs.items():
        build = statistics.median(x["build_seconds"] for x in rs)
        out[(scene, config)] = {
            "triangles": rs[0]["triangles"],
            "build_ms": build * 1e3,
            "x_embree": build / embree[scene] if scene in embree else float("nan"),
            "mrays": statistics.median(total(x) for x in rs),
            "sah": rs[0].get("sah_cost", 0.0),
            "peak": statistics.median(x.get("build_peak_mib", 0.0) for x in rs),
        }
    return out


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    before, after = summary(load(sys.argv[1])), summary(load(sys.argv[2]))
    print("| scene | config | build ms before → after | ÷ Embree before → after | after ÷ before | "
          "SAH cost before → after | Mrays/s before → after | build peak MiB after |")
    print("|---|---|---|---|---|---|---|---|")
    for key, a in after.items():
        b = before.get(key)
        if not b:
            continue
        scene, config = key
        sah = f"{b['sah']:.2f} → {a['sah']:.2f}" if a["sah"] else "–"
        print(f"| {scene} ({a['triangles']:,}) | {config} | {b['build_ms']:.1f} → {a['build_ms']:.1f} | "
              f"{b['x_embree']:.2f} → {a['x_embree']:.2f} | {a['build_ms'] / b['build_ms']:.2f} | {sah} | "
              f"{b['mrays']:.2f} → {a['mrays']:.2f} | {a['peak']:.1f} |")
    return 0


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "build_speed_table"))
