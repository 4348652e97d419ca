#!/usr/bin/env python3
"""From ab_compare.py's files: per scene and config, its speed over Embree's fastest in the same run
(the lesser time of embree:single and embree:packet8, for each kind of ray apart: the first kind,
closest hit; the second, any hit for frame, random and ao rays, closest hit for diffuse bounces), the
median of each side's runs, and new ÷ old; then both kinds together with the range of the runs."""
import json
import statistics
import sys

KINDS = ('primary', 'shadow')
for path in sys.argv[1:]:
    d = json.load(open(path))
    acc = {}
    for run in d['runs']:
        rows = {(r['scene'], r['config']): r for r in run['rows']}
        for (scene, config), r in rows.items():
            if config.startswith('embree'):
                continue
            e1, e8 = rows[(scene, 'embree:single')], rows[(scene, 'embree:packet8')]
            ratios = [min(e1[k + '_seconds'], e8[k + '_seconds']) / r[k + '_seconds'] for k in KINDS]
            both = min(sum(e1[k + '_seconds'] for k in KINDS), sum(e8[k + '_seconds'] for k in KINDS))
            ratios.append(both / sum(r[k + '_seconds'] for k in KINDS))
            acc.setdefault((scene, config), {'a': [], 'b': []})[run['side']].append(ratios)
    print(f"{path}: --rays {d['args'][d['args'].index('--rays') + 1]}")
    print('| scene | config | first kind: old → new | second kind: old → new | both: old → new (ranges) | new ÷ old, both |')
    print('|---|---|--:|--:|--:|--:|')
    for (scene, config), v in acc.items():
        med = lambda side, i: statistics.median(x[i] for x in v[side])
        rng = lambda side: f"{min(x[2] for x in v[side]):.2f}–{max(x[2] for x in v[side]):.2f}"
        cells = [f"{med('a', i):.2f} → {med('b', i):.2f}" for i in range(2)]
        both = f"{med('a', 2):.2f} ({rng('a')}) → {med('b', 2):.2f} ({rng('b')})"
        print(f"| {scene} | `{config}` | {cells[0]} | {cells[1]} | {both} | {med('b', 2) / med('a', 2):.3f} |")
    print()
