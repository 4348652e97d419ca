#!/usr/bin/env python3
"""The summary table of docs/INCOHERENT.md from cellrt_bench's JSON, one file per ray kind: per scene,
Embree's fastest configuration in the same run, cellrt's fastest exact configuration over it (primary
and second-kind rays together, then the second kind alone), named configurations over it, and the
kd-tree's single-ray path (kd:branched) over rtcIntersect1 on the primary rays.

usage: bench/kinds_table.py PREFIX KIND... [--second] [--configs CONFIG...]
       (reads PREFIX_KIND.json for each KIND, e.g. docs/figures/incoherent_zen3/after frame ao)

--second: each named configuration's second kind of rays alone over Embree's fastest on them, after
its figure for both kinds. A configuration that reports its route (`auto`: the share of rays each
path answered) gets a second table of those shares.
"""
import sys
import bench_outputs


def rate(r):
    return (r["primary_rays"] + r["shadow_rays"]) / (r["primary_seconds"] + r["shadow_seconds"])


def second_rate(r):
    return r["shadow_rays"] / r["shadow_seconds"]


def primary_rate(r):
    return r["primary_rays"] / r["primary_seconds"]


def main(argv) -> int:
    if len(argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    configs = []
    second = "--second" in argv
    argv = [a for a in argv if a != "--second"]
    if "--configs" in argv:
        i = argv.index("--configs")
        argv, configs = argv[:i], argv[i + 1 :]
    prefix, kinds = argv[1], argv[2:]
    head = ["rays", "scene", "Embree's fastest, Mrays/s", "cellrt's fastest ÷ Embree's", "second kind alone"]
    for c in configs:
        head += [f"{c} ÷ Embree's"] + ([f"{c}, second kind"] if second else [])
    head += ["kd:branched ÷ rtcIntersect1, primary"]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * 2 + "--:|" * (len(head) - 2))
    for kind in kinds:
        rows = bench_outputs.load_json(f"{prefix}_{kind}.json", rows=True)
        for scene in dict.fromkeys(r["scene"] for r in rows):
            rs = {r["config"]: r for r in rows if r["scene"] == scene}
            embree = [c for c in rs if c.startswith("embree")]
            ours = [c for c in rs if not c.startswith("embree")]
            best = max(embree, key=lambda c: rate(rs[c]))
            best_second = max(second_rate(rs[c]) for c in embree)
            fastest = max(ours, key=lambda c: rate(rs[c]))
            fastest_second = max(ours, key=lambda c: second_rate(rs[c]))
            cells = [kind, scene, f"{rate(rs[best]) * 1e-6:.2f} ({best})",
                     f"{rate(rs[fastest]) / rate(rs[best]):.2f} ({fastest})",
                     f"{second_rate(rs[fastest_second]) / best_second:.2f} ({fastest_second})"]
            for c in configs:
                cells.append(f"{rate(rs[c]) / rate(rs[best]):.2f}" if c in rs else "–")
                if second:
                    cells.append(f"{second_rate(rs[c]) / best_second:.2f}" if c in rs else "–")
            if "kd:branched" in rs and "embree:single" in rs:
                cells.append(f"{primary_rate(rs['kd:branched']) / primary_rate(rs['embree:single']):.2f}")
            else:
                cells.append("–")
            print("| " + " | ".join(cells) + " |")
    routed = []
    for kind in kinds:
        rows = bench_outputs.load_json(f"{prefix}_{kind}.json", rows=True)
        routed += [(kind, r["scene"], r["config"], r["routed"]) for r in rows if r.get("routed")]
    if routed:
        print("\n| rays | scene | config | share of rays per path (primary: closest; second kind: closest or any) |")
        print("|---|---|---|---|")
        for row in routed:
            print("| " + " | ".join(row) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(bench_outputs.run(lambda: main(sys.argv), "kinds_table"))
