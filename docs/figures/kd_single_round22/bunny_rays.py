#!/usr/bin/env python3
"""What the bunny's camera rays meet at 256 x 256: the share that misses the scene box, the share that
crosses it without a hit, and the share that hits. Run from the repository root with the Python module
built: PYTHONPATH=build/python python3 docs/figures/kd_single_round22/bunny_rays.py"""
import numpy as np

import cellrt

scene = cellrt.load_scene("../shared/scenes/bunny/bunny.json")
o, d = scene.camera.rays(256, 256)
v = scene.triangles.reshape(-1, 3)
lo, hi = v.min(0), v.max(0)
with np.errstate(divide="ignore", invalid="ignore"):
    t0, t1 = (lo - o) / d, (hi - o) / d
enter = (np.minimum(t0, t1).max(1) <= np.maximum(t0, t1).min(1)) & (np.maximum(t0, t1).min(1) >= 0)
hit = cellrt.Accelerator(scene.triangles, kind="bvh").intersect(o, d)["prim"] >= 0
print(f"miss the box {1 - enter.mean():.3f}, cross it without a hit {(enter & ~hit).mean():.3f}, hit {hit.mean():.3f}")
