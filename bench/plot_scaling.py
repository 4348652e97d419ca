#!/usr/bin/env python3
"""Draws the scaling curves of cellrt_scaling's JSON: per scene, seconds per frame and parallel
efficiency against workers, one row per dispatch mode; colour = structure, line style = packet size.

usage: bench/plot_scaling.py [--overwrite] scaling.json [more.json ...] OUTDIR   (Debian's python3,
       python3-matplotlib)

A figure already in OUTDIR is replaced only with --overwrite.

Several runs are drawn together; a point that more than one of them measured is taken from the first.
Runs of one scene must have measured the same frames (the shading, its AO samples and, within 1 %,
the frame's rays, which the frame size sets): otherwise the script names the two files and draws nothing, as one
curve would join points of different work. The efficiency is the JSON's own (the median of each
round's ratio to the fewest workers) where it has one, else t(first) first / (t(N) N) from the medians.
"""
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import bench_outputs

STYLES = ["-", "--", ":", "-."]


def main() -> int:
    args = sys.argv[1:]
    overwrite = "--overwrite" in args
    args = [a for a in args if a != "--overwrite"]
    if len(args) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    *inputs, outdir = args
    seen = set()
    frames = {}  # scene -> (what its frames were, the file that said so)
    # scene -> dispatch -> (config, packet) -> [(workers, seconds, efficiency or None)]
    data = defaultdict(lambda: defaultdict(lambda: defaultdict(list)))
    try:
        for path in inputs:
            points = bench_outputs.load_json(path, rows=True)
            for p in points:
                frame = (p.get("shading", "direct"), p.get("ao_samples"), p["rays"])
                first, other = frames.setdefault(p["scene"], (frame, path))
                # The rays within 1 %: the structures' shadow rays may differ by a hit or two (Embree's
                # test is not cellrt's), another frame size by far more.
                if first[:2] != frame[:2] or abs(first[2] - frame[2]) > 0.01 * first[2]:
                    raise ValueError(f"{path} and {other} traced other frames of {p['scene']} (shading, AO samples "
                                     f"and rays: {frame} against {first}): draw them apart")
                key = (p["scene"], p["dispatch"], p["config"], p["packet"], p["workers"])
                if key in seen:
                    continue
                seen.add(key)
                data[p["scene"]][p["dispatch"]][(p["config"], p["packet"])].append(
                    (p["workers"], p["seconds"], p.get("efficiency")))
        os.makedirs(outdir, exist_ok=True)
        for scene in data:
            out = os.path.join(outdir, f"scaling_{scene}.png")
            if os.path.exists(out) and not overwrite:
                raise ValueError(f"{out}: file exists (pass --overwrite to replace it)")
    except (OSError, ValueError, KeyError, TypeError, bench_outputs.InputError) as e:
        print(f"plot_scaling.py: error: {e if not isinstance(e, KeyError) else f'a point has no {e}'}",
              file=sys.stderr)
        return 1
    for scene, by_dispatch in data.items():
        dispatches = sorted(by_dispatch)
        configs = sorted({c for d in by_dispatch.values() for c, _ in d})
        packets = sorted({p for d in by_dispatch.values() for _, p in d})
        colour = {c: f"C{i}" for i, c in enumerate(configs)}
        style = {p: STYLES[i % len(STYLES)] for i, p in enumerate(packets)}
        shading = frames[scene][0][0]
        highest = 0.0  # the efficiency axis reaches the highest point (a noisy short run passes 1)
        fig, axes = plt.subplots(len(dispatches), 2, figsize=(11, 3.6 * len(dispatches)), squeeze=False)
        for row, d in enumerate(dispatches):
            ax_t, ax_e = axes[row]
            for (config, packet), pts in sorted(by_dispatch[d].items()):
                pts.sort(key=lambda x: x[0])
                w = [x for x, _, _ in pts]
                t = [y for _, y, _ in pts]
                label = f"{config} {packet}x{packet}"
                kw = dict(color=colour[config], linestyle=style[packet], marker="o", label=label)
                ax_t.plot(w, t, **kw)
                eff = [e if e is not None else t[0] * w[0] / (ti * wi) for wi, ti, e in pts]
                highest = max([highest] + eff)
                ax_e.plot(w, eff, **kw)
            ax_t.set(xlabel="workers", ylabel="seconds per frame", title=f"{scene} ({shading}), {d}: time",
                     yscale="log")
            ax_e.set(xlabel="workers", ylabel="parallel efficiency", title=f"{scene} ({shading}), {d}: efficiency")
            for ax in (ax_t, ax_e):
                ax.set_xticks(sorted({x for pts in by_dispatch[d].values() for x, _, _ in pts}))
        for ax in axes[:, 1]:
            ax.set_ylim(0, max(1.15, 1.05 * highest))
        legend = {}  # every curve of every row, once
        for ax in axes.flat:
            for handle, label in zip(*ax.get_legend_handles_labels()):
                legend.setdefault(label, handle)
        fig.legend(list(legend.values()), list(legend), loc="center right", fontsize=7)
        fig.tight_layout(rect=(0, 0, 0.8, 1))
        out = os.path.join(outdir, f"scaling_{scene}.png")
        fig.savefig(out, dpi=100)
        plt.close(fig)
        print(out)
    return 0


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "plot_scaling"))
