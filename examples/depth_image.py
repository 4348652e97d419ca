#!/usr/bin/env python3
"""Casts one ray per pixel from numpy through cellrt and plots the depth image with matplotlib.

    PYTHONPATH=build/python python3 examples/depth_image.py ../shared/scenes/sponza/sponza.json -o depth.png

The rays are the scene camera's (Camera.rays, as the renderer casts them); any (N, 3) origins and
directions would do. Misses (t = inf) show as the colour map's "bad" colour."""
import argparse
import os
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import cellrt  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default="builtin:city", help="view file, mesh or builtin:NAME")
    parser.add_argument("-o", "--output", default="depth.png", help="PNG to write")
    parser.add_argument("--size", default=None, help="WIDTHxHEIGHT (default: the scene's)")
    parser.add_argument("--kind", default="kd", help="accelerator kind (%s)" % ", ".join(cellrt.kinds()))
    parser.add_argument("--overwrite", action="store_true", help="replace the output if it exists")
    args = parser.parse_args()
    if os.path.exists(args.output) and not args.overwrite:
        sys.exit(f"{args.output} exists (use --overwrite)")
    try:
        scene = cellrt.load_scene(args.scene)
        width, height = scene.size if args.size is None else map(int, args.size.split("x"))
        origins, directions = scene.camera.rays(width, height)
        acc = cellrt.Accelerator(scene.triangles, kind=args.kind)
        hits = acc.intersect(origins, directions)
    except ValueError as e:  # cellrt.Error included
        sys.exit(f"depth_image: {e}")
    depth = np.where(hits["prim"] >= 0, hits["t"], np.nan).reshape(height, width)
    figure, axes = plt.subplots(figsize=(width / 100 + 1.5, height / 100 + 0.5), dpi=100)
    shown = axes.imshow(depth, cmap="viridis_r")
    axes.set_axis_off()
    axes.set_title(f"{scene.name}: distance along the camera ray ({acc.stats.name}, {len(scene.triangles)} triangles)",
                   fontsize=8)
    figure.colorbar(shown, ax=axes, shrink=0.8)
    # Written beside the target and renamed into place: an interrupted run leaves no partial file.
    folder = os.path.dirname(os.path.abspath(args.output))
    with tempfile.NamedTemporaryFile(dir=folder, suffix=".png", delete=False) as tmp:
        figure.savefig(tmp, format="png")
    os.replace(tmp.name, args.output)
    print(f"{args.output}: {width}x{height}, {np.isfinite(depth).mean():.1%} of the rays hit")


if __name__ == "__main__":
    main()
