#!/usr/bin/env python3
"""Issue 18's figures from run.sh's files: per ray kind and scene, each config's time (primary +
shadow seconds; the configs the files hold) over Embree's fastest (the least of its configurations in the file: single rays, packets of 8 and of 16) in the same
run, as speed ratios (Embree's time / config's time); the median of the runs, and their range."""
import json, glob, statistics, sys
kinds = ['frame', 'ao', 'diffuse', 'random']
# The configs of the first run, in its order, but Embree's (the ones divided by).
first = json.load(open(sorted(glob.glob('state_frame_*.json'))[0]))
configs = list(dict.fromkeys(r['config'] for r in first if not r['config'].startswith('embree')))
print('| rays | scene | ' + ' | '.join(f'`{c}`' for c in configs) + ' | kd:rec primary ÷ rtcIntersect1 |')
print('|---|---|' + '--:|' * (len(configs) + 1))
for kind in kinds:
    runs = [json.load(open(f)) for f in sorted(glob.glob(f'state_{kind}_*.json'))]
    scenes = []
    for r in runs[0]:
        if r['scene'] not in scenes: scenes.append(r['scene'])
    for sc in scenes:
        cells = {c: [] for c in configs}
        single = []
        for run in runs:
            d = {r['config']: r for r in run if r['scene'] == sc}
            t = lambda c: d[c]['primary_seconds'] + d[c]['shadow_seconds']
            emb = min(t(e) for e in d if e.startswith('embree'))
            for c in configs: cells[c].append(emb / t(c))
            single.append(d['embree:single']['primary_seconds'] / d['kd:rec']['primary_seconds'])
        fmt = lambda v: f'{statistics.median(v):.2f} ({min(v):.2f}–{max(v):.2f})'
        print(f'| {kind} | {sc} | ' + ' | '.join(fmt(cells[c]) for c in configs) + f' | {fmt(single)} |')
