"""kd:branched's camera rays over rtcIntersect1 in the state runs (the summary's last column is kd:rec's)."""
import json, statistics as st, sys
D = sys.argv[1] if len(sys.argv) > 1 else "."
for k in ["frame", "ao", "diffuse", "random"]:
    acc = {}
    for r in (1, 2):
        rows = json.load(open(f"{D}/state_{k}_{r}.json"))
        by = {(x["scene"], x["config"]): x for x in rows}
        for (sc, cf), x in by.items():
            if cf == "kd:branched":
                acc.setdefault(sc, []).append(by[(sc, "embree:single")]["primary_seconds"] / x["primary_seconds"])
    print(k, " ".join(f"{s} {st.median(v):.2f} ({min(v):.2f}-{max(v):.2f})" for s, v in acc.items()))
