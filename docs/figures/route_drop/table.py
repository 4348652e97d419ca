#!/usr/bin/env python3
"""run.sh's files: per scene, kind and batch, a fresh accelerator's first call over its second (median
of each run's rounds; both runs of each build), and the new build's first and second calls over the old's."""
import glob
import json
import statistics

cells = {}
for f in sorted(glob.glob('first_call_*.json')):
    who = 'old' if '_old_' in f else 'new'
    for r in json.load(open(f)):
        cells.setdefault((r['scene'], r['kind'], r['rays']), {}).setdefault(who, []).append(r)
print('| scene | kind | rays | first ÷ second, old | new | first call new ÷ old | second call new ÷ old |')
print('|---|---|---|---|---|--:|--:|')
for (scene, kind, rays), v in cells.items():
    ratio = lambda side: ', '.join(f"{x['first_over_second']:.3f}" for x in v[side])
    med = lambda side, key: statistics.median(x[key] for x in v[side])
    print(f"| {scene} | {kind} | {rays} | {ratio('old')} | {ratio('new')} | "
          f"{med('new', 'first_s') / med('old', 'first_s'):.3f} | {med('new', 'second_s') / med('old', 'second_s'):.3f} |")
