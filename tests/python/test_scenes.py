"""cellrt.load_scene for every kind of scene the library loads (view files, OBJ, PLY, builtin:), the
Scene's fields, Scene from numpy, and the example script."""
import gc
import json
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import cellrt
from conftest import scenes_dir, shared_scene

QUAD_OBJ = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"
QUAD = np.array([[[0, 0, 0], [1, 0, 0], [1, 1, 0]], [[0, 0, 0], [1, 1, 0], [0, 1, 0]]], np.float32)


def test_obj_and_ply_meshes(tmp_path):
    obj = tmp_path / "quad.obj"
    obj.write_text(QUAD_OBJ)
    ply = tmp_path / "quad.ply"
    ply.write_text("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                   "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                   "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")
    for path in (obj, ply, str(obj)):
        scene = cellrt.load_scene(path)
        assert np.array_equal(scene.triangles, QUAD)
        assert scene.triangles.dtype == np.float32 and scene.name == "quad"
        assert scene.size == (512, 512)


def test_view_file_fields(tmp_path):
    (tmp_path / "quad.obj").write_text(QUAD_OBJ)
    view = {"name": "q", "mesh": "quad.obj",
            "camera": {"position": [0.5, 0.5, 3], "look_at": [0.5, 0.5, 0], "up": [0, 1, 0], "fov_y_deg": 40},
            "light": {"type": "point", "position": [1, 2, 3], "color": [1, 0.5, 0.25]},
            "image": {"width": 40, "height": 30}}
    (tmp_path / "q.json").write_text(json.dumps(view))
    scene = cellrt.load_scene(tmp_path / "q.json")
    assert scene.size == (40, 30) and scene.name == "q"
    assert scene.camera.position == (0.5, 0.5, 3.0) and scene.camera.fov_y_deg == 40
    assert scene.light.position == (1.0, 2.0, 3.0) and scene.light.color == (1.0, 0.5, 0.25)
    o, d = scene.camera.rays(*scene.size)
    assert o.shape == d.shape == (1200, 3)
    image = cellrt.render(scene)
    assert image.shape == (30, 40, 3)
    # The quad fills the middle of the view: hit there, sky at the corners.
    hits = cellrt.Accelerator(scene.triangles).intersect(o, d)["prim"].reshape(30, 40)
    assert hits[15, 20] >= 0 and hits[0, 0] == -1


def test_builtin_scenes_and_shared_scenes():
    for name in ("city", "forest", "spheres"):
        scene = cellrt.load_scene(f"builtin:{name}?tris=1000&seed=2")
        assert 500 < len(scene.triangles) < 2000
        assert np.isfinite(scene.triangles).all()
    view = pathlib.Path(shared_scene("teapot"))
    teapot = cellrt.load_scene(view)
    fields = json.loads(view.read_text())
    assert teapot.size == (fields["image"]["width"], fields["image"]["height"])
    assert np.allclose(teapot.camera.position, fields["camera"]["position"])
    assert np.array_equal(cellrt.load_scene(view.with_suffix(".obj")).triangles, teapot.triangles)


def test_scene_edits_change_the_render():
    scene = cellrt.load_scene("builtin:city?tris=2000")
    before = cellrt.render(scene, size=(32, 32))
    scene.camera.fov_y_deg = 20.0
    scene.light.color = (0.5, 0.5, 0.5)
    scene.size = (16, 8)
    after = cellrt.render(scene)
    assert after.shape == (8, 16, 3) and not np.array_equal(before[:8, :16], after)


def test_scene_from_numpy_renders():
    scene = cellrt.Scene(QUAD)
    assert np.array_equal(scene.triangles, QUAD)
    image = cellrt.render(scene, size=(20, 20), shading="ao", ao_samples=2, threads=1)
    assert image.shape == (20, 20, 3) and np.isfinite(image).all()


def test_the_triangles_view_keeps_its_scene_alive():
    tris = cellrt.load_scene("builtin:spheres?tris=500").triangles  # the only reference to the scene
    copy = np.array(tris)
    gc.collect()
    garbage = [cellrt.load_scene("builtin:city?tris=500").triangles.copy() for _ in range(20)]
    assert isinstance(tris.base, cellrt.Scene) and len(garbage) == 20
    assert np.array_equal(tris, copy)


def test_depth_image_example(tmp_path):
    pytest.importorskip("matplotlib")
    example = pathlib.Path(os.environ.get("CELLRT_EXAMPLES", "examples")) / "depth_image.py"
    if not example.is_file():
        pytest.skip(f"{example} absent")
    out = tmp_path / "depth.png"
    subprocess.run([sys.executable, str(example), "builtin:city?tris=2000", "-o", str(out), "--size", "64x48"],
                   check=True, env={**os.environ, "MPLBACKEND": "Agg"})
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
