"""Rays at lengths far from 1 (docs/HIT_SEMANTICS.md, "Known limits"): every structure, traversal
and SIMD setting gives brute force's answers bit for bit when the directions are scaled from
subnormal lengths to near FLT_MAX, or the scene, origins and directions together from 1e-15 to
1e30. Where the float test leaves its range a triangle is a miss on every path, never a hit that
one path finds and another culls."""
import numpy as np
import pytest

import cellrt

KINDS = ["kd:branched", "kd:rec", "kd:branchless", "bih:branched", "bih:branchless",
         "bvh", "bvh:paired", "bvh:stream", "bvh:packet", "auto"]
# Every kind one ray at a time, and every kind whose batches SIMD packets may trace with them (a
# kd-tree or BIH kernel named with simd="auto" is refused: the packets would replace it).
CONFIGS = [(kind, "off") for kind in KINDS] + [(kind, "auto") for kind in
                                               ["kd", "bih", "bvh", "bvh:paired", "bvh:stream", "bvh:packet", "auto"]]


@pytest.fixture(scope="module")
def probe():
    tris = np.asarray(cellrt.load_scene("builtin:spheres?tris=2000").triangles, dtype=np.float32)
    points = tris.reshape(-1, 3)
    lo, hi = points.min(0), points.max(0)
    rng = np.random.default_rng(5)
    n = 1200
    org = (lo + (hi - lo) * rng.uniform(-0.5, 1.5, size=(n, 3))).astype(np.float32)
    dirs = rng.uniform(-1, 1, size=(n, 3)).astype(np.float32)
    along = np.arange(n) % 4 == 1  # a quarter along an axis, either way
    dirs[along] = 0
    dirs[along, (np.arange(n)[along] // 4) % 3] = np.where(np.arange(n)[along] % 8 < 4, 1, -1)
    return tris, org, dirs


def disagreements(tris, org, dirs):
    ref = cellrt.Accelerator(tris, kind="brute", simd="off").intersect(org, dirs)
    bad = []
    for kind, simd in CONFIGS:
        got = cellrt.Accelerator(tris, kind=kind, simd=simd).intersect(org, dirs)
        differ = (got["prim"] != ref["prim"]) | (got["t"].view(np.uint32) != ref["t"].view(np.uint32))
        if differ.any():
            bad.append(f"{kind} simd={simd}: {int(differ.sum())} rays")
    return ref, bad


@pytest.mark.parametrize("scale", [1e-45, 1e-40, 1e-30, 1e-20, 1e17, 1e19, 1e20, 1e25, 1e30, 3e38])
def test_scaled_directions(probe, scale):
    tris, org, dirs = probe
    ref, bad = disagreements(tris, org, (dirs * np.float32(scale)).astype(np.float32))
    assert not bad, bad
    # Subnormal directions hit nothing (ray.hpp); the others meet the triangles the unscaled ones do.
    unscaled = cellrt.Accelerator(tris, kind="brute", simd="off").intersect(org, dirs)
    if scale < 1e-38:
        assert (ref["prim"] < 0).all()
    else:
        assert (unscaled["prim"] >= 0).sum() > len(org) // 10
        assert (ref["prim"] >= 0).sum() == (unscaled["prim"] >= 0).sum()


@pytest.mark.parametrize("scale", [1e-15, 1e15, 1e18, 1e20, 1e30])
def test_scaled_scene_origins_and_directions(probe, scale):
    tris, org, dirs = probe
    s = np.float32(scale)
    ref, bad = disagreements((tris * s).astype(np.float32), (org * s).astype(np.float32), (dirs * s).astype(np.float32))
    assert not bad, bad
    # Up to 1e18 the test's arithmetic stays in range and the rays meet the scene; beyond, its edge
    # functions overflow and every path misses alike.
    if scale <= 1e18:
        assert (ref["prim"] >= 0).sum() > len(org) // 10


@pytest.mark.parametrize("scale,direction_scale", [(1e-12, 1e8), (1e-16, 1.0), (1e-17, 1.0)])
def test_tiny_scene_along_long_or_unit_directions(probe, scale, direction_scale):
    """The scene and origins shrunk, the directions not (or lengthened): the test's T, a length cubed,
    underflows. Its sign was lost, and triangles behind an origin were hit at t = -0 before the one in
    front: 1,365 of 20,000 rays into a 1e-12 soup along directions 1e8 long took a wrong triangle
    (found by audit, 2026-12-07). Such hits take t in double precision (triangle.hpp, t_underflowed):
    the unscaled triangles, every path alike."""
    tris, org, dirs = probe
    s = np.float32(scale)
    ref, bad = disagreements((tris * s).astype(np.float32), (org * s).astype(np.float32),
                             (dirs * np.float32(direction_scale)).astype(np.float32))
    assert not bad, bad
    unscaled = cellrt.Accelerator(tris, kind="brute", simd="off").intersect(org, dirs)
    assert (unscaled["prim"] >= 0).sum() > len(org) // 10
    # The same triangles but where two lie within rounding of one depth (a shared edge's neighbours).
    assert (ref["prim"] != unscaled["prim"]).sum() <= len(org) // 500
    assert (ref["t"][ref["prim"] >= 0] >= 0).all(), "a hit behind its origin"
