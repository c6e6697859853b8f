"""Open3D's Poisson-disk sampling, the peer of the blue_noise example.

    python blue_noise_peer.py MESH.obj OUT_DIR N [N ...]   (normally through
                                                           peers.sh, which sets
                                                           up the venv first)

For each N, times TriangleMesh.sample_points_poisson_disk(N) (Open3D's
weighted sample elimination, Yuksel 2015, with its default init_factor 5)
once, around the call only (loading is not timed), and writes the points as
little-endian float32 x, y, z triples to OUT_DIR/open3d_<N>.f32 so that the
Rust side measures their spacing exactly as it measures its own. Prints one
JSON object per N and line on stdout, nothing else:

  {"peer": "open3d", "version": ..., "n": N, "ms": ..., "points": "<file>"}

or {"peer": "open3d", "n": N, "error": "..."}.
"""

import json
import os
import sys
import time


def main():
    mesh_path, out_dir = sys.argv[1], sys.argv[2]
    counts = [int(a) for a in sys.argv[3:]]
    try:
        import numpy as np
        import open3d as o3d
    except Exception as e:  # reported, not raised: the Rust side goes on
        for n in counts:
            print(json.dumps({"peer": "open3d", "n": n, "error": f"import: {e}"}))
        return
    mesh = o3d.io.read_triangle_mesh(mesh_path)
    for n in counts:
        try:
            t0 = time.perf_counter()
            cloud = mesh.sample_points_poisson_disk(n)
            ms = (time.perf_counter() - t0) * 1e3
            path = os.path.join(out_dir, f"open3d_{n}.f32")
            np.asarray(cloud.points, dtype="<f4").tofile(path)
            print(json.dumps({"peer": "open3d", "version": o3d.__version__, "n": n,
                              "ms": ms, "points": path}), flush=True)
        except Exception as e:
            print(json.dumps({"peer": "open3d", "n": n, "error": str(e)}), flush=True)


if __name__ == "__main__":
    main()
