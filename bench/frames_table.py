#!/usr/bin/env python3
"""frames_ab.sh's runs: per shading, scene, workers and config, the median frame seconds of the old
binary (a) and the new (b), new ÷ old, and each side's median ratio to Embree's packet8 in its runs."""
import re
import statistics
import sys

import bench_outputs


def main():
    if len(sys.argv) < 2:
        sys.exit('usage: bench/frames_table.py frames_a_*.json frames_b_*.json   (frames_ab.sh\'s files)')
    for path in sys.argv[1:]:
        if not re.search(r'frames_([ab])_', path):
            sys.exit(f'frames_table: error: {path}: not a frames_a_* or frames_b_* file of frames_ab.sh')
    cells = {}
    for path in sys.argv[1:]:
        who = re.search(r'frames_([ab])_', path).group(1)
        runs = bench_outputs.load_json(path, rows=True)
        emb = {(r['shading'], r['scene'], r['workers']): r['seconds'] for r in runs if r['config'] == 'embree:packet8'}
        for r in runs:
            key = (r['shading'], r['scene'], r['workers'], r['config'])
            c = cells.setdefault(key, {'a': [], 'b': [], 'ra': [], 'rb': []})
            c[who].append(r['seconds'])
            c['r' + who].append(emb[key[:3]] / r['seconds'])
    print('| shading | scene | workers | config | old s | new s | new ÷ old | Embree ÷ old | Embree ÷ new |')
    print('|---|---|--:|---|--:|--:|--:|--:|--:|')
    for (sh, sc, w, cfg), c in sorted(cells.items()):
        a, b = statistics.median(c['a']), statistics.median(c['b'])
        print(f"| {sh} | {sc} | {w} | {cfg} | {a:.4f} | {b:.4f} | {b / a:.3f} | "
              f"{statistics.median(c['ra']):.2f} | {statistics.median(c['rb']):.2f} |")


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "frames_table"))
