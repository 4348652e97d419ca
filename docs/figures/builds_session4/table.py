import json,statistics,sys
configs=['kd:branched','bvh']
scenes=[]
for x in json.load(open('builds_old_1.json')):
    if x['scene'] not in scenes: scenes.append(x['scene'])
for c in configs:
    print(f'\n{c}\n| scene | build ms before → after | ÷ Embree before → after | per round before → after | SAH cost |')
    print('|---|---|---|---|---|')
    for sc in scenes:
        out=[]
        for v in ['old','new']:
            ms=[];rat=[]
            for r in [1,2,3]:
                d={x['config']:x for x in json.load(open(f'builds_{v}_{r}.json')) if x['scene']==sc}
                ms.append(d[c]['build_seconds']*1e3); rat.append(d[c]['build_seconds']/d['embree:single']['build_seconds']); sah=d[c]['sah_cost']
            out.append((statistics.median(ms),[f'{x:.2f}' for x in rat],statistics.median(rat),sah))
        print(f"| {sc} | {out[0][0]:.1f} → {out[1][0]:.1f} | {out[0][2]:.2f} → {out[1][2]:.2f} | {', '.join(out[0][1])} → {', '.join(out[1][1])} | {out[0][3]:.2f} → {out[1][3]:.2f} |")
