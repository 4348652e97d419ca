#!/usr/bin/env python3
"""The tables of docs/INCOHERENT.md's twentieth round from this folder (run.sh made it):
python3 tables.py > tables.md"""
import collections, glob, json, os, statistics

HERE = os.path.dirname(os.path.abspath(__file__))
E = 'embree:packet16'
SHADINGS = ['direct', 'ao', 'diffuse']
SCENES = ['sponza', 'sibenik', 'bunny', 'teapot']


def span(v):
    return f"{statistics.median(v):.2f} ({min(v):.2f}–{max(v):.2f})" if v else '–'


def runs(pattern):
    """(shading, scene, who) -> one {config: seconds} per run; who is the file name's a, b or c."""
    out = collections.defaultdict(list)
    for f in sorted(glob.glob(os.path.join(HERE, pattern))):
        who = os.path.basename(f).split('_')[1]
        by = collections.defaultdict(dict)
        for r in json.load(open(f)):
            by[(r['shading'], r['scene'])][r['config']] = r['seconds']
        for (sh, sc), c in by.items():
            out[(sh, sc, who)].append(c)
    return out


def over_best(r):
    return r['auto'] / min(r['kd+auto'], r['bvh:packet'])


print('## bvh:packet over Embree, one structure after another (sequential/) and interleaved (kept/, both binaries)\n')
print('| shading | scene | sequential | interleaved |\n|---|---|--:|--:|')
seq, kept = runs('sequential/f_*.json'), runs('kept/f_*.json')
for sh in SHADINGS:
    for sc in SCENES:
        a = [c[E] / c['bvh:packet'] for w in 'ab' for c in seq.get((sh, sc, w), [])]
        b = [c[E] / c['bvh:packet'] for w in 'ab' for c in kept.get((sh, sc, w), [])]
        if a:
            print(f'| {sh} | {sc} | {span(a)} | {span(b)} |')

print("\n## The old route (a) against the kept one (b), kept/: speed over Embree's packets of sixteen, and "
      "auto's time over the faster of kd+auto and bvh:packet\n")
configs = ['auto', 'kd+auto', 'bvh:packet']
print('| shading | scene | ' + ' | '.join(f'{c} ÷ Embree, old → new' for c in configs) +
      ' | auto ÷ fastest other, old → new |\n|---|---|' + '--:|' * 4)
for sh in SHADINGS:
    for sc in SCENES:
        a, b = kept[(sh, sc, 'a')], kept[(sh, sc, 'b')]
        cells = [f'{span([r[E] / r[c] for r in a])} → {span([r[E] / r[c] for r in b])}' for c in configs]
        cells.append(f'{span([over_best(r) for r in a])} → {span([over_best(r) for r in b])}')
        print(f'| {sh} | {sc} | ' + ' | '.join(cells) + ' |')

print("\n## auto's time over the faster of kd+auto and bvh:packet, route by route (each folder's own runs)\n")
variants = [('old', 'kept/f_a_*.json'), ('cover 2 %, every 4th run', 'interleaved_02/f_b_*.json'),
            ('cover 5 %, backing off', 'cover_mix/f_b_*.json'), ('+ tree affinity', 'affinity/f_c_*.json'),
            ('pairs', 'pairs/f_b_*.json'), ('kept', 'kept/f_b_*.json')]
data = [(name, runs(p)) for name, p in variants]
print('| shading | scene | ' + ' | '.join(n for n, _ in data) + ' |\n|---|---|' + '--:|' * len(data))
for sh in SHADINGS:
    for sc in SCENES:
        cells = [span([over_best(r) for w in 'abc' for r in d.get((sh, sc, w), [])]) for _, d in data]
        print(f'| {sh} | {sc} | ' + ' | '.join(cells) + ' |')

print('\n## One frame per process (`cellrt render`, 384 x 384, one thread, the route learning within it): '
      'render time in ms, old (a) → new (b), mean of 12 renders each (printed to the millisecond)\n')
files = [('cover 5 %, backing off', 'cover_mix.txt'), ('pairs', 'pairs.txt'), ('kept', 'kept.txt')]
print('| scene | accel | ' + ' | '.join(n for n, _ in files) + ' |\n|---|---|' + '--:|' * len(files))
times = []
for _, name in files:
    t = collections.defaultdict(list)
    for line in open(os.path.join(HERE, 'first_frame', name)):
        p = line.split()
        if len(p) >= 5:
            t[(p[1], p[2], p[0])].append(1e3 * float(p[4]))
    times.append(t)
for sc in SCENES:
    for acc in ['auto', 'kd', 'bvh:packet']:
        cells = [f"{statistics.mean(t[(sc, acc, 'a')]):.2f} → {statistics.mean(t[(sc, acc, 'b')]):.2f}" for t in times]
        print(f'| {sc} | {acc} | ' + ' | '.join(cells) + ' |')

print("\n## Whole frames with one and two workers (two_workers/): Embree's fastest of its single rays and "
      "packets of eight and sixteen over auto's frame time\n")
print('| shading | workers | ' + ' | '.join(SCENES) + ' |\n|---|--:|' + '--:|' * len(SCENES))
for sh in ['ao', 'diffuse']:
    pts = json.load(open(os.path.join(HERE, 'two_workers', f'scaling_{sh}.json')))
    for w in (1, 2):
        cells = []
        for sc in SCENES:
            t = {p['config']: p['seconds'] for p in pts if p['scene'] == sc and p['workers'] == w}
            embree = min(v for k, v in t.items() if k.startswith('embree'))
            cells.append(f"{embree / t['auto']:.2f}")
        print(f'| {sh} | {w} | ' + ' | '.join(cells) + ' |')
