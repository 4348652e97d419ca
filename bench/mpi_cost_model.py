#!/usr/bin/env python3
"""Frame time of cellrt-mpi on N nodes, from the cost model of docs/DISTRIBUTED.md.

The per-frame terms are fitted to bench/mpi_efficiency.sh's figures (one process, 2 ranks with 128-
and 64-pixel tiles); the network's are assumed (an InfiniBand-class fabric) and given as options.
For each N the tile edge (of 256, 128, 64, 32, 16) that gives the shortest frame is chosen.

  python3 bench/mpi_cost_model.py --frame-cpu 0.44 --tile-cpu 0.0001 [--cores 2] [--size 1920x1080]
      [--slowdown S] [--tile EDGE] [--pixel-bytes 3]
"""
import argparse
import math
import bench_outputs
import sys


def frame_time(n_nodes, a, edge):
    w, h = a.width, a.height
    tiles = math.ceil(w / edge) * math.ceil(h / edge)
    t1 = a.frame_cpu / a.cores                      # one node's frame, all its cores tracing
    t_tile = a.slowdown * t1 / tiles                 # one tile on one node, every core of it busy
    tile_bytes = a.pixel_bytes * edge * edge         # float RGB (12) or a PNG's 8-bit sRGB (3)
    # A rank asks ahead: the next tile is there unless an answer takes longer than the tiles queued.
    answer = a.poll / 2 + 2 * a.latency + tile_bytes / (a.transfer or a.bandwidth)
    starve = max(0.0, answer - (a.ahead - 1) * t_tile)
    per_rank_tiles = tiles / n_nodes
    trace = per_rank_tiles * (t_tile + a.tile_cpu + starve) + t_tile / 2  # the last tile's tail
    if per_rank_tiles < 1:                           # more nodes than tiles: one tile is the frame
        trace = t_tile + a.tile_cpu + starve
    # Rank 0's master receives every tile through one network port and copies it into the frame.
    master = tiles * a.message + a.pixel_bytes * w * h / a.bandwidth + a.pixel_bytes * w * h / a.copy
    return max(trace, master) + a.collectives * math.ceil(math.log2(max(n_nodes, 2))) * a.latency, tiles


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--frame-cpu", type=float, required=True, help="one process's frame, CPU seconds (fitted)")
    p.add_argument("--tile-cpu", type=float, required=True, help="a rank's cost per tile, seconds (fitted)")
    p.add_argument("--cores", type=int, default=2, help="cores per node")
    p.add_argument("--size", default="1920x1080")
    p.add_argument("--slowdown", type=float, default=1.0,
                   help="a tile's time with every core of the machine busy over one core's (measured)")
    p.add_argument("--tile", type=int, help="this tile edge only (default: the best of 256 to 16 for each N)")
    p.add_argument("--ahead", type=int, default=2)
    p.add_argument("--poll", type=float, default=500e-6, help="the master's poll interval, s")
    p.add_argument("--latency", type=float, default=2e-6, help="network latency, s (assumed)")
    p.add_argument("--bandwidth", type=float, default=12e9, help="network bandwidth, B/s (assumed)")
    p.add_argument("--transfer", type=float,
                   help="B/s at which one rank's tile reaches rank 0 (default: --bandwidth; on one machine the "
                        "shared-memory transport as the polls drive it, fitted)")
    p.add_argument("--copy", type=float, default=5e9, help="rank 0's memory copy into the frame, B/s (assumed)")
    p.add_argument("--message", type=float, default=5e-6, help="rank 0's handling of one tile message, s (assumed)")
    p.add_argument("--collectives", type=int, default=3, help="collectives per frame (agreement, figures)")
    p.add_argument("--pixel-bytes", type=int, default=12,
                   help="bytes a pixel travels in: 12 (float RGB, a .pfm frame) or 3 (8-bit sRGB, a .png frame)")
    p.add_argument("--scene-bytes", type=float, default=66454 * 36, help="triangles broadcast, bytes")
    a = p.parse_args()
    a.width, a.height = map(int, a.size.split("x"))
    t1 = a.frame_cpu / a.cores
    print(f"one node ({a.cores} cores): {t1 * 1e3:.1f} ms per {a.size} frame")
    print("| nodes | tile | tiles | frame ms | speed-up | efficiency | --broadcast-scene ms |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for k in range(1, 11):
        n = 2 ** k
        edges = (a.tile,) if a.tile else (256, 128, 64, 32, 16)
        best = min((frame_time(n, a, e) + (e,) for e in edges), key=lambda r: r[0])
        t, tiles, edge = best
        bcast = math.ceil(math.log2(n)) * (a.latency + a.scene_bytes / a.bandwidth)
        print(f"| {n} | {edge} | {tiles} | {t * 1e3:.2f} | {t1 / t:.1f} | {t1 / t / n:.2f} | {bcast * 1e3:.2f} |")


if __name__ == "__main__":
    sys.exit(bench_outputs.run(main, "mpi_cost_model"))
