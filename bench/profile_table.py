#!/usr/bin/env python3
"""Instruction-level statistics of every structure x traversal on every shared scene (the study's
Table 5-7), as Markdown tables for docs/PROFILE.md: runs `cellrt profile --json` for each and prints
the traversal alone, the whole render, and branchless against branched.

usage: bench/profile_table.py [--cellrt build/cellrt] [--scenes ../shared/scenes]
                              [--method auto|hardware|callgrind] [--size WxH] [--json-out FILE [--overwrite]]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import bench_outputs

SCENES = ["sponza", "sibenik", "bunny", "teapot"]
CONFIGS = [("kd", "rec"), ("kd", "branched"), ("kd", "branchless"), ("bih", "branched"), ("bih", "branchless")]


def profile(args, view, accel, traversal, json_path):
    cmd = [args.cellrt, "profile", view, "--accel", accel, "--traversal", traversal, "--method", args.method,
           "--json", json_path, "--overwrite"]
    if args.size:
        cmd += ["--size", args.size]
    done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        sys.exit(f"profile_table: {' '.join(cmd)} failed:\n{done.stdout}{done.stderr}")
    with open(json_path, encoding="utf-8") as f:
        return json.load(f)


def num(v, digits):
    return "n/a" if v is None else f"{v:,.{digits}f}"


def ratio(a, b):
    return "n/a" if a is None or b is None or b == 0 else f"{a / b:.2f}"


def rate(region):
    return 100.0 * region["mispredictions"] / region["branches"] if region["branches"] else 0.0


def traversal_table(rows):
    out = ["| scene | structure | traversal | nodes | leaves | triangles | instructions | branches | "
           "mispredictions | mispredicted | cycles | CPI |",
           "|---|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|"]
    for r in rows:
        t, w, n = r["regions"]["traversal"], r["work"]["per_ray"], r["rays"]["all"]
        out.append(f'| {r["scene"]} | {r["accel"]} | {r["traversal"]} | {w["nodes"]:.2f} | {w["leaves"]:.2f} | '
                   f'{w["triangles"]:.2f} | {t["per_ray"]["instructions"]:,.0f} | {t["branches"] / n:,.1f} | '
                   f'{t["per_ray"]["mispredictions"]:.2f} | {rate(t):.1f} % | {num(t["per_ray"]["cycles"], 0)} | '
                   f'{num(t["cpi"], 2)} |')
    return out


def render_table(rows):
    out = ["| scene | structure | traversal | instructions | mispredictions | cycles | CPI | traversal share "
           "of instructions | native render CPU time (ms) | native ns per 1000 instructions |",
           "|---|---|---|--:|--:|--:|--:|--:|--:|--:|"]
    for r in rows:
        w, t = r["regions"]["render"], r["regions"]["traversal"]
        ns = 1e12 * r["native_render_cpu_seconds"] / w["instructions"]
        out.append(f'| {r["scene"]} | {r["accel"]} | {r["traversal"]} | {w["per_ray"]["instructions"]:,.0f} | '
                   f'{w["per_ray"]["mispredictions"]:.2f} | {num(w["per_ray"]["cycles"], 0)} | {num(w["cpi"], 2)} | '
                   f'{100.0 * t["instructions"] / w["instructions"]:.0f} % | '
                   f'{1e3 * r["native_render_cpu_seconds"]:.1f} | {ns:,.0f} |')
    return out


def branchless_table(rows):
    by = {(r["scene"], r["accel"], r["traversal"]): r for r in rows}
    out = ["| scene | structure | instructions | mispredictions | cycles | native render CPU time |",
           "|---|---|--:|--:|--:|--:|"]
    for scene in SCENES:
        for accel in ("kd", "bih"):
            a, b = by.get((scene, accel, "branchless")), by.get((scene, accel, "branched"))
            if not a or not b:
                continue
            ta, tb = a["regions"]["traversal"], b["regions"]["traversal"]
            out.append(f'| {scene} | {accel} | {ratio(ta["instructions"], tb["instructions"])} | '
                       f'{ratio(ta["mispredictions"], tb["mispredictions"])} | {ratio(ta["cycles"], tb["cycles"])} | '
                       f'{ratio(a["native_render_cpu_seconds"], b["native_render_cpu_seconds"])} |')
    return out


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cellrt", default=os.path.join(here, "..", "build", "cellrt"))
    p.add_argument("--scenes", default=os.path.join(here, "..", "..", "shared", "scenes"))
    p.add_argument("--method", default="auto", choices=["auto", "hardware", "callgrind"])
    p.add_argument("--size", help="image size WxH (default: cellrt profile's)")
    p.add_argument("--json-out", help="also write every profile's JSON, as one list, to this file")
    p.add_argument("--overwrite", action="store_true", help="replace the --json-out file if it exists")
    args = p.parse_args()
    if args.json_out:
        bench_outputs.check_output(p, "--json-out", args.json_out, args.overwrite)

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for scene in SCENES:
            view = os.path.join(args.scenes, scene, scene + ".json")
            if not os.path.exists(view):
                sys.exit(f"profile_table: {view} not found (pass --scenes)")
            for accel, traversal in CONFIGS:
                print(f"profile_table: {scene} {accel} {traversal}", file=sys.stderr, flush=True)
                rows.append(profile(args, view, accel, traversal, os.path.join(tmp, "p.json")))
    if args.json_out:
        with open(args.json_out, "w", encoding="utf-8") as f:
            json.dump(rows, f, indent=1)
    r0 = rows[0]
    print(f'Method: {r0["method"]}; {r0["width"]}x{r0["height"]} pixels, packet {r0["packet"]}, one render thread.\n')
    print("Traversal alone (the accelerator's intersect/occluded calls), per ray:\n")
    print("\n".join(traversal_table(rows)))
    print("\nWhole render, per ray:\n")
    print("\n".join(render_table(rows)))
    print("\nBranchless / branched, traversal alone (native time: whole render):\n")
    print("\n".join(branchless_table(rows)))


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "profile_table"))
