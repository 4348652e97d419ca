#!/usr/bin/env python3
# Random rays by query: closest hits (primary) and any hits (shadow) apart, each cellrt path over
# Embree's fastest in the same run, median of the runs; new folder against old.
#   split.py docs/figures/any_hit_order docs/figures/incoherent_round13
import json,statistics,sys,glob
# closest (primary) and any-hit (shadow) separately: cellrt config time / Embree's fastest time, per run; median
def table(files, configs):
    runs=[json.load(open(f)) for f in files]
    out={}
    for part in ("primary","shadow"):
        for sc in ["sponza","sibenik","bunny","teapot"]:
            for c in configs:
                vals=[]
                for r in runs:
                    rows={x["config"]:x for x in r if x["scene"]==sc}
                    emb=min(rows[e][part+"_seconds"] for e in rows if e.startswith("embree"))
                    vals.append(emb/rows[c][part+"_seconds"])
                out[(part,sc,c)]=statistics.median(vals)
    return out
for label,files in [("new",sorted(glob.glob(sys.argv[1]+"/state_random_*.json"))),("old",sorted(glob.glob(sys.argv[2]+"/state_random_*.json")))]:
    t=table(files,["auto","bvh:paired"])
    for part in ("primary","shadow"):
        print(label, part, " ".join("%s %.2f/%.2f"%(sc, t[(part,sc,"auto")], t[(part,sc,"bvh:paired")]) for sc in ["sponza","sibenik","bunny","teapot"]))
