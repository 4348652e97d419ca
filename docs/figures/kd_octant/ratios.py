import json, sys, statistics as st
d = json.load(open(sys.argv[1]))
side = sys.argv[2] if len(sys.argv) > 2 else None
acc = {}
for run in d['runs']:
    if side and run['side'] != side: continue
    rows = {(r['scene'], r['config']): r for r in run['rows']}
    for (sc, cf), r in rows.items():
        e = rows.get((sc, 'embree:single'))
        if not e or cf == 'embree:single': continue
        acc.setdefault((sc, cf), []).append((e['primary_seconds'] / r['primary_seconds'], e['shadow_seconds'] / r['shadow_seconds']))
for k, v in sorted(acc.items()):
    print(k[0], k[1], 'primary %.3f' % st.median(x[0] for x in v), 'any %.3f' % st.median(x[1] for x in v), len(v))
