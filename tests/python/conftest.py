"""Shared pieces of the Python module's tests: the scenes, rays that probe a scene, and the paths of
the C++ programs the tests compare with (set by CTest: python/CMakeLists.txt)."""
import os
import pathlib

import numpy as np
import pytest

import cellrt


def scenes_dir():
    return pathlib.Path(os.environ.get("CELLRT_SCENES") or os.environ.get("CELLRT_SCENES_DIR") or "../shared/scenes")


def shared_scene(name):
    """The view file of a shared scene, or a skip when the shared scenes are absent."""
    path = scenes_dir() / name / f"{name}.json"
    if not path.is_file():
        pytest.skip(f"shared scene {path} absent")
    return str(path)


def program(variable):
    path = os.environ.get(variable)
    if not path or not os.path.isfile(path):
        pytest.skip(f"{variable} is not set to a built program (run the suite through ctest)")
    return path


def probe_rays(scene, count, seed):
    """Rays that meet a scene in every way: from inside and outside its box toward its triangles'
    corners and centres (edges and vertices hit exactly), in random directions, with random bounds."""
    rng = np.random.default_rng(seed)
    tris = np.asarray(scene.triangles, dtype=np.float32)
    lo, hi = tris.reshape(-1, 3).min(0), tris.reshape(-1, 3).max(0)
    pad = (hi - lo) * 0.25 + 1e-3
    origins = rng.uniform(lo - pad, hi + pad, size=(count, 3)).astype(np.float32)
    pick = rng.integers(0, len(tris), size=count)
    weights = rng.choice([0.0, 0.5, 1.0, 1 / 3], size=(count, 3))
    weights /= np.maximum(weights.sum(1, keepdims=True), 1e-9)
    targets = np.einsum("nk,nkc->nc", weights, tris[pick]).astype(np.float32)
    directions = targets - origins
    random = rng.random(count) < 0.3
    directions[random] = rng.normal(size=(int(random.sum()), 3)).astype(np.float32)
    diagonal = float(np.linalg.norm(hi - lo))
    tnear = np.where(rng.random(count) < 0.2, rng.uniform(0, 0.5, count), 0.0).astype(np.float32)
    tfar = np.where(rng.random(count) < 0.2, rng.uniform(0.5, 2.0, count) * diagonal, np.inf).astype(np.float32)
    return origins, directions.astype(np.float32), tnear, tfar


@pytest.fixture(scope="session")
def city():
    return cellrt.load_scene("builtin:city?tris=3000&seed=3")


@pytest.fixture(scope="session")
def spheres():
    return cellrt.load_scene("builtin:spheres?tris=2000&seed=5")
