#!/usr/bin/env python3
"""The kd-tree's TA_rec two rays at a time, tried and not kept (docs/INCOHERENT.md, "Eleventh round"):
files KIND_ROUND_V.json from one binary, V = 0 one ray at a time, 1 two (an environment switch of
that experiment's binary, not in the repository); kd:rec over embree:single in the same run, medians
of the two rounds, and two ÷ one."""
import collections
import glob
import json
import os
import statistics

acc = collections.defaultdict(list)
for f in glob.glob(os.path.join(os.path.dirname(__file__) or '.', '*_[12]_[01].json')):
    kind, _, v = os.path.basename(f)[:-5].split('_')
    by = collections.defaultdict(dict)
    for x in json.load(open(f)):
        by[x['scene']][x['config']] = x
    for scene, c in by.items():
        for k in ('primary', 'shadow'):
            acc[(kind, scene, k, v)].append(c['embree:single'][k + '_seconds'] / c['kd:rec'][k + '_seconds'])
print('| rays | scene | kind | one ÷ rtcIntersect1/Occluded1 | two ÷ the same | two ÷ one |')
print('|---|---|---|--:|--:|--:|')
for key in sorted({k[:3] for k in acc}):
    a, b = statistics.median(acc[key + ('0',)]), statistics.median(acc[key + ('1',)])
    print(f'| {key[0]} | {key[1]} | {"first" if key[2] == "primary" else "second"} | {a:.2f} | {b:.2f} | {b / a:.2f} |')
