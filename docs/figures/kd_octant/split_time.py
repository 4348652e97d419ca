# The bunny's camera rays (512 x 512, one thread) split by whether they meet the scene's box, kd:branched,
# kd:rec and Embree's rtcIntersect1 on each part (INCOHERENT.md, seventeenth round). From the repository root:
#   PYTHONPATH=build/python python3 docs/figures/kd_octant/split_time.py ../shared/scenes/bunny/bunny.json
import time, sys, numpy as np, cellrt
scene = cellrt.load_scene(sys.argv[1])
o, d = scene.camera.rays(512, 512)
tri = scene.triangles
lo = tri.reshape(-1, 3).min(0); hi = tri.reshape(-1, 3).max(0)
with np.errstate(divide='ignore', invalid='ignore'):
    inv = 1.0 / d
    t0 = (lo - o) * inv; t1 = (hi - o) * inv
    tn = np.nanmax(np.minimum(t0, t1), 1); tf = np.nanmin(np.maximum(t0, t1), 1)
inbox = (tn <= tf) & (tf >= 0)
print("rays", len(o), "hit the box", inbox.mean())
accs = {k: cellrt.Accelerator(tri, kind=k, simd="off" if k.startswith("kd") else "auto", threads=1)
        for k in ["kd:branched", "kd:rec", "embree:single"]}
def best(a, oo, dd):
    ts = []
    for _ in range(7):
        t = time.process_time(); a.intersect(oo, dd); ts.append(time.process_time() - t)
    return sorted(ts)[3] / len(oo) * 1e9
for name, m in [("all", np.ones(len(o), bool)), ("in box", inbox), ("miss box", ~inbox)]:
    oo, dd = np.ascontiguousarray(o[m]), np.ascontiguousarray(d[m])
    r = {k: best(a, oo, dd) for k, a in accs.items()}
    print(name, " ".join("%s %.1f ns" % kv for kv in r.items()), "branched/embree %.2f" % (r["embree:single"] / r["kd:branched"]))
