#!/usr/bin/env python3
"""A/B of two cellrt_bench builds by instruction counts. Each binary runs under callgrind on the
same rays. For every scene, configuration and ray kind, the script reports the instructions (Ir) of
one timed pass: primary rays through intersect, then the rays of the second kind (shadow, AO and
random rays through occluded, diffuse bounces through intersect), which the bench's JSON and this
table call "shadow" whatever their kind. Each count is the inclusive cost of the bench's calls into
the accelerator's entry point, so building the structures and making the rays are left out.

Why: on the shared VM, times of whole runs vary by +-10% (docs/BENCHMARKS.md), which is more than
the 2% to be shown. Instruction counts repeat exactly from run to run. They are not time: they do
not see cache misses, mispredicted branches or which instructions run. But a refactor that only
moves code barely changes them, so a ratio near 1 is the evidence, and a larger one shows where to
look.

How: callgrind starts a new dump each time clock_gettime is called (--dump-before), and cellrt_bench
reads the clock just before and just after every pass. So each pass is a dump of its own, whether a
run traces one configuration or all of them (the counts are the same either way). A round is a
primary dump, then gap dumps (calling neither entry point, or tiny), then the second kind's dump. For each
scene the bench runs one warm-up round per configuration, then --repeats more; the last round is the
one reported. Under valgrind '+auto' resolves to avx2, because valgrind has no AVX-512.

With --cache-sim, callgrind also simulates the data caches (Zen 3's: 32 KiB first level, 512 KiB
second) and the table adds the first- and second-level data misses per ray of the same calls: the
lines a traversal touches that were not cached, which instruction counts do not see.

    bench/ab_callgrind.py OLD NEW --json out.json [--overwrite] [--keep DIR] [--cache-sim] -- [cellrt_bench options]
"""
import argparse
import glob
import json
import math
import os
import re
import subprocess
import sys
import tempfile

import bench_outputs
from bench_outputs import check_output

ENTRY = re.compile(r"^[\w:<>, ]*::(intersect|occluded)\(std::span<cellrt::Ray const")


def option_values(args, name, default):
    if name not in args:
        return default
    i = args.index(name) + 1
    vals = []
    while i < len(args) and not args[i].startswith("--"):
        vals.append(args[i])
        i += 1
    return vals


def without_option(args, name):
    if name not in args:
        return list(args)
    i = args.index(name)
    j = i + 1
    while j < len(args) and not args[j].startswith("--"):
        j += 1
    return args[:i] + args[j:]


def dump_counts(path):
    """(total Ir, intersect costs, occluded costs) of one callgrind dump: the inclusive cost of the calls
    into an accelerator's intersect/occluded from outside one (the bench's loop), per event (Ir, and with
    the cache simulation Dr, Dw, D1mr, ...) as a dict."""
    names, fn, cfn, total = {}, "", "", 0
    events, skip = ["Ir"], 1
    cost = {"intersect": {}, "occluded": {}}
    lines = iter(open(path, errors="replace"))
    for line in lines:
        if line.startswith("events:"):
            events = line.split()[1:]
        elif line.startswith("positions:"):
            skip = len(line.split()) - 1
        elif line.startswith(("fn=", "cfn=")):
            key, _, rest = line.rstrip("\n").partition("=")
            ident, _, name = rest.partition(" ")
            if name:
                names[ident] = name
            if key == "fn":
                fn = names.get(ident, ident)
            else:
                cfn = names.get(ident, ident)
        elif line.startswith("calls="):
            values = [int(v) for v in next(lines).split()[skip:]]
            e = ENTRY.match(cfn.replace("(anonymous namespace)", "anon"))
            if e and not ENTRY.match(fn.replace("(anonymous namespace)", "anon")):
                c = cost[e.group(1)]
                for name, v in zip(events, values):
                    c[name] = c.get(name, 0) + v
        elif line.startswith(("summary:", "totals:")):
            total = int(line.split()[1])
    return total, cost["intersect"], cost["occluded"]


# The ray kinds answered by intersect (closest hit); every other kind goes through occluded.
CLOSEST_KINDS = {"primary", "bounce"}


def pass_cost(dump, call):
    """The costs of `dump` when it is one pass through `call` ("intersect" or "occluded"): all but 1 % of
    its instructions inside that call and none in the other; None otherwise."""
    total, intersect, occluded = dump
    mine, other = (intersect, occluded) if call == "intersect" else (occluded, intersect)
    return mine if mine.get("Ir", 0) > 0.99 * total and not other else None


# The cache simulation's geometry, the Zen 3 cores this was measured on: 32 KiB 8-way first-level data
# (and instruction) cache, 512 KiB 8-way second level (callgrind's "LL"), 64-byte lines.
CACHE_SIM = ["--cache-sim=yes", "--I1=32768,8,64", "--D1=32768,8,64", "--LL=524288,8,64"]


def run(binary, configs, args, keep, cache_sim):
    """{(config, scene): {primary, shadow, rounds, rays, work}} from one callgrind run of `configs`; primary
    and shadow are the last round's {event: count}."""
    d = tempfile.mkdtemp(prefix="ab_cg_", dir=keep)
    bench_json = os.path.join(d, "bench.json")
    cmd = ["valgrind", "--tool=callgrind", *(CACHE_SIM if cache_sim else []), f"--callgrind-out-file={d}/cg.out",
           "--dump-before=*clock_gettime*", binary, *without_option(without_option(args, "--configs"), "--json"), "--configs", *configs,
           "--json", bench_json]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        sys.exit(f"ab_callgrind.py: error: {' '.join(cmd)} failed:\n{res.stderr[-2000:]}")
    rows = json.load(open(bench_json))
    # The second pass calls what its kind asks (closest_hit() in workload.hpp): intersect for bounce
    # rays (--rays diffuse), occluded for shadow, AO and random any-hit rays. A bench older than
    # --rays ao/diffuse writes no shadow_kind: its second kind is shadow.
    kinds = {r.get("shadow_kind", "shadow") for r in rows}
    if len(kinds) != 1:
        sys.exit(f"ab_callgrind.py: error: {binary}: second ray kinds {sorted(kinds)}, expected one")
    second = "intersect" if kinds <= CLOSEST_KINDS else "occluded"
    files = sorted(glob.glob(f"{d}/cg.out.*"), key=lambda p: int(p.rsplit(".", 1)[1]))
    dumps = [dump_counts(p) for p in files]
    rounds, i = [], 0
    while i < len(dumps):
        if pass_cost(dumps[i], "intersect"):
            j = i + 1
            # Gaps: dumps that call neither entry point, or tiny ones that are no pass of the second
            # kind (the route's own clock reads inside a pass cut a few calls into dumps of their own).
            while j < len(dumps) and not pass_cost(dumps[j], second) and (not any(dumps[j][1:]) or dumps[j][0] < 10000):
                j += 1
            if j < len(dumps) and pass_cost(dumps[j], second):
                rounds.append((pass_cost(dumps[i], "intersect"), pass_cost(dumps[j], second)))
                i = j
        i += 1
    # Per scene, the bench traces its configurations in turn: a warm-up round, then --repeats rounds.
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    traced = [[r for r in rows if r["scene"] == s] for s in scenes]
    passes = 1 + int(option_values(args, "--repeats", ["5"])[0])
    if len(rounds) != passes * len(rows):
        sys.exit(f"ab_callgrind.py: error: {binary}: {len(rounds)} pass rounds for {len(rows)} (scene, config) "
                 f"rows x {passes}; rerun with --keep to look at the dumps")
    out, k = {}, 0
    for rs in traced:
        mine = rounds[k:k + passes * len(rs)]
        k += passes * len(rs)
        for j, r in enumerate(rs):
            own = mine[j::len(rs)]
            out[(r["config"], r["scene"])] = {
                "primary": own[-1][0], "shadow": own[-1][1], "rounds": own, "primary_rays": r["primary_rays"],
                "shadow_rays": r["shadow_rays"], "work": [r["primary_per_ray"], r["shadow_per_ray"]]}
    if not keep:
        for p in glob.glob(f"{d}/*"):
            os.unlink(p)
        os.rmdir(d)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--json", required=True, help="write the counts and ratios here")
    ap.add_argument("--overwrite", action="store_true", help="replace an existing --json file")
    ap.add_argument("--keep", help="keep the callgrind dumps in folders under this one")
    ap.add_argument("--cache-sim", action="store_true",
                    help="also simulate the caches (32 KiB L1, 512 KiB L2) and report first- and second-level "
                         "data misses per ray beside the instructions")
    ap.add_argument("--one-config-per-run", action="store_true",
                    help="one valgrind run per configuration (the counts are the same; the scenes load more often)")
    argv = sys.argv[1:]
    split = argv.index("--") if "--" in argv else len(argv)
    o = ap.parse_args(argv[:split])
    check_output(ap, "--json", o.json, o.overwrite)
    args = argv[split + 1:]
    configs = option_values(args, "--configs", ["kd:rec", "kd:branched", "kd:branchless", "kd+auto",
                                                "bih:branched", "bih:branchless", "bih+auto", "bih+auto@split=sah"])
    groups = [[c] for c in configs] if o.one_config_per_run else [configs]
    results = []
    if o.cache_sim:
        print("| config | scene | kind | Ir old | Ir new | new/old | D1 misses/ray old | new | L2 misses/ray old | new |"
              "\n|---|---|---|---|---|---|---|---|---|---|", flush=True)
    else:
        print("| config | scene | kind | Ir old | Ir new | new/old |\n|---|---|---|---|---|---|", flush=True)
    for g in groups:
        old, new = run(o.old, g, args, o.keep, o.cache_sim), run(o.new, g, args, o.keep, o.cache_sim)
        for key in old:
            c, s = key
            if old[key]["work"] != new[key]["work"] or old[key]["primary_rays"] != new[key]["primary_rays"]:
                print(f"warning: {c} {s}: old and new traced different rays or did different work", file=sys.stderr)
            for kind in ("primary", "shadow"):
                a, b = old[key][kind]["Ir"], new[key][kind]["Ir"]
                rays = old[key][kind + "_rays"]
                row = {"config": c, "scene": s, "kind": kind, "rays": rays, "ir_old": a, "ir_new": b, "ratio": b / a,
                       "passes_old": [r[kind == "shadow"]["Ir"] for r in old[key]["rounds"]],
                       "passes_new": [r[kind == "shadow"]["Ir"] for r in new[key]["rounds"]]}
                line = f"| {c} | {s} | {kind} | {a:,} | {b:,} | {b / a:.4f} |"
                if o.cache_sim:
                    for side, counts in (("old", old[key][kind]), ("new", new[key][kind])):
                        row["events_" + side] = counts
                        row["d1_misses_per_ray_" + side] = (counts.get("D1mr", 0) + counts.get("D1mw", 0)) / rays
                        row["l2_misses_per_ray_" + side] = (counts.get("DLmr", 0) + counts.get("DLmw", 0)) / rays
                    line += (f" {row['d1_misses_per_ray_old']:.2f} | {row['d1_misses_per_ray_new']:.2f} |"
                             f" {row['l2_misses_per_ray_old']:.2f} | {row['l2_misses_per_ray_new']:.2f} |")
                results.append(row)
                print(line, flush=True)
    cell = [r["ratio"] for r in results if not r["config"].startswith("embree")]
    summary = {}
    if cell:
        summary = {"points": len(cell), "max": max(cell), "min": min(cell),
                   "geomean": math.exp(sum(map(math.log, cell)) / len(cell)),
                   "above_1.02": [f'{r["config"]} {r["scene"]} {r["kind"]}' for r in results
                                  if not r["config"].startswith("embree") and r["ratio"] > 1.02]}
        print(f"\ncellrt points: {len(cell)}, new/old geomean {summary['geomean']:.4f}, "
              f"min {summary['min']:.4f}, max {summary['max']:.4f}, above 1.02: {summary['above_1.02'] or 'none'}")
    with open(o.json, "w") as f:
        json.dump({"old": o.old, "new": o.new, "bench_args": args, "measure": "callgrind Ir" + (" and simulated D1/L2 data misses" if o.cache_sim else "") + ", one timed pass",
                   "summary": summary, "results": results}, f, indent=1)


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "ab_callgrind"))
