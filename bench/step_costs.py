#!/usr/bin/env python3
"""Where the time of a single-ray kernel goes: instructions and estimated cycles per ray set-up, per
inner-node step, per leaf and per triangle test, by callgrind (repeatable where the machine has no
hardware counters), for every configuration, scene and ray kind asked for. docs/INCOHERENT.md.

One valgrind run per (configuration, scene, ray kind): `cellrt_bench --builds 1 --repeats 1` under
callgrind with its cache and branch simulation and per-instruction costs. The bench switches
instrumentation on only around its traced passes (CALLGRIND_START/STOP_INSTRUMENTATION, so run it with
--instr-atstart=no) and reads the clock before and after every pass; `--dump-before=*clock_gettime*`
makes each pass a dump of its own. The second round of passes (after the warm-up round, so the
simulated caches hold what a steady state holds) is the one measured: the primary rays' pass and the
second kind's (shadow, AO, diffuse bounce or random any-hit rays).

Attribution. Every executed instruction of the bench binary is looked up with `addr2line -i`, which
gives the chain of functions inlined at its address; the chain decides the step it belongs to:

  triangle  the watertight test and its hit rule (intersect_unbounded, intersect_closest,
            intersect_any, the queries' test; the BVH's eight-lane watertight_leaf)
  leaf      a leaf's own work: the traits' Leaves::test loop, the kd-tree's mailbox, the BVH's
            test_leaf outside the lane test, and the stack pop that follows a leaf
  node      an inner-node step: the node loop of the kernel (its source lines, checked below), the
            node fetch, the BVH's meet_children and its push
  setup     per ray: TraversalRay (reciprocal direction, margin, the watertight shear), clip to the
            scene box, the query's construction, the kernel's stack and mailbox initialisation
  batch     per ray: the batch loop around the kernel, validity check, the result's store, the
            virtual call and the bench's own loop
  other     anything else (another object, an address without line information)

Costs per step are the category's total divided by the bench's counts of that step (nodes, leaves,
triangles per ray, from its counting pass over the same rays; rays for setup and batch). Estimated
cycles: Ir + 10 (I1mr + D1mr + D1mw) + 100 (ILmr + DLmr + DLmw) + 20 (Bcm + Bim), with the simulated
caches given by --I1/--D1/--LL (defaults: this machine's L1s and its 2 MiB L2 as the "last level").

A least-squares fit of each pass's Ir against (rays, nodes, leaves, triangles) over all passes of a
configuration is written next to it, as a check that needs no source attribution.

    bench/step_costs.py --bench build/bench/cellrt_bench --scenes-dir /work/shared/scenes \\
        --json docs/figures/step_costs.json [--work DIR] [--configs ...] [--scenes ...] [--rays ...]

Finished runs are kept in --work (one JSON each) and not run again, so an interrupted study resumes.
"""
import argparse
import collections
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import time
import bench_outputs

EVENTS = ["Ir", "Dr", "Dw", "I1mr", "D1mr", "D1mw", "ILmr", "DLmr", "DLmw", "Bc", "Bcm", "Bi", "Bim"]
CATEGORIES = ["setup", "node", "leaf", "pop", "triangle", "batch", "other"]
ENTRY = re.compile(r"^[\w:<>, ]*::(intersect|occluded)\(std::span<cellrt::Ray const")
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def cycles(c):
    """callgrind's usual estimate (KCachegrind's CEst with 20 cycles per misprediction)."""
    return (c["Ir"] + 10 * (c["I1mr"] + c["D1mr"] + c["D1mw"]) + 100 * (c["ILmr"] + c["DLmr"] + c["DLmw"])
            + 20 * (c["Bcm"] + c["Bim"]))


# ---------------------------------------------------------------------------------------------------
# Source attribution: which lines of the kernels' own functions are node steps, leaves, pops, set-up.
# Each range is checked against the source (a marker that must appear in its first line), so that an
# edit that moves the kernels makes this script fail instead of misattributing.

# Per kernel: its file, a text on the line that names it, and its steps in source order, each from
# the first line (after the previous step's) that holds its marker; the first step starts on the
# template line above the name, the last ends at the function's closing brace. Markers are searched,
# not line numbers kept, so an edit elsewhere does not shift them, and a marker that is gone stops the
# script instead of misattributing.
# Each rule also names the kinds of structure (a configuration's KIND) whose kernels run it: only the
# rules of the kinds measured are resolved, so a rule gone stale for another structure stops nothing.
LINE_RULES = {
    "traverse_branched_from<": ("src/kernel/stack_traversal.hpp", "bool traverse_branched_from(", [
        ("setup", None), ("node", "for (;;) {"), ("leaf", "if (reached_leaf && leaves.test"),
        ("pop", "if (!pop_live(stack, sp, 0")], ("kd", "bih")),
    "traverse_branched<": ("src/kernel/stack_traversal.hpp", "bool traverse_branched(", [("setup", None)],
                           ("kd", "bih")),
    "traverse_branchless<": ("src/kernel/stack_traversal.hpp", "bool traverse_branchless(", [
        ("setup", None), ("node", "for (;;) {"), ("leaf", "if constexpr (Traits::kGaps) {"),
        ("pop", "if (!pop_live(stack, sp, bottom")], ("kd", "bih")),
    "kd_traverse_rec<": ("src/kdtree/kd_traversal.hpp", "bool kd_traverse_rec(", [
        ("setup", None), ("node", "for (;;) {"), ("leaf", "if (leaves.test(n, mem, r, q, c)) return true;"),
        ("pop", "// Continue with the node")], ("kd",)),
    # The BVH's walk is split in three: the ray's stacks (traverse_bvh_from), the loop over steps
    # (traverse_bvh_from_walk, also the paired walks' tail) and the step itself (bvh_step, which the
    # paired walks call directly). The loop and the step's leaf-or-node dispatch are the node step,
    # as the one loop's head was before the split.
    "traverse_bvh_from<": ("src/bvh/bvh_kernels.inl", "bool traverse_bvh_from(", [("setup", None)], ("bvh",)),
    "traverse_bvh_from_walk<": ("src/bvh/bvh_kernels.inl", "bool traverse_bvh_from_walk(", [
        ("setup", None), ("node", "for (;;) {")], ("bvh",)),
    "bvh_step<": ("src/bvh/bvh_kernels.inl", "BvhStep bvh_step(", [
        ("node", None), ("leaf", "if (test_leaf(leaves[BvhNode::leaf_index"), ("node", "} else {"),
        ("pop", "for (;;) {")], ("bvh",)),
}


def resolve_line_rules(root, configs):
    """The LINE_RULES of the structures that `configs` measure (every one for `auto`), as
    {function: (file, [(first, last, category)])}, 1-based inclusive lines."""
    kinds = {re.match(r"[a-z]*", c).group() for c in configs}
    resolved = {}
    for fn, (path, anchor, steps, used_by) in LINE_RULES.items():
        if "auto" not in kinds and not kinds.intersection(used_by):
            continue
        lines = open(os.path.join(root, path)).read().split("\n")
        named = [i for i, line in enumerate(lines) if anchor in line]
        if not named:
            sys.exit(f"step_costs.py: error: {path} no longer has '{anchor}'; update LINE_RULES")
        starts, pos = [named[0] - 1], named[0] + 1
        for cat, marker in steps[1:]:
            found = next((i for i in range(pos, len(lines)) if marker in lines[i]), None)
            if found is None:
                sys.exit(f"step_costs.py: error: {path} no longer reads '{marker}' after '{anchor}' ({fn} {cat}); "
                         f"update LINE_RULES")
            starts.append(found)
            pos = found + 1
        end = next(i for i in range(pos, len(lines)) if lines[i] == "}")
        bounds = starts + [end + 1]
        resolved[fn] = (path, [(bounds[k] + 1, bounds[k + 1], steps[k][0]) for k in range(len(steps))])
    return resolved


# Functions whose instructions belong to one step wherever they are inlined. A chain of inlined
# functions is read from the innermost frame out; the first frame named here (or by LINE_RULES)
# decides. TRIANGLE functions win over everything (a lambda reading a leaf's scene index inside the
# hit rule is part of the triangle test).
TRIANGLE = ["intersect_unbounded", "intersect_closest", "intersect_any", "ClosestHit::test<", "AnyHit::test<",
            "watertight_leaf"]
NAMED = [
    ("RecentTriangles::seen", "leaf"),
    ("RecentTriangles::RecentTriangles", "setup"),
    ("Leaves::Leaves", "setup"),
    ("Leaves::test<", "leaf"),
    ("test_leaf<", "leaf"),
    ("pop_live<", "pop"),
    ("meet_children", "node"),
    ("BoxRay::BoxRay", "setup"),
    ("TraversalRay::TraversalRay", "setup"),
    ("TraversalRay::clip", "setup"),
    ("WatertightRay::WatertightRay", "setup"),
    ("prepare_rays", "setup"),  # the paired BVH walks' set-up, eight rays at a time in lanes
    ("load_ray_lanes", "setup"),
    ("ClosestHit::ClosestHit", "setup"),
    ("AnyHit::AnyHit", "setup"),
    ("DirectMemory<", None),  # node(), index(), triangle(): the caller decides
    ("closest_hits<", "batch"),
    ("any_hits<", "batch"),
    ("with_counters<", "batch"),
    ("ClosestHit::result", "batch"),
    ("is_valid", "batch"),
    ("::intersect(std::span", "batch"),
    ("::occluded(std::span", "batch"),
    ("closest_batch", "batch"),
    ("any_batch", "batch"),
    ("paired_batch", "batch"),
    ("(anonymous namespace)::answer", "batch"),
    ("with_direct_kernel", "batch"),
    ("with_kd_kernel", "batch"),
    ("with_bih_kernel", "batch"),
    ("with_kernel", "batch"),
    ("timed_passes", "batch"),
]
# Files of inlined lines that the chain decides by its callers, never by themselves (vectors, boxes,
# SIMD lanes, the standard library) when no rule above names their function.
GENERIC_FILES = ("include/cellrt/vec.hpp", "include/cellrt/box.hpp", "include/cellrt/ray.hpp", "src/simd/lanes.inl",
                 "kd_node.hpp", "bih_node.hpp", "bvh_node.hpp", "/usr/")


RULES = {}  # resolve_line_rules(ROOT, configs), once the script runs


def classify_chain(chain, rules=RULES):
    """chain: [(function, file, line)] innermost first. Returns (category, reason)."""
    for fn, _, _ in chain:
        if any(t in fn for t in TRIANGLE):
            return "triangle", fn
    for fn, path, line in chain:
        for key, (rule_path, ranges) in rules.items():
            if key in fn and path.endswith(rule_path):
                for first, last, cat in ranges:
                    if first <= line <= last:
                        return cat, f"{rule_path}:{line}"
                return "other", f"{rule_path}:{line} (no range)"
        for key, cat in NAMED:
            if key in fn:
                if cat is None:
                    break
                return cat, key
        # An implicit constructor's member initialisers carry the member's line, not a function of
        # their own: the kd-tree's mailbox slots.
        if path.endswith("src/kdtree/kd_traversal.hpp") and 20 <= line <= 22:
            return "setup", "RecentTriangles initialisers"
    return "other", (chain[0][0] if chain else "?")


def addr2line(binary, addrs):
    """{addr: [(function, file, line)]} innermost first, for file addresses `addrs`."""
    out = {}
    if not addrs:
        return out
    text = subprocess.run(["addr2line", "-C", "-f", "-i", "-a", "-e", binary],
                          input="\n".join(f"{a:#x}" for a in addrs), capture_output=True, text=True,
                          check=True).stdout.split("\n")
    cur, i = None, 0
    while i < len(text):
        line = text[i]
        if line.startswith("0x"):
            cur = int(line, 16)
            out[cur] = []
            i += 1
            continue
        if cur is None or i + 1 >= len(text):
            i += 1
            continue
        fn, loc = line, text[i + 1]
        path, _, ln = loc.rpartition(":")
        ln = ln.split(" ")[0]
        out[cur].append((fn, path, int(ln) if ln.isdigit() else 0))
        i += 2
    return out


# ---------------------------------------------------------------------------------------------------
# callgrind output (--compress-strings=no --compress-pos=no --dump-instr=yes)

def parse_dump(path):
    """(summary Ir, {"intersect": Ir, "occluded": Ir} entered from outside, {(object, addr): [events]})."""
    events, ob, fn, cfn = EVENTS, "", "", ""
    entry = {"intersect": 0, "occluded": 0}
    cost = collections.defaultdict(lambda: [0] * len(EVENTS))
    total = 0
    skip_next = False
    positions = 2
    with open(path, errors="replace") as f:
        for line in f:
            if skip_next:
                skip_next = False
                parts = line.split()
                e = ENTRY.match(cfn.replace("(anonymous namespace)", "anon"))
                if e and not ENTRY.match(fn.replace("(anonymous namespace)", "anon")):
                    entry[e.group(1)] += int(parts[positions]) if len(parts) > positions else 0
                continue
            c = line[0]
            if c == "0":
                parts = line.split()
                vals = cost[(ob, int(parts[0], 16))]
                for k, v in enumerate(parts[positions:]):
                    vals[k] += int(v)
            elif line.startswith("fn="):
                fn = line[3:].rstrip("\n")
            elif line.startswith("ob="):
                ob = line[3:].rstrip("\n")
            elif line.startswith("cfn="):
                cfn = line[4:].rstrip("\n")
            elif line.startswith("calls="):
                skip_next = True
            elif line.startswith("events:"):
                events = line.split()[1:]
                if events != EVENTS:
                    sys.exit(f"step_costs.py: error: {path}: unexpected events {events}")
            elif line.startswith("positions:"):
                positions = len(line.split()) - 1
            elif line.startswith(("summary:", "totals:")):
                total = int(line.split()[1])
    return total, entry, cost


def symbol_table(binary):
    """[(addr, size, demangled name)] of the binary's functions."""
    out = []
    text = subprocess.run(["nm", "-C", "-S", "--defined-only", binary], capture_output=True, text=True,
                          check=True).stdout
    for line in text.split("\n"):
        parts = line.split(" ", 3)
        if len(parts) == 4 and parts[2] in "tTwW":
            out.append((int(parts[0], 16), int(parts[1], 16), parts[3]))
    return out


def find_base(binary, dump_paths):
    """The load offset of a PIE binary under valgrind: the offset under which the first instruction of
    the most functions listed in the dumps lands on their symbol's address."""
    hdr = subprocess.run(["readelf", "-h", binary], capture_output=True, text=True, check=True).stdout
    if "EXEC (Executable file)" in hdr:
        return 0
    syms = {name: addr for addr, _, name in symbol_table(binary)}
    exe = os.path.realpath(binary)
    firsts = {}
    for p in dump_paths:
        ob, fn = "", ""
        with open(p, errors="replace") as f:
            for line in f:
                if line.startswith("ob="):
                    ob = os.path.realpath(line[3:].strip())
                elif line.startswith("fn="):
                    fn = line[3:].strip()
                elif line[0] == "0" and ob == exe and fn in syms:
                    a = int(line.split()[0], 16)
                    firsts[fn] = min(firsts.get(fn, a), a)
    votes = collections.Counter(a - syms[fn] for fn, a in firsts.items())
    if not votes:
        sys.exit(f"step_costs.py: error: cannot find where valgrind loaded {binary}")
    return votes.most_common(1)[0][0]


# ---------------------------------------------------------------------------------------------------

def run_one(o, config, scene, rays, out_path):
    d = out_path + ".tmp"
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    bench_json = os.path.join(d, "bench.json")
    cmd = ["valgrind", "--tool=callgrind", "--instr-atstart=no", "--cache-sim=yes", "--branch-sim=yes",
           f"--I1={o.I1}", f"--D1={o.D1}", f"--LL={o.LL}", "--dump-instr=yes", "--compress-strings=no",
           "--compress-pos=no", "--dump-before=*clock_gettime*", f"--callgrind-out-file={d}/cg.out",
           o.bench, "--scenes-dir", o.scenes_dir, "--scenes", scene, "--configs", config, "--rays", rays,
           "--size", o.size, "--builds", "1", "--repeats", "1", "--json", bench_json]
    t0 = time.time()
    res = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.time() - t0
    if res.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{res.stderr[-3000:]}")
    files = sorted(glob.glob(f"{d}/cg.out.*"), key=lambda p: int(p.rsplit(".", 1)[1]))
    dumps = []
    for p in files:
        total, entry, cost = parse_dump(p)
        # A pass's dump is mostly its batch call; the dumps between passes never enter one. Not "all but
        # 1 %": the bench's fixed cost around the call (its allocations, more on the first pass) is more
        # than that of a tiny pass.
        if total and max(entry.values()) > 0.5 * total:
            dumps.append((p, total, entry, cost))
    if len(dumps) != 4:
        sys.exit(f"step_costs.py: error: {config} {scene} {rays}: {len(dumps)} pass dumps, expected 4 "
                 f"(warm-up and timed, two kinds)")
    row = json.load(open(bench_json))[0]
    exe = os.path.realpath(o.bench)
    base = find_base(o.bench, [p for p, *_ in dumps])
    addrs = sorted({a for _, _, _, cost in dumps[2:] for (ob, a) in cost if os.path.realpath(ob) == exe})
    chains = addr2line(o.bench, [a - base for a in addrs])
    cls = {a: classify_chain(chains.get(a - base, [])) for a in addrs}
    passes = {}
    for (p, total, entry, cost), kind in zip(dumps[2:], ("primary", "secondary")):
        cats = {c: [0] * len(EVENTS) for c in CATEGORIES}
        other = collections.Counter()
        hot = []
        for (ob, a), v in cost.items():
            if os.path.realpath(ob) == exe:
                cat, why = cls[a]
            else:
                cat, why = "other", os.path.basename(ob)
            cats[cat] = [x + y for x, y in zip(cats[cat], v)]
            if cat == "other":
                other[why] += v[0]
            if v[0]:
                fr = chains.get(a - base, [])
                hot.append({"addr": a - base, "count": v[0], "cat": cat,
                            "where": [f"{fn.split('(')[0][-60:]} {os.path.basename(f)}:{ln}" for fn, f, ln in fr[:4]]})
        work = row["primary_per_ray" if kind == "primary" else "shadow_per_ray"]
        n = row["primary_rays" if kind == "primary" else "shadow_rays"]
        passes[kind] = {
            "query": "closest" if entry["intersect"] > entry["occluded"] else "any",
            "rays": n, "nodes": work["nodes"] * n, "leaves": work["leaves"] * n, "triangles": work["triangles"] * n,
            "total": dict(zip(EVENTS, [sum(c[k] for c in cats.values()) for k in range(len(EVENTS))])),
            "dump_total_ir": total,
            "categories": {c: dict(zip(EVENTS, v)) for c, v in cats.items()},
            "other_top": other.most_common(8),
            "instructions": sorted(hot, key=lambda h: -h["count"])[:400] if o.keep_instructions else [],
        }
    result = {"config": config, "scene": scene, "rays": rays, "size": o.size, "secondary_kind": row["shadow_kind"],
              "triangles_in_scene": row["triangles"], "valgrind_seconds": wall, "passes": passes}
    with open(out_path, "w") as f:
        json.dump(result, f)
    if not o.keep_dumps:
        shutil.rmtree(d, ignore_errors=True)
    return result


def per_step(p):
    """Ir and estimated cycles per step of one pass, with the cycles split into instructions, cache
    misses and mispredictions."""
    cats = p["categories"]
    counts = {"setup": p["rays"], "batch": p["rays"], "node": p["nodes"], "leaf": p["leaves"],
              "triangle": p["triangles"], "other": p["rays"]}
    merged = dict(cats)
    merged["leaf"] = {e: cats["leaf"][e] + cats["pop"][e] for e in EVENTS}  # a leaf and the pop after it
    out = {}
    for c, n in counts.items():
        ev = merged[c]
        if not n:
            out[c] = None
            continue
        l1 = ev["I1mr"] + ev["D1mr"] + ev["D1mw"]
        ll = ev["ILmr"] + ev["DLmr"] + ev["DLmw"]
        br = ev["Bcm"] + ev["Bim"]
        out[c] = {"count": n, "ir": ev["Ir"] / n, "cycles": cycles(ev) / n,
                  "cyc_instr": ev["Ir"] / n, "cyc_l1": 10 * l1 / n, "cyc_ll": 100 * ll / n, "cyc_mispredict": 20 * br / n,
                  "l1_misses": l1 / n, "ll_misses": ll / n, "mispredicts": br / n, "branches": (ev["Bc"] + ev["Bi"]) / n}
    t = p["total"]
    out["ray"] = {"count": p["rays"], "ir": t["Ir"] / p["rays"], "cycles": cycles(t) / p["rays"],
                  "cyc_instr": t["Ir"] / p["rays"],
                  "cyc_l1": 10 * (t["I1mr"] + t["D1mr"] + t["D1mw"]) / p["rays"],
                  "cyc_ll": 100 * (t["ILmr"] + t["DLmr"] + t["DLmw"]) / p["rays"],
                  "cyc_mispredict": 20 * (t["Bcm"] + t["Bim"]) / p["rays"],
                  "nodes": p["nodes"] / p["rays"], "leaves": p["leaves"] / p["rays"],
                  "triangles": p["triangles"] / p["rays"]}
    out["share"] = {c: cats[c]["Ir"] / t["Ir"] if t["Ir"] else 0 for c in CATEGORIES}
    return out


def lstsq(rows, cols):
    """Ordinary least squares by the normal equations (Gauss-Jordan); rows: [(y, [x...])]."""
    k = len(cols)
    a = [[0.0] * (k + 1) for _ in range(k)]
    for y, x in rows:
        for i in range(k):
            for j in range(k):
                a[i][j] += x[i] * x[j]
            a[i][k] += x[i] * y
    for i in range(k):
        piv = max(range(i, k), key=lambda r: abs(a[r][i]))
        a[i], a[piv] = a[piv], a[i]
        if abs(a[i][i]) < 1e-12:
            return None
        for r in range(k):
            if r != i:
                f = a[r][i] / a[i][i]
                a[r] = [x - f * y for x, y in zip(a[r], a[i])]
    coef = [a[i][k] / a[i][i] for i in range(k)]
    resid = [y - sum(c * xi for c, xi in zip(coef, x)) for y, x in rows]
    ss = sum(r * r for r in resid)
    mean = sum(y for y, _ in rows) / len(rows)
    tot = sum((y - mean) ** 2 for y, _ in rows) or 1.0
    return {"coef": dict(zip(cols, coef)), "r2": 1 - ss / tot,
            "max_rel_residual": max(abs(r) / y for r, (y, _) in zip(resid, rows) if y)}


def fits(results):
    """Per configuration and query (closest, any): Ir and estimated cycles of a pass against its rays,
    nodes, leaves and triangles, over every distinct pass (frame, AO and diffuse share their primary rays)."""
    out = {}
    groups = collections.defaultdict(dict)
    for r in results:
        for kind, p in r["passes"].items():
            key = (r["scene"], "random" if r["rays"] == "random" else "frame", kind) if kind == "primary" else \
                (r["scene"], r["rays"], kind)
            groups[(r["config"], p["query"])][key] = p
    for (config, query), ps in groups.items():
        cols = ["rays", "nodes", "leaves", "triangles"]
        for metric in ("ir", "cycles"):
            rows = [((p["total"]["Ir"] if metric == "ir" else cycles(p["total"])), [p[c] for c in cols])
                    for p in ps.values()]
            if len(rows) > len(cols):
                f = lstsq(rows, cols)
                if f:
                    f["passes"] = len(rows)
                    out.setdefault(config, {}).setdefault(query, {})[metric] = f
    return out


def hot_loop(binary, results, config="kd:branched"):
    """The branched kd kernel's inner loop in the disassembly: the function holding the busiest
    node-step instruction of `config`'s primary pass (sponza frame where measured), every instruction
    of it as objdump prints it, with its step and how often it ran in that pass, and the node-step
    instructions grouped by that count: a group run once per node step is the loop's common path."""
    runs = [r for r in results if r["config"] == config and r["passes"]["primary"].get("instructions")]
    runs.sort(key=lambda r: (r["scene"] != "sponza", r["rays"] != "frame"))
    if not runs:
        return None
    run = runs[0]
    p = run["passes"]["primary"]
    counts = {h["addr"]: h["count"] for h in p["instructions"]}
    steps = [h for h in p["instructions"] if h["cat"] == "node"]
    if not steps:  # no node step among the busiest instructions: the kernel had no line information
        return None
    top = max(steps, key=lambda h: h["count"])["addr"]
    sym = next(((a, n, name) for a, n, name in symbol_table(binary) if a <= top < a + n), None)
    if not sym:
        return None
    addr, size, name = sym
    dis = subprocess.run(["objdump", "-d", "--no-show-raw-insn", f"--start-address={addr:#x}",
                          f"--stop-address={addr + size:#x}", binary], capture_output=True, text=True,
                         check=True).stdout
    insns = []
    for line in dis.split("\n"):
        m = re.match(r"\s+([0-9a-f]+):\s+(.*)$", line)
        if m:
            insns.append((int(m.group(1), 16), re.sub(r"\s+<.*>$", "", m.group(2).strip())))
    chains = addr2line(binary, [a for a, _ in insns])
    out, groups = [], collections.defaultdict(list)
    for a, text in insns:
        ch = chains.get(a, [])
        cat, _ = classify_chain(ch)
        n = counts.get(a, 0)
        if n:
            out.append({"addr": a, "insn": text, "cat": cat, "count": n,
                        "line": f"{os.path.basename(ch[0][1])}:{ch[0][2]}" if ch else ""})
        if n and cat in ("node", "triangle"):
            groups[(cat, n)].append(text.split()[0])
    return {"config": config, "scene": run["scene"], "rays": run["rays"], "nodes": p["nodes"], "leaves": p["leaves"],
            "triangles": p["triangles"], "function": name,
            "groups": [{"cat": c, "count": n, "per_step": n / (p["nodes"] if c == "node" else p["triangles"]),
                        "instructions": len(v), "mnemonics": v}
                       for (c, n), v in sorted(groups.items(), key=lambda kv: (kv[0][0], -kv[0][1]))],
            "instructions (executed, in address order)": out}


def fmt(x, digits=0):
    return "–" if x is None else f"{x:,.{digits}f}"


def tables(path, split_scenes=("sponza",)):
    """The markdown tables of docs/INCOHERENT.md from a JSON this script wrote."""
    doc = bench_outputs.load_json(path)
    rows = doc["rows"]
    configs = list(dict.fromkeys(r["config"] for r in rows))
    scenes = list(dict.fromkeys(r["scene"] for r in rows))

    def passes(config):
        seen = set()
        order = {"frame": 0, "ao": 1, "diffuse": 2, "random": 3}
        for r in sorted((r for r in rows if r["config"] == config),
                        key=lambda r: (scenes.index(r["scene"]), order.get(r["rays"], 9), r["pass"] != "primary")):
            label = ("random closest" if r["pass"] == "primary" else "random any") if r["rays"] == "random" else \
                ("primary" if r["pass"] == "primary" else r["kind"])
            if (r["scene"], label) in seen:
                continue
            seen.add((r["scene"], label))
            yield label, r

    out = []
    for c in configs:
        out.append(f"**{c}**: per ray; then Ir / estimated cycles per step\n")
        out.append("| scene | rays | nodes / leaves / tris per ray | Ir per ray | cycles per ray | set-up | node step | "
                   "leaf | triangle | batch loop |")
        out.append("|---|---|---|--:|--:|--:|--:|--:|--:|--:|")
        for label, r in passes(c):
            ps = r["per_step"]
            ray = ps["ray"]
            cell = lambda k: "–" if ps[k] is None else f"{ps[k]['ir']:.0f} / {ps[k]['cycles']:.0f}"
            out.append(f"| {r['scene']} | {label} | {ray['nodes']:.1f} / {ray['leaves']:.1f} / {ray['triangles']:.1f} | "
                       f"{ray['ir']:,.0f} | {ray['cycles']:,.0f} | {cell('setup')} | {cell('node')} | {cell('leaf')} | "
                       f"{cell('triangle')} | {cell('batch')} |")
        out.append("")
    out.append("Estimated cycles per step split: instructions + L1 misses x 10 + LL misses x 100 + mispredictions x 20\n")
    out.append("| config | scene | rays | step | Ir | L1 miss cycles | LL miss cycles | mispredict cycles | "
               "L1 misses | LL misses | mispredictions | share of the ray's cycles |")
    out.append("|---|---|---|---|--:|--:|--:|--:|--:|--:|--:|--:|")
    for c in configs:
        for label, r in passes(c):
            if r["scene"] not in split_scenes or label not in ("primary", "shadow", "random closest", "random any"):
                continue
            ps = r["per_step"]
            tot = ps["ray"]["cycles"] * ps["ray"]["count"]
            for k in ("setup", "node", "leaf", "triangle"):
                x = ps[k]
                if x is None:
                    continue
                out.append(f"| {c} | {r['scene']} | {label} | {k} | {x['ir']:.1f} | {x['cyc_l1']:.1f} | {x['cyc_ll']:.1f} | "
                           f"{x['cyc_mispredict']:.1f} | {x['l1_misses']:.3f} | {x['ll_misses']:.3f} | "
                           f"{x['mispredicts']:.3f} | {100 * x['cycles'] * x['count'] / tot:.0f} % |")
    out.append("")
    out.append("Least-squares fit of Ir per pass = a rays + b nodes + c leaves + d triangles\n")
    out.append("| config | query | passes | per ray | per node | per leaf | per triangle | R² | worst residual |")
    out.append("|---|---|--:|--:|--:|--:|--:|--:|--:|")
    for c in configs:
        for q, f in sorted(doc["fits"].get(c, {}).items()):
            g = f["ir"]
            k = g["coef"]
            out.append(f"| {c} | {q} | {g['passes']} | {k['rays']:.0f} | {k['nodes']:.1f} | {k['leaves']:.1f} | "
                       f"{k['triangles']:.1f} | {g['r2']:.4f} | {100 * g['max_rel_residual']:.1f} % |")
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bench", default=os.path.join(ROOT, "build/bench/cellrt_bench"))
    ap.add_argument("--scenes-dir", default=os.path.join(ROOT, "../shared/scenes"))
    ap.add_argument("--scenes", nargs="+", default=["sponza", "sibenik", "bunny", "teapot"])
    ap.add_argument("--rays", nargs="+", default=["frame", "random", "ao", "diffuse"])
    ap.add_argument("--configs", nargs="+", default=["kd:branched", "bvh:wide", "kd:rec", "kd:branchless", "bih:branched"])
    ap.add_argument("--size", default="128x128")
    ap.add_argument("--I1", default="32768,8,64")
    ap.add_argument("--D1", default="49152,12,64")
    ap.add_argument("--LL", default="2097152,16,64", help="the simulated last level: by default this machine's L2")
    ap.add_argument("--work", default="/tmp/step_costs", help="finished runs, one JSON each")
    ap.add_argument("--json", help="write the study here")
    ap.add_argument("--overwrite", action="store_true", help="replace the --json file if it exists")
    ap.add_argument("--tables", metavar="JSON", help="print the markdown tables of a written study and stop")
    ap.add_argument("--order", choices=["rays", "scenes"], default="rays",
                    help="rays: every configuration on one (ray kind, scene) before the next")
    ap.add_argument("--report-only", action="store_true", help="only gather what --work holds")
    ap.add_argument("--keep-dumps", action="store_true")
    ap.add_argument("--keep-instructions", action="store_true", help="the 400 busiest instructions of each pass")
    o = ap.parse_args()
    if o.tables:
        print(tables(o.tables))
        return
    if not o.json:
        ap.error("--json is required")
    bench_outputs.check_output(ap, "--json", o.json, o.overwrite)
    if not os.path.exists(o.bench):
        sys.exit(f"step_costs.py: error: no bench at {o.bench}")
    # Without line information every instruction would fall to "other", silently.
    sections = subprocess.run(["readelf", "-S", "-W", o.bench], capture_output=True, text=True).stdout
    if ".debug_line" not in sections:
        sys.exit(f"step_costs.py: error: {o.bench} has no line information; build it with "
                 f"-DCMAKE_CXX_FLAGS=-g (docs/INCOHERENT.md)")
    RULES.update(resolve_line_rules(ROOT, o.configs))
    os.makedirs(o.work, exist_ok=True)
    todo = [(c, s, r) for r in o.rays for s in o.scenes for c in o.configs]
    results = []
    for c, s, r in todo:
        path = os.path.join(o.work, re.sub(r"[^\w.+=@-]", "_", f"{c}__{s}__{r}") + ".json")
        if os.path.exists(path):
            results.append(json.load(open(path)))
            continue
        if o.report_only:
            continue
        t = time.time()
        res = run_one(o, c, s, r, path)
        results.append(res)
        pp = res["passes"]
        print(f"{c:14} {s:8} {r:8} {time.time() - t:6.0f} s  primary {pp['primary']['total']['Ir'] / pp['primary']['rays']:8.0f}"
              f" Ir/ray  {res['secondary_kind']} {pp['secondary']['total']['Ir'] / pp['secondary']['rays']:8.0f} Ir/ray",
              flush=True)
    rows = []
    for r in results:
        for kind, p in r["passes"].items():
            rows.append({"config": r["config"], "scene": r["scene"], "rays": r["rays"], "pass": kind,
                         "kind": "primary" if kind == "primary" else r["secondary_kind"], "query": p["query"],
                         "per_step": per_step(p), "totals": p["total"], "categories": p["categories"],
                         "other_top": p["other_top"]})
    doc = {
        "what": "callgrind per-step costs of cellrt's single-ray kernels (bench/step_costs.py, docs/INCOHERENT.md)",
        "bench": os.path.relpath(o.bench, ROOT), "size": o.size,
        "valgrind": subprocess.run(["valgrind", "--version"], capture_output=True, text=True).stdout.strip(),
        "caches": {"I1": o.I1, "D1": o.D1, "LL": o.LL},
        "cycles": "Ir + 10*(I1mr+D1mr+D1mw) + 100*(ILmr+DLmr+DLmw) + 20*(Bcm+Bim)",
        "categories": "setup, batch: per ray; node: per inner node; leaf: per leaf, its pop included; triangle: per triangle tested",
        "rows": rows, "fits": fits(results),
        "hot_loops": {c: hot_loop(o.bench, results, c) for c in ("kd:branched", "bvh:wide")},
    }
    os.makedirs(os.path.dirname(os.path.abspath(o.json)), exist_ok=True)
    with open(o.json, "w") as f:
        json.dump(doc, f, indent=1)
    print(f"wrote {o.json}: {len(rows)} passes")


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "step_costs"))
