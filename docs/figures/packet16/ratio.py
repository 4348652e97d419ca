# Per scene and ray kind: each side's time over Embree's packets of sixteen in the same run (median over runs).
import json, statistics, sys
for kind in ["frame", "ao", "diffuse"]:
    d = json.load(open(f"docs/figures/packet16/time_{kind}.json"))
    vals = {}
    for run in d["runs"]:
        rows = {(r["scene"], r["config"]): r for r in run["rows"]}
        for (scene, cfg), r in rows.items():
            if cfg.startswith("embree"): continue
            e = rows[(scene, "embree:packet16")]
            for part in ["primary", "shadow", "total"]:
                t = (r["primary_seconds"] + r["shadow_seconds"]) if part == "total" else r[part + "_seconds"]
                te = (e["primary_seconds"] + e["shadow_seconds"]) if part == "total" else e[part + "_seconds"]
                vals.setdefault((scene, cfg, part), {}).setdefault(run["side"], []).append(te / t)
    print(f"\n{kind}: Embree packet16 time / cellrt time (median of runs), old -> new")
    print("| scene | config | primary | second | total |\n|---|---|--:|--:|--:|")
    for scene in ["sponza", "sibenik", "bunny", "teapot"]:
        for cfg in ["bvh:packet", "auto"]:
            cells = []
            for part in ["primary", "shadow", "total"]:
                v = vals[(scene, cfg, part)]
                cells.append(f"{statistics.median(v['a']):.2f} → {statistics.median(v['b']):.2f}")
            print(f"| {scene} | `{cfg}` | " + " | ".join(cells) + " |")
