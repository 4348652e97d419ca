#!/usr/bin/env python3
"""Issue 18's figures from run.sh's files: per ray kind and scene, each config's time (primary +
shadow seconds; the configs the files hold) over Embree's fastest (the least of its configurations in the file: single rays, packets of 8 and of 16) in the same
run, as speed ratios (Embree's time / config's time); the median of the runs, and their range.
A config a run did not measure is left out of that run's figures ("–" where no run has it); the
last column, kd:rec's primary rays over rtcIntersect1's, is left out, with a note, where the runs
lack kd:rec or embree:single (CONFIGS of incoherent_state.sh)."""
import glob, statistics, sys
import bench_outputs


def main():
    kinds = ['frame', 'ao', 'diffuse', 'random']
    files = {kind: sorted(glob.glob(f'state_{kind}_*.json')) for kind in kinds}
    if not any(files.values()):
        sys.exit('incoherent_state_table.py: error: no state_KIND_RUN.json files here (run it in the folder '
                 'incoherent_state.sh wrote)')
    runs = {kind: [bench_outputs.load_json(f, rows=True) for f in fs] for kind, fs in files.items()}
    rows = [r for rs in runs.values() for run in rs for r in run]
    if not any(r['config'].startswith('embree') for r in rows):
        sys.exit('incoherent_state_table.py: error: the runs have no Embree configuration, and every figure '
                 'here is a ratio to Embree\'s fastest; add one (embree:single) to CONFIGS')
    # The configs of the first run, in its order, but Embree's (the ones divided by).
    first = next(rs[0] for rs in runs.values() if rs)
    configs = list(dict.fromkeys(r['config'] for r in first if not r['config'].startswith('embree')))
    measured = {r['config'] for r in rows}
    single = {'kd:rec', 'embree:single'} <= measured
    print('| rays | scene | ' + ' | '.join(f'`{c}`' for c in configs) +
          (' | kd:rec primary ÷ rtcIntersect1 |' if single else ' |'))
    print('|---|---|' + '--:|' * (len(configs) + single))
    fmt = lambda v: f'{statistics.median(v):.2f} ({min(v):.2f}–{max(v):.2f})' if v else '–'
    for kind in kinds:
        if not runs[kind]:
            continue
        scenes = list(dict.fromkeys(r['scene'] for r in runs[kind][0]))
        for sc in scenes:
            cells = {c: [] for c in configs}
            ratios = []
            for run in runs[kind]:
                d = {r['config']: r for r in run if r['scene'] == sc}
                t = lambda c: d[c]['primary_seconds'] + d[c]['shadow_seconds']
                embree = [t(e) for e in d if e.startswith('embree')]
                if not embree:
                    continue
                for c in configs:
                    if c in d:
                        cells[c].append(min(embree) / t(c))
                if single and 'kd:rec' in d and 'embree:single' in d:
                    ratios.append(d['embree:single']['primary_seconds'] / d['kd:rec']['primary_seconds'])
            print(f'| {kind} | {sc} | ' + ' | '.join(fmt(cells[c]) for c in configs) +
                  (f' | {fmt(ratios)} |' if single else ' |'))
    if not single:
        lacking = ' and '.join(c for c in ('kd:rec', 'embree:single') if c not in measured)
        print(f'\n(Left out: kd:rec primary ÷ rtcIntersect1, as the runs have no {lacking}.)')


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "incoherent_state_table"))
