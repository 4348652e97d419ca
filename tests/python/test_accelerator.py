"""Every kind and instruction set from Python against brute force, bit for bit; the two ways to give
triangles; conversions and the zero-copy path; threads, concurrency and the GIL; the statistics."""
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import cellrt
from conftest import probe_rays

# Embree answers up to rounding (docs/EMBREE.md): compared apart, with a tolerance.
KINDS = [k for k in cellrt.kinds() if k not in ("brute", "embree")]
SIMD = ["off", "auto", "portable"]


def assert_same_hits(a, b):
    assert np.array_equal(a["prim"], b["prim"])
    for key in ("t", "u", "v"):
        assert np.array_equal(a[key].view(np.int32), b[key].view(np.int32)), key


@pytest.fixture(scope="module", params=["city", "spheres"])
def case(request):
    scene = request.getfixturevalue(request.param)
    rays = probe_rays(scene, 20000, seed=11)
    brute = cellrt.Accelerator(scene.triangles, kind="brute", simd="off")
    return scene, rays, brute.intersect(*rays), brute.occluded(*rays)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("simd", SIMD)
def test_every_kind_finds_the_brute_force_hit(case, kind, simd):
    scene, rays, hits, occluded = case
    acc = cellrt.Accelerator(scene.triangles, kind=kind, simd=simd)
    assert_same_hits(acc.intersect(*rays), hits)
    assert np.array_equal(acc.occluded(*rays), occluded)


@pytest.mark.skipif("embree" not in cellrt.kinds(), reason="built without Embree 3")
def test_embree_agrees_up_to_rounding(city):
    o, d = city.camera.rays(128, 128)
    ref = cellrt.Accelerator(city.triangles, kind="brute").intersect(o, d)
    got = cellrt.Accelerator(city.triangles, kind="embree").intersect(o, d)
    same = got["prim"] == ref["prim"]
    assert same.mean() > 0.999
    hit = same & (ref["prim"] >= 0)
    assert np.allclose(got["t"][hit], ref["t"][hit], rtol=1e-5, atol=0)


def test_the_probe_rays_hit_and_miss(case):
    _, _, hits, occluded = case
    hit = hits["prim"] >= 0
    assert 0.2 < hit.mean() < 0.95
    assert np.all(np.isinf(hits["t"][~hit])) and np.all(hits["u"][~hit] == 0)
    assert hits["prim"].dtype == np.int64 and occluded.dtype == np.bool_
    assert np.array_equal(occluded[hit], np.ones(hit.sum(), bool))


def test_single_ray_traversals(case):
    scene, rays, hits, _ = case
    for kind in ("kd:rec", "kd:branchless", "bih:branchless"):
        assert_same_hits(cellrt.Accelerator(scene.triangles, kind=kind, simd="off").intersect(*rays), hits)


def test_a_tree_kernel_runs_alone_and_is_refused_with_packets(case):
    # simd=None takes one ray at a time for a kd-tree or BIH kernel; named with a SIMD set, whose
    # packets would replace it, it is refused (it ran the packets and reported the kernel until an
    # audit, 2026-12-07).
    scene, rays, hits, _ = case
    for kind in ("kd:rec", "bih:branchless", "brute:loop"):
        acc = cellrt.Accelerator(scene.triangles, kind=kind)
        assert acc.config == kind and acc.stats.traversal == kind.split(":")[1]
        assert_same_hits(acc.intersect(*rays), hits)
        with pytest.raises(ValueError, match="names a single-ray kernel"):
            cellrt.Accelerator(scene.triangles, kind=kind, simd="auto")
    assert cellrt.Accelerator(scene.triangles, kind="kd").stats.traversal == "packet"


def test_bvh_traversals(case):
    scene, rays, hits, occluded = case
    for kind in ("bvh:wide", "bvh:paired", "bvh:stream", "bvh:packet"):
        acc = cellrt.Accelerator(scene.triangles, kind=kind)
        assert acc.stats.traversal == kind.split(":")[1]
        assert_same_hits(acc.intersect(*rays), hits)
        assert np.array_equal(acc.occluded(*rays), occluded)


# A thin triangle seen at a grazing angle, a small triangle across the ray just behind where the
# float test used to put the hit, and a cloud of tiny triangles around that point to make the
# trees cut there (audit, 2026-12-07): the crossing with the thin triangle's plane, which the test
# took, lay off the triangle, and the kd-tree (1: 1 long, 1e-3 wide) and the BVH's spatial splits
# (2: 2.8e-4 wide, 2.4e-7 rad), whose cells and boxes hold clipped parts of it, missed that hit.
GRAZING = [
    ([[0.31996285915374756, 0.5216338038444519, 0.965959906578064],
      [0.6800371408462524, 0.4783662259578705, 0.034040119498968124],
      [0.6808173656463623, 0.4778325855731964, 0.03436636924743652]],
     [-0.35135218501091003, 1.1609665155410767, -0.2756071388721466],
     [0.7802489995956421, -0.5336419343948364, 0.32624801993370056], 1.264935, 1, 1.7e-3, 2e-5, 5e-5, 0.001),
    ([[0.8049867749214172, 0.7365383505821228, 0.18214364349842072],
      [0.19501322507858276, 0.2634616196155548, 0.8178563714027405],
      [0.19522954523563385, 0.2634125351905823, 0.8180273771286011]],
     [1.201639175415039, 0.3552662134170532, 1.0283280611038208],
     [-0.7722904086112976, 0.17522260546684265, -0.6106263995170593], 0.88926196, 2, 0.3, 1e-3, 4e-3, 6e-5),
]


@pytest.mark.parametrize("sliver, origin, direction, t_old, seed, spread, size, clear, behind", GRAZING)
def test_grazing_slivers_are_found_by_every_kind(sliver, origin, direction, t_old, seed, spread, size, clear, behind):
    o = np.array([origin], np.float32)
    d = np.array([direction], np.float32)
    o0, d0 = o[0].astype(float), d[0].astype(float)
    rng = np.random.default_rng(seed)
    c = o0 + t_old * d0 + rng.uniform(-spread, spread, (3000, 3))
    u = d0 / np.linalg.norm(d0)
    rel = c - o0
    c = c[np.linalg.norm(rel - np.outer(rel @ u, u), axis=1) > clear]
    cloud = c[:, None, :] + rng.uniform(-size, size, (len(c), 3, 3))
    p = np.cross(u, [0, 0, 1])
    p /= np.linalg.norm(p)
    q = np.cross(u, p)
    blocker = o0 + (t_old + behind) * d0 + 1e-4 * np.array([p, -p + q, -p - q])
    tris = np.concatenate([np.array(sliver)[None], blocker[None], cloud]).astype(np.float32)
    brute = cellrt.Accelerator(tris, kind="brute", simd="off")
    hit = brute.intersect(o, d)
    t = hit["t"][0]
    assert np.isfinite(t)
    for kind in KINDS + [None]:
        for simd in ("off", "auto"):
            acc = cellrt.Accelerator(tris, kind=kind, simd=simd)
            assert_same_hits(acc.intersect(o, d), hit)
            assert acc.occluded(o, d, 0.0, t)[0], acc.config
            assert acc.intersect(o, d, t, t)["prim"][0] == hit["prim"][0], acc.config


def test_indexed_mesh_equals_triangle_soup(city):
    tris = np.asarray(city.triangles)
    vertices, faces = np.unique(tris.reshape(-1, 3), axis=0, return_inverse=True)
    faces = faces.reshape(-1, 3)
    rays = probe_rays(city, 5000, seed=2)
    a = cellrt.Accelerator(vertices, faces.astype(np.int32)).intersect(*rays)
    b = cellrt.Accelerator(tris).intersect(*rays)
    c = cellrt.Accelerator(vertices.astype(np.float64), faces.astype(np.uint64)).intersect(*rays)
    assert_same_hits(a, b)
    assert_same_hits(a, c)


def test_float64_and_strided_input_give_the_same_hits(city):
    acc = cellrt.Accelerator(city.triangles)
    o, d, tn, tf = probe_rays(city, 5000, seed=3)
    ref = acc.intersect(o, d, tn, tf)
    assert_same_hits(acc.intersect(o.astype(np.float64), d.astype(np.float64), tn.astype(np.float64), tf), ref)
    wide = np.zeros((len(o), 6), np.float32)
    wide[:, :3], wide[:, 3:] = o, d
    assert_same_hits(acc.intersect(wide[:, :3], wide[:, 3:], tn, tf), ref)
    assert_same_hits(acc.intersect(o.tolist(), d.tolist(), tn.tolist(), tf.tolist()), ref)


def test_contiguous_float32_is_read_in_place():
    a = np.zeros((10, 3), np.float32)
    assert cellrt._reads_in_place(a)
    assert not cellrt._reads_in_place(a.astype(np.float64))
    assert not cellrt._reads_in_place(np.zeros((10, 6), np.float32)[:, :3])
    assert not cellrt._reads_in_place(np.asfortranarray(np.zeros((10, 3), np.float32)))
    assert not cellrt._reads_in_place(a.tolist())


def test_scalar_and_array_bounds_agree(city):
    acc = cellrt.Accelerator(city.triangles)
    o, d, _, _ = probe_rays(city, 3000, seed=4)
    n = len(o)
    assert_same_hits(acc.intersect(o, d, 0.5, 40.0), acc.intersect(o, d, np.full(n, 0.5), np.full(n, 40.0)))
    near = acc.intersect(o, d)
    far = acc.intersect(o, d, tnear=near["t"][np.isfinite(near["t"])].max() * 2)
    assert np.all(far["prim"] == -1)
    assert np.array_equal(acc.occluded(o, d, tfar=np.where(near["prim"] >= 0, near["t"], np.inf)), near["prim"] >= 0)


def test_threads_and_batch_sizes_do_not_change_hits(city):
    o, d, tn, tf = probe_rays(city, 10000, seed=5)
    ref = cellrt.Accelerator(city.triangles, threads=1).intersect(o, d, tn, tf)
    acc = cellrt.Accelerator(city.triangles, threads=0)
    assert_same_hits(acc.intersect(o, d, tn, tf), ref)
    for n in (0, 1, 1023, 1024, 1025, 3000):
        part = acc.intersect(o[:n], d[:n], tn[:n], tf[:n])
        assert len(part["t"]) == n
        assert np.array_equal(part["prim"], ref["prim"][:n])


def test_concurrent_calls_from_python_threads(city):
    acc = cellrt.Accelerator(city.triangles)
    rays = probe_rays(city, 20000, seed=6)
    ref = acc.intersect(*rays)
    results = [None] * 4

    def work(i):
        results[i] = acc.intersect(*rays)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        assert_same_hits(r, ref)


def test_the_gil_is_released_while_tracing():
    scene = cellrt.load_scene("builtin:forest?tris=50000&seed=1")
    acc = cellrt.Accelerator(scene.triangles, simd="off", threads=1)
    o, d = scene.camera.rays(1024, 1024)
    start = time.perf_counter()
    acc.intersect(o, d)
    alone = time.perf_counter() - start
    worker = threading.Thread(target=acc.intersect, args=(o, d))
    gaps, last = [], time.perf_counter()
    worker.start()
    while worker.is_alive():
        now = time.perf_counter()
        gaps.append(now - last)
        last = now
    worker.join()
    # Held, the GIL would stall this loop for the whole trace.
    assert max(gaps) < 0.5 * alone, (max(gaps), alone)


def run_python(code, timeout):
    """Runs `code` in a Python of its own: what happens at its exit is what these tests look at."""
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=timeout)


def test_the_interpreter_ends_while_a_daemon_thread_renders():
    # The render's worker team was a static whose destructor waited at exit for the run; the thread,
    # resumed in a finalized interpreter, then ended in std::terminate (status 134).
    code = ("import threading, time, cellrt\n"
            "scene = cellrt.load_scene('builtin:city?tris=2000')\n"
            "threading.Thread(target=cellrt.render, args=(scene,), daemon=True,\n"
            "                 kwargs=dict(size=(4096, 4096), shading='ao', ao_samples=16, threads=2)).start()\n"
            "time.sleep(0.3)\n")
    done = run_python(code, timeout=300)
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("call, threads", [("acc.intersect(o, d)", 3), ("acc.occluded(o, d)", 3),
                                           ("cellrt.Accelerator(tri)", 3),
                                           ("cellrt.load_scene('builtin:spheres?tris=100')", 3),
                                           ("acc.occluded(o64, d64)", 8), ("cellrt.Accelerator(tri64)", 8)])
def test_the_interpreter_ends_while_a_daemon_thread_loops_over_calls(call, threads):
    # Short calls in a loop: the thread took the GIL back as the interpreter finalized, which ended it
    # by pthread_exit; unwinding out of py::gil_scoped_release's destructor was std::terminate
    # (status 134; found by audit, 2026-12-07), and unwinding pybind11's frames without the GIL a
    # segmentation fault in one run of three. Three threads, under which a first fix (an atexit
    # barrier) hung. The same where Python code runs inside a call (numpy.require and errstate,
    # converting float64 rays, triangles and the bounds): 35 exits of 40 crashed with eight threads
    # over float64 rays, one of a hundred with three over float32 rays under load (found on a
    # loaded machine, 2026-12-07; python/interpreter_exit.hpp).
    code = ("import threading, time, numpy as np, cellrt\n"
            "tri = np.eye(3, dtype=np.float32)[None]; tri64 = tri.astype(np.float64)\n"
            "acc = cellrt.Accelerator(tri)\n"
            "o = np.zeros((8, 3), np.float32); d = np.ones((8, 3), np.float32)\n"
            "o64 = o.astype(np.float64); d64 = d.astype(np.float64)\n"
            "def loop():\n"
            "    while True:\n"
            f"        {call}\n"
            f"for _ in range({threads}):\n"
            "    threading.Thread(target=loop, daemon=True).start()\n"
            "time.sleep(0.2)\n")
    for _ in range(5):
        done = run_python(code, timeout=120)
        assert done.returncode == 0, done.stderr


def test_an_atexit_callback_joins_a_thread_in_calls_and_a_forked_child_ends():
    # A first fix of the exit (an atexit barrier) blocked the threads that an earlier atexit callback
    # then joined, and hung forked children at exit (found by review, 2026-12-07).
    code = ("import atexit, os, threading, time\n"
            "done = threading.Event()\n"
            "def work():\n"
            "    import numpy as np, cellrt\n"
            "    acc = cellrt.Accelerator(np.eye(3, dtype=np.float32)[None])\n"
            "    o = np.zeros((8, 3), np.float32); d = np.ones((8, 3), np.float32)\n"
            "    while not done.is_set():\n"
            "        acc.intersect(o, d)\n"
            "t = threading.Thread(target=work, daemon=True)\n"
            "def stop():\n"
            "    done.set(); t.join(); print('joined')\n"
            "atexit.register(stop)\n"
            "t.start(); time.sleep(0.3)\n"
            "pid = os.fork()\n"
            "if pid:  # the child ends as the parent does, through its atexit callbacks\n"
            "    _, status = os.waitpid(pid, 0); print('child', os.waitstatus_to_exitcode(status))\n")
    done = run_python(code, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("joined") == 2 and "child 0" in done.stdout, done.stdout


def test_more_threads_than_cores_trace_without_a_word():
    # An arena of more threads than cores printed TBB's warning on stderr (found by audit, 2026-12-07).
    code = ("import numpy as np, cellrt\n"
            "a = cellrt.Accelerator(np.eye(3, dtype=np.float32)[None], threads=1024)\n"
            "o = np.random.default_rng(1).random((5000, 3)).astype(np.float32)\n"
            "a.intersect(o, o - 0.5); a.occluded(o, o - 0.5)\n")
    done = run_python(code, timeout=120)
    assert done.returncode == 0 and done.stderr == "", done.stderr


def test_stats_are_typed(city):
    kd = cellrt.Accelerator(city.triangles, kind="kd", params={"leaf_size": 2, "method": "binned", "bins": 64}).stats
    assert kd.name == "kd" and kd.triangles == len(city.triangles)
    assert kd.build_seconds > 0 and kd.memory_bytes > 0
    assert kd.traversal == "packet" and kd.simd_lanes in (4, 8, 16)
    assert kd.tree.nodes == kd.tree.inner_nodes + kd.tree.leaves and kd.tree.sah_cost > 0
    assert kd.settings["method"] == "binned"
    assert ("triangles", str(len(city.triangles))) in kd.figures
    bih = cellrt.Accelerator(city.triangles, kind="bih", simd="off").stats
    assert bih.simd_lanes == 0 and bih.tree.empty_space_nodes is not None
    assert cellrt.Accelerator(city.triangles, kind="brute").stats.tree is None


def test_the_default_kind_is_the_route_over_one_bvh_on_the_cpu(city):
    # kind=None: `auto@packets=bvh`, which routes each batch to its fastest path over one wide BVH;
    # params add to it.
    acc = cellrt.Accelerator(city.triangles).stats
    assert acc.name == "auto" and acc.settings["packets"] == "bvh"
    streams_off = cellrt.Accelerator(city.triangles, kind=None, params={"streams": "off"}).stats.settings
    assert streams_off["packets"] == "bvh" and streams_off["streams"] == "off"
    assert cellrt.Accelerator(city.triangles, kind="auto").stats.settings["packets"] == "kd"
    assert cellrt.Accelerator(city.triangles, kind="kd").stats.name == "kd"


def test_an_accelerator_names_its_configuration(city):
    # The configuration built, as one string that cellrt_bench and the CLI read back.
    default = cellrt.Accelerator(city.triangles)
    assert default.config == "auto+auto@packets=bvh" and default.device == "cpu"
    kd = cellrt.Accelerator(city.triangles, kind="kd:rec", simd="off", params={"leaf_size": 2, "bins": 64})
    assert kd.config == "kd:rec@bins=64,leaf_size=2"
    assert repr(kd) == "<cellrt.Accelerator kd:rec@bins=64,leaf_size=2 on cpu, %d triangles>" % len(city.triangles)


def test_the_default_render_is_the_kd_trees_image_bit_for_bit(city):
    # kind=None renders over the library's default (one wide BVH), the CLI's default over the kd-tree.
    for shading in ("direct", "diffuse"):
        default = cellrt.render(city, size=(41, 29), shading=shading)
        kd = cellrt.render(city, kind="kd", size=(41, 29), shading=shading)
        assert np.array_equal(default.view(np.uint32), kd.view(np.uint32))


def test_empty_mesh_and_empty_batch():
    acc = cellrt.Accelerator(np.zeros((0, 3, 3), np.float32))
    r = acc.intersect(np.zeros((2, 3)), np.ones((2, 3)))
    assert np.array_equal(r["prim"], [-1, -1])
    empty = acc.intersect(np.zeros((0, 3)), np.zeros((0, 3)))
    assert all(len(v) == 0 for v in empty.values())
    assert acc.occluded(np.zeros((0, 3)), np.zeros((0, 3))).shape == (0,)


def test_degenerate_rays_miss():
    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], np.float32)
    acc = cellrt.Accelerator(tri)
    o = np.array([[0.2, 0.2, 1], [0.2, 0.2, 1], [0.2, 0.2, 1]], np.float32)
    d = np.array([[0, 0, -1], [0, 0, 0], [0, 0, -1]], np.float32)
    r = acc.intersect(o, d, tnear=np.array([0, 0, 2], np.float32))
    assert r["prim"].tolist() == [0, -1, -1]
    assert r["t"][0] == 1.0 and abs(r["u"][0] - 0.2) < 1e-6 and abs(r["v"][0] - 0.2) < 1e-6


@pytest.fixture(scope="module")
def gpu():
    info = cellrt.device_info()
    if not info["present"]:
        pytest.skip("no CUDA device: " + info["reason"])
    return info


@pytest.mark.parametrize("kind", ["kd", "bih:branchless"])
def test_the_gpu_answers_as_brute_force(gpu, case, kind):
    scene, rays, hits, occluded = case
    acc = cellrt.Accelerator(scene.triangles, kind=kind, device="cuda")
    assert_same_hits(acc.intersect(*rays), hits)
    assert np.array_equal(acc.occluded(*rays), occluded)
    assert "cuda" in str(acc.stats.settings)


@pytest.mark.parametrize("shading", ["direct", "ao", "diffuse"])
def test_the_gpu_renders_the_cpus_image(gpu, city, shading):
    cpu = cellrt.render(city, size=(61, 43), shading=shading)
    for kind in ("kd", "bih"):
        on_gpu = cellrt.render(city, kind=kind, size=(61, 43), shading=shading, device="cuda")
        assert np.array_equal(on_gpu.view(np.int32), cpu.view(np.int32)), kind
