#!/usr/bin/env python3
"""run.sh's files: per configuration the median of render_seconds (rank 0's frame) over the rounds,
its ratio to the plain program's on 2 threads, rank 1's busy share of its frame, and the whole
command's wall time (wall.txt), all medians."""
import glob
import json
import os
import statistics as st
import sys

here = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
def runs(prefix):
    return [json.load(open(f)) for f in sorted(glob.glob(os.path.join(here, prefix + '.r*.json')))]
wall = {}
for line in open(os.path.join(here, 'wall.txt')):
    name, _, seconds = line.split()
    wall.setdefault(name, []).append(float(seconds))
plain = st.median(j['render_seconds'] for j in runs('plain'))
print(f'plain cellrt, 2 threads: {plain * 1e3:.1f} ms (median of {len(runs("plain"))}), command {st.median(wall["plain"]):.2f} s')
print('| transport | pixels | render ms, median (min-max) | ÷ plain | rank 1 busy share | command s |')
print('|---|---|---|--:|--:|--:|')
for copy in ('cma', 'none'):
    for v, pixels in (('old', 'float (c0bff76)'), ('new', '8-bit')):
        js = runs(f'{v}.{copy}')
        t = [j['render_seconds'] for j in js]
        busy = st.median(j['ranks'][1]['busy_seconds'] / j['ranks'][1]['seconds'] for j in js)
        name = 'single copy (default)' if copy == 'cma' else 'no single copy'
        print(f'| {name} | {pixels} | {st.median(t) * 1e3:.1f} ({min(t) * 1e3:.1f}-{max(t) * 1e3:.1f}) | '
              f'{st.median(t) / plain:.3f} | {busy:.2f} | {st.median(wall[f"{v}.{copy}"]):.2f} |')
