#!/usr/bin/env python3
"""Builds on 1 and 2 threads, old (f743214) against new, three rounds in turn (docs/BUILD_SPEED.md):
  for r in 1 2 3; for v in old new; for t in 1 2: cellrt_bench --scenes sponza sibenik bunny teapot
  'builtin:forest?tris=1000000' --size 16x16 --repeats 1 --builds 5 --threads $t
  --configs embree kd bih@split=sah --json $v.t$t.r$r.json"""
import json
import os
import statistics
from collections import defaultdict

here = os.path.dirname(os.path.abspath(__file__))
d = defaultdict(list)
for v in ("old", "new"):
    for t in (1, 2):
        for r in (1, 2, 3):
            for x in json.load(open(os.path.join(here, f"{v}.t{t}.r{r}.json"))):
                d[(v, t, x["scene"], x["config"])].append(x["build_seconds"])
print("| structure | scene | before: 1 / 2 threads ms, speed-up | after | 2 threads after ÷ before |")
print("|---|---|---|---|---|")
for c in ("bih@split=sah", "kd", "embree"):
    for s in sorted({k[2] for k in d}):
        m = {(v, t): statistics.median(d[(v, t, s, c)]) for v in ("old", "new") for t in (1, 2)}
        cells = [f"{m[(v, 1)] * 1e3:.1f} / {m[(v, 2)] * 1e3:.1f}, {m[(v, 1)] / m[(v, 2)]:.2f}" for v in ("old", "new")]
        print(f"| {c} | {s} | {cells[0]} | {cells[1]} | {m[('new', 2)] / m[('old', 2)]:.2f} |")
