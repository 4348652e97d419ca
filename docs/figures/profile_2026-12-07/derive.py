#!/usr/bin/env python3
"""The figures docs/PROFILE.md quotes in its text ("Reading"), from bench/profile_table.py's --json-out file.

usage: derive.py profile_rows_run1.json
"""
import json
import sys

rows = json.load(open(sys.argv[1]))
by = {(r["scene"], r["accel"], r["traversal"]): r for r in rows}
tr = lambda r: r["regions"]["traversal"]
wr = lambda r: r["regions"]["render"]
n = lambda r: r["rays"]["all"]
for scene in ("sponza", "sibenik", "bunny", "teapot"):
    for accel in ("kd", "bih"):
        a, b = by[(scene, accel, "branchless")], by[(scene, accel, "branched")]
        nodes_b = b["work"]["per_ray"]["nodes"]
        di = tr(a)["per_ray"]["instructions"] - tr(b)["per_ray"]["instructions"]
        dm = tr(b)["per_ray"]["mispredictions"] - tr(a)["per_ray"]["mispredictions"]
        dbr = (tr(b)["branches"] - tr(a)["branches"]) / n(a)
        print(f"{scene} {accel}: branchless/branched instructions {tr(a)['instructions'] / tr(b)['instructions']:.3f}, "
              f"mispredictions {tr(a)['mispredictions'] / tr(b)['mispredictions']:.3f}; per ray +{di:.0f} instructions, "
              f"-{dm:.2f} mispredictions, -{dbr:.1f} branches; per branched inner node: +{di / nodes_b:.1f} instructions, "
              f"-{dm / nodes_b:.2f} mispredictions, -{dbr / nodes_b:.2f} branches; nodes branchless/branched "
              f"{a['work']['per_ray']['nodes'] / nodes_b:.3f}")
    r, b = by[(scene, "kd", "rec")], by[(scene, "kd", "branched")]
    print(f"{scene} kd rec/branched: instructions {tr(r)['instructions'] / tr(b)['instructions']:.3f}, "
          f"mispredictions {tr(r)['mispredictions'] / tr(b)['mispredictions']:.3f}")
rates = [100 * tr(r)["mispredictions"] / tr(r)["branches"] for r in rows]
print(f"traversal misprediction rates {min(rates):.1f} .. {max(rates):.1f} %")
for r in rows:
    own = wr(r)["per_ray"]["instructions"] - tr(r)["per_ray"]["instructions"]
    share = 100 * tr(r)["instructions"] / wr(r)["instructions"]
    print(f"{r['scene']} {r['accel']} {r['traversal']}: renderer's own {own:.0f} instructions per ray, "
          f"traversal share {share:.1f} %, native {1e3 * r['native_render_cpu_seconds']:.1f} ms")
