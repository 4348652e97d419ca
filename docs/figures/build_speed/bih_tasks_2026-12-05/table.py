#!/usr/bin/env python3
"""The SAH BIH's build on 1 and 2 threads, main (base: 227f705, tasks from 4096 triangles, kParallelMin) against tasks from
1024 triangles (pm1024, not kept), five rounds in turn (docs/BUILD_SPEED.md, 2026-12-05):
  for r in 1..5; for v in base pm1024; for t in 1 2: cellrt_bench --scenes sponza sibenik bunny teapot
  'builtin:forest?tris=1000000' --size 16x16 --repeats 1 --builds 5 --threads $t
  --configs embree bih@split=sah --json $v.t$t.r$r.json
Medians of each side's builds."""
import collections
import glob
import json
import os
import statistics as st
import sys
here=sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
d=collections.defaultdict(list)
for f in glob.glob(os.path.join(here,'*.json')):
    v,t,r=os.path.basename(f)[:-5].split('.')
    for x in json.load(open(f)): d[(v,int(t[1:]),x['scene'],x['config'])].append(x['build_seconds'])
print('| structure | scene | before: 1 / 2 threads ms, speed-up | after | 2 threads, after ÷ before |')
print('|---|---|---|---|--:|')
for c in ('bih@split=sah','embree'):
  for s in ('sponza','sibenik','bunny','teapot','forest'):
    m={(v,t):st.median(d[(v,t,s,c)]) for v in ('base','pm1024') for t in (1,2)}
    cells=[f"{m[(v,1)]*1e3:.1f} / {m[(v,2)]*1e3:.1f}, {m[(v,1)]/m[(v,2)]:.2f}" for v in ('base','pm1024')]
    print(f"| {c} | {s} | {cells[0]} | {cells[1]} | {m[('pm1024',2)]/m[('base',2)]:.3f} |")
