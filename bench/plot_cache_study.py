#!/usr/bin/env python3
"""Draws the study's cache graphs (Hapala, section 5.2) from the CSV of `cellrt cache-study`, one PNG
per graph and scene:

  5-1 / 5-3   node-cache hit ratio vs line size, kd / BIH (triangle cache 128 x 128)
  5-2 / 5-4   modelled frame time vs node-cache layout, kd / BIH (the kernels' measured time where
              every row's cycles are 0: a CSV of cache-study --device cuda)
  5-5 / 5-6   asynchronous vs synchronous access: time ratio per node-cache layout, kd / BIH
  5-7 / 5-9   triangle-cache hit ratio vs line size, kd / BIH (node cache at the study's best)
  5-8 / 5-10  modelled frame time vs triangle-cache layout, kd / BIH (likewise)

One line per number of sets: solid direct-mapped, dashed 4-way. Hit ratios are drawn for the
branchless traversal where the CSV has it, and its title says which: the kd-tree's branched
traversal reads the same lines, the BIH's does not (its branchless traversal visits more nodes;
docs/LOCALSTORE.md), so a BIH graph stands for its branchless runs only.

usage: bench/plot_cache_study.py [--overwrite] cache_study.csv OUTDIR

A graph already in OUTDIR is replaced only with --overwrite (the run stops at the first such file).
"""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import bench_outputs

GRAPHS = {  # (structure, sweep) -> graph numbers: hit ratio, time, async vs sync
    ("kd", "node"): ("5-1", "5-2", "5-5"),
    ("bih", "node"): ("5-3", "5-4", "5-6"),
    ("kd", "triangle"): ("5-7", "5-8", None),
    ("bih", "triangle"): ("5-9", "5-10", None),
}


def layout_of(row, sweep):
    prefix = "node" if sweep == "node" else "tri"
    return int(row[prefix + "_line"]), int(row[prefix + "_sets"]), int(row[prefix + "_ways"])


def curves(rows, sweep, value):
    """{(ways, sets): [(line, value), ...]} sorted by line size."""
    out = defaultdict(list)
    for r in rows:
        line, sets, ways = layout_of(r, sweep)
        out[(ways, sets)].append((line, value(r)))
    return {k: sorted(v) for k, v in sorted(out.items())}


def draw(ax, lines, ylabel, title):
    colours = {}
    for (ways, sets), pts in lines.items():
        colour = colours.setdefault(sets, f"C{len(colours)}")
        label = f"{sets} set" + ("" if sets == 1 else "s") + ("" if ways == 1 else " x 4 ways")
        ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", markersize=3, color=colour,
                linestyle="-" if ways == 1 else "--", label=label)
    ax.set_xscale("log", base=2)
    ax.set(xlabel="line size (bytes)", ylabel=ylabel, title=title)
    ax.grid(True, alpha=0.3)


OVERWRITE = "--overwrite" in sys.argv
if OVERWRITE:
    sys.argv.remove("--overwrite")


def save(fig, outdir, graph, scene, what):
    path = os.path.join(outdir, f"graph_{graph}_{scene}_{what}.png")
    if os.path.exists(path) and not OVERWRITE:
        raise ValueError(f"{path}: file exists (pass --overwrite to replace it)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(path)


def hit_ratio(row, cache):
    """The row's hit ratio in per cent; NaN (a gap in the curve) where the cache had no reads."""
    value = row[cache + "_hit_ratio"]
    return 100.0 * float(value) if value else float("nan")


COLUMNS = {"scene", "structure", "traversal", "access", "sweep", "node_line", "node_sets", "node_ways", "tri_line",
           "tri_sets", "tri_ways", "node_hit_ratio", "tri_hit_ratio", "cycles", "frame_ms"}


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    try:
        with open(sys.argv[1], encoding="utf-8", newline="") as f:
            reader = csv.DictReader(f)
            missing = COLUMNS - set(reader.fieldnames or [])
            if missing:
                raise ValueError(f"{sys.argv[1]}: not a cache-study CSV (no column {', '.join(sorted(missing))})")
            rows = list(reader)
        if not rows:
            raise ValueError(f"{sys.argv[1]}: no results, only the header")
        os.makedirs(sys.argv[2], exist_ok=True)
    except (OSError, ValueError) as e:
        print(f"plot_cache_study.py: error: {e}", file=sys.stderr)
        return 1
    outdir = sys.argv[2]
    groups = defaultdict(list)  # (scene, structure, sweep) -> rows
    for r in rows:
        groups[(r["scene"], r["structure"], r["sweep"])].append(r)

    for (scene, structure, sweep), rs in sorted(groups.items()):
        hit_graph, time_graph, async_graph = GRAPHS[(structure, sweep)]
        cache = "node" if sweep == "node" else "tri"
        name = "node cache" if sweep == "node" else "triangle cache"
        accesses = sorted({r["access"] for r in rs}, reverse=True)  # sync first
        traversals = sorted({r["traversal"] for r in rs})
        hit_traversal = "branchless" if "branchless" in traversals else traversals[0]

        fig, axes = plt.subplots(1, len(accesses), figsize=(5.5 * len(accesses), 4.2), squeeze=False)
        for ax, access in zip(axes[0], accesses):
            sel = [r for r in rs if r["access"] == access and r["traversal"] == hit_traversal]
            draw(ax, curves(sel, sweep, lambda r: hit_ratio(r, cache)), "hit ratio (%)",
                 f"{scene}, {structure} {hit_traversal}: {name}, {access}")
        axes[0][-1].legend(fontsize=7)
        save(fig, outdir, hit_graph, scene, f"{structure}_{sweep}_hit_ratio")

        # The device's runs model nothing: their frame_ms is the kernels' own measured time (cycles 0).
        kind = "measured" if all(float(r["cycles"]) == 0 for r in rs) else "modelled"
        panels = [(t, a) for t in traversals for a in accesses]
        fig, axes = plt.subplots(1, len(panels), figsize=(4.8 * len(panels), 4.2), squeeze=False, sharey=True)
        for ax, (traversal, access) in zip(axes[0], panels):
            sel = [r for r in rs if r["access"] == access and r["traversal"] == traversal]
            draw(ax, curves(sel, sweep, lambda r: float(r["frame_ms"])), f"{kind} ms per frame",
                 f"{structure} {traversal}, {access}")
        axes[0][-1].legend(fontsize=7)
        fig.suptitle(f"{scene}: {kind} time vs {name} layout")
        save(fig, outdir, time_graph, scene, f"{structure}_{sweep}_time")

        if async_graph and len(accesses) == 2:
            fig, axes = plt.subplots(1, len(traversals), figsize=(5.5 * len(traversals), 4.2), squeeze=False,
                                     sharey=True)
            for ax, traversal in zip(axes[0], traversals):
                ms = {(layout_of(r, sweep), r["access"]): float(r["frame_ms"]) for r in rs
                      if r["traversal"] == traversal}
                ratio = [dict(r, ratio=ms[(layout_of(r, sweep), "async")] / ms[(layout_of(r, sweep), "sync")])
                         for r in rs if r["traversal"] == traversal and r["access"] == "sync"]
                draw(ax, curves(ratio, sweep, lambda r: r["ratio"]), "async time / sync time",
                     f"{structure} {traversal}")
                ax.axhline(1.0, color="black", linewidth=0.8)
            axes[0][-1].legend(fontsize=7)
            fig.suptitle(f"{scene}: asynchronous vs synchronous access (below 1: async is faster)")
            save(fig, outdir, async_graph, scene, f"{structure}_async_vs_sync")
    return 0


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "plot_cache_study"))
