"""The module against the C++ library without the bindings, bit for bit: the same rays through
make_accelerator in one call of cellrt_py_reference (tests/python/reference_trace.cpp), the camera's
rays, and renders against `cellrt render` PFM files."""
import subprocess

import numpy as np
import pytest

import cellrt
from conftest import probe_rays, program, shared_scene

RAY = np.dtype([("org", "<f4", 3), ("tnear", "<f4"), ("dir", "<f4", 3), ("tfar", "<f4")])
HIT = np.dtype([("t", "<f4"), ("prim", "<u4"), ("u", "<f4"), ("v", "<f4")])


def reference(tmp_path, scene_spec, accel_spec, rays, mode):
    o, d, tn, tf = rays
    records = np.zeros(len(o), RAY)
    records["org"], records["dir"], records["tnear"], records["tfar"] = o, d, tn, tf
    (tmp_path / "rays").write_bytes(records.tobytes())
    subprocess.run([program("CELLRT_PY_REFERENCE"), scene_spec, accel_spec, str(tmp_path / "rays"),
                    str(tmp_path / "out"), mode], check=True)
    data = (tmp_path / "out").read_bytes()
    return np.frombuffer(data, HIT) if mode == "closest" else np.frombuffer(data, np.uint8).astype(bool)


SPECS = [("kd", "auto", {"leaf_size": 3}), ("kd:rec", "off", {}), ("bih", "avx2", {"leaf_size": 3}),
         ("bih", "off", {}), ("bvh", "auto", {"max_leaf": 2}), ("auto", "auto", {}), ("brute", "off", {})]


@pytest.mark.parametrize("kind,simd,params", SPECS)
def test_hits_equal_the_cpp_library(tmp_path, kind, simd, params):
    spec = "builtin:spheres?tris=3000&seed=9"
    scene = cellrt.load_scene(spec)
    rays = probe_rays(scene, 30000, seed=21)
    acc = cellrt.Accelerator(scene.triangles, kind=kind, simd=simd, params=params)
    cpp_spec = f"{kind}+{simd}" + ("@" + ",".join(f"{k}={v}" for k, v in params.items()) if params else "")
    ref = reference(tmp_path, spec, cpp_spec, rays, "closest")
    got = acc.intersect(*rays)
    prim = np.where(ref["prim"] == 0xFFFFFFFF, -1, ref["prim"].astype(np.int64))
    assert np.array_equal(got["prim"], prim)
    for key in ("t", "u", "v"):
        assert np.array_equal(got[key].view(np.uint32), ref[key].view(np.uint32)), key
    assert (prim >= 0).mean() > 0.2
    assert np.array_equal(acc.occluded(*rays), reference(tmp_path, spec, cpp_spec, rays, "any"))


def test_camera_rays_equal_the_cpp_camera(tmp_path, city):
    program("CELLRT_PY_REFERENCE")
    subprocess.run([program("CELLRT_PY_REFERENCE"), "builtin:city?tris=3000&seed=3", "camera", "37x23",
                    str(tmp_path / "cam")], check=True)
    ref = np.frombuffer((tmp_path / "cam").read_bytes(), RAY)
    o, d = city.camera.rays(37, 23)
    assert np.array_equal(o.view(np.uint32), ref["org"].view(np.uint32))
    assert np.array_equal(d.view(np.uint32), ref["dir"].view(np.uint32))


def read_pfm(path):
    data = path.read_bytes()
    header, rest = data.split(b"\n", 3)[:3], data.split(b"\n", 3)[3]
    assert header[0] == b"PF" and float(header[2]) < 0
    width, height = map(int, header[1].split())
    return np.frombuffer(rest, "<f4").reshape(height, width, 3)[::-1]  # PFM rows run bottom to top


def cli_render(tmp_path, spec, *options):
    out = tmp_path / "cli.pfm"
    subprocess.run([program("CELLRT_CLI"), "render", spec, "-o", str(out), "--overwrite", *options], check=True,
                   stdout=subprocess.DEVNULL)
    return read_pfm(out)


@pytest.mark.parametrize("shading", ["direct", "ao", "diffuse"])
def test_render_equals_the_cli(tmp_path, shading):
    spec = "builtin:city?tris=3000&seed=3"
    image = cellrt.render(cellrt.load_scene(spec), kind="bih", size=(61, 47), shading=shading, threads=2)
    assert image.shape == (47, 61, 3) and image.dtype == np.float32
    ref = cli_render(tmp_path, spec, "--accel", "bih", "--size", "61x47", "--shading", shading, "--threads", "1")
    assert np.array_equal(image.view(np.uint32), ref.view(np.uint32))
    assert image.std() > 0.01


@pytest.mark.parametrize("name", ["teapot", "bunny"])
def test_shared_scene_renders_equal_the_cli(tmp_path, name):
    view = shared_scene(name)
    scene = cellrt.load_scene(view)
    image = cellrt.render(scene, size=(96, 72))
    assert np.array_equal(image.view(np.uint32), cli_render(tmp_path, view, "--size", "96x72").view(np.uint32))
