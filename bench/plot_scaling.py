#!/usr/bin/env python3
"""Draws the scaling curves of cellrt_scaling's JSON: seconds per frame and parallel efficiency
against workers, one figure per scene, one line per structure, dispatch mode and packet size.

usage: bench/plot_scaling.py scaling.json OUTDIR
"""
import json
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    with open(sys.argv[1], encoding="utf-8") as f:
        points = json.load(f)
    os.makedirs(sys.argv[2], exist_ok=True)
    by_scene = defaultdict(lambda: defaultdict(list))
    for p in points:
        key = f'{p["config"]} {p["dispatch"]} {p["packet"]}x{p["packet"]}'
        by_scene[p["scene"]][key].append((p["workers"], p["seconds"]))
    for scene, lines in by_scene.items():
        fig, (ax_t, ax_e) = plt.subplots(1, 2, figsize=(11, 4.2))
        for key, pts in sorted(lines.items()):
            pts.sort()
            w = [x for x, _ in pts]
            t = [y for _, y in pts]
            base = t[0] * w[0]
            ax_t.plot(w, t, marker="o", label=key)
            ax_e.plot(w, [base / (ti * wi) for wi, ti in pts], marker="o", label=key)
        ax_t.set(xlabel="workers", ylabel="seconds per frame", title=f"{scene}: time", yscale="log")
        ax_e.set(xlabel="workers", ylabel="parallel efficiency", title=f"{scene}: efficiency", ylim=(0, 1.1))
        ax_e.legend(fontsize=7)
        fig.tight_layout()
        out = os.path.join(sys.argv[2], f"scaling_{scene}.png")
        fig.savefig(out, dpi=110)
        print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
