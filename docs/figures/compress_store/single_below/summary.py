#!/usr/bin/env python3
"""kPacketSingleBelow variants (any hit, closest hit) against the kept (3, 1): bvh:packet's time B/A per
ray kind, and the same divided by Embree's B/A in the same runs (the machine's drift taken out)."""
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))
print('| any, closest | rays | camera rays B/A (÷ Embree\'s) | second rays B/A (÷ Embree\'s) |\n|---|---|---|---|')
for v in ['5_1', '8_1', '3_2', '3_3']:
    for k in ['ao', 'frame', 'diffuse']:
        d = json.load(open(os.path.join(HERE, f'{v}_{k}.json')))
        by = {(r['scene'], r['config']): r for r in d['ratios']}
        cells = []
        for part in ('primary', 'shadow'):
            raw = [by[(s, 'bvh:packet')][part] for s in ('sponza', 'sibenik', 'bunny', 'teapot')]
            rel = [by[(s, 'bvh:packet')][part] / by[(s, 'embree:packet16')][part] for s in ('sponza', 'sibenik', 'bunny', 'teapot')]
            cells.append(f'{min(raw):.3f}–{max(raw):.3f} ({min(rel):.3f}–{max(rel):.3f})')
        print(f'| {v.replace("_", ", ")} | {k} | {cells[0]} | {cells[1]} |')
