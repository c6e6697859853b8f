"""Python peers of the mesh-sampling benchmark.

    python peers.py MESH.obj N REPEATS    (normally through peers.sh, which
                                           sets up the venv first)

Times trimesh.sample.sample_surface and Open3D's
TriangleMesh.sample_points_uniformly at N points on MESH: one warm-up call
at a small N, then REPEATS calls at N, each timed with time.perf_counter
around the sampling call only (loading is not timed). Prints one JSON
object per peer and line on stdout, nothing else:

  {"peer": "trimesh", "version": ..., "n": N, "faces": ..., "median_s": ...,
   "msamples_per_s": N / median_s / 1e6, "times_s": [...], "threads": 1,
   "cpu_per_wall": ...}

or {"peer": ..., "error": "..."} when a peer cannot be imported or fails.

Threads: both peers sample on one thread. trimesh's sample_surface is numpy
(cumsum, random, searchsorted, elementwise arithmetic: none of it
multithreaded); Open3D's SamplePointsUniformly is a serial C++ loop (no
OpenMP). "cpu_per_wall" (process CPU time / wall time over the timed calls,
all threads included) measures it: ~1.0 means one busy thread.

The two differ in what they draw: trimesh picks each point's triangle by a
binary search in the area CDF (i.i.d. points); Open3D walks the triangles
in order and gives each round(N * cumulative area) - (points so far), a
stratified sample with no search.
"""

import json
import os
import statistics
import sys
import time

WARMUP_N = 10_000


def bench(peer, version, n, faces, sample, repeats):
    sample(min(n, WARMUP_N))
    times = []
    cpu0 = time.process_time()
    for _ in range(repeats):
        t0 = time.perf_counter()
        points = sample(n)
        times.append(time.perf_counter() - t0)
        del points  # freed outside the timed region
    cpu = time.process_time() - cpu0
    median = statistics.median(times)
    return {"peer": peer, "version": version, "n": n, "faces": faces,
            "median_s": median, "msamples_per_s": n / median / 1e6,
            "times_s": times, "threads": 1,
            "cpu_per_wall": round(cpu / sum(times), 2)}


def run_trimesh(path, n, repeats):
    import trimesh
    mesh = trimesh.load(path, force="mesh", process=False)
    return bench("trimesh", trimesh.__version__, n, len(mesh.faces),
                 lambda k: trimesh.sample.sample_surface(mesh, k), repeats)


def run_open3d(path, n, repeats):
    import open3d as o3d
    # Loaded by Open3D's own reader (not from trimesh's arrays), so this peer
    # works without trimesh. Positions only: the bunny OBJ has no normals or
    # colours, which Open3D would otherwise interpolate too.
    mesh = o3d.io.read_triangle_mesh(path)
    return bench("open3d", o3d.__version__, n, len(mesh.triangles),
                 mesh.sample_points_uniformly, repeats)


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: peers.py MESH.obj N REPEATS")
    path, n, repeats = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    # Only the JSON lines go to the real stdout; anything else written there,
    # Open3D's C++ log included, is sent to stderr.
    out = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    for peer, run in (("trimesh", run_trimesh), ("open3d", run_open3d)):
        try:
            result = run(path, n, repeats)
        except Exception as e:  # ImportError, OSError (libusb), load errors
            result = {"peer": peer, "error": f"{type(e).__name__}: {e}"}
        print(json.dumps(result), file=out, flush=True)


if __name__ == "__main__":
    main()
