"""Open3D's and MeshLab's Poisson-disk sampling, the peers of the blue_noise
example.

    python blue_noise_peer.py MESH.obj OUT_DIR N [N ...]   (normally through
                                                           peers.sh, which sets
                                                           up the venv first)

For each N, times once, around the call only (loading is not timed):

- open3d: TriangleMesh.sample_points_poisson_disk(N) (Open3D's weighted
  sample elimination, Yuksel 2015, with its default init_factor 5);
- meshlab: pymeshlab's generate_sampling_poisson_disk(samplenum=N) with its
  defaults (Corsini et al. 2012: Poisson-disk dart throwing on a Monte Carlo
  pool of 20 N points, radius found by search, best-sample heuristic on).
  MeshLab returns a count near N, not N: the row carries its own count;
- pcu: point-cloud-utils' sample_mesh_poisson_disk(v, f, num_samples=N)
  with its defaults (VCG's Poisson-disk sampling, Corsini et al. 2012, as
  MeshLab's), positions from the returned faces and barycentrics (timed
  with the call: a user needs them; a few ms).

and writes the points as little-endian float32 x, y, z triples to
OUT_DIR/<peer>_<N>.f32 so that the Rust side measures their spacing exactly
as it measures its own. Prints one JSON object per peer, N and line on
stdout, nothing else:

  {"peer": ..., "version": ..., "n": N, "points": <count>, "ms": ...,
   "cpu_ms": ..., "file": "<file>"}

(cpu_ms is the process's CPU time over the call: cpu_ms / ms shows how many
threads the peer kept busy) or {"peer": ..., "n": N, "error": "..."}.
"""

import json
import os
import sys
import time


def timed(call):
    """(result, wall ms, process CPU ms) of call()."""
    c0, t0 = time.process_time(), time.perf_counter()
    result = call()
    ms = (time.perf_counter() - t0) * 1e3
    return result, ms, (time.process_time() - c0) * 1e3


def report(peer, version, n, out_dir, points, ms, cpu_ms):
    import numpy as np

    path = os.path.join(out_dir, f"{peer}_{n}.f32")
    np.asarray(points, dtype="<f4").tofile(path)
    print(json.dumps({"peer": peer, "version": version, "n": n, "points": len(points),
                      "ms": ms, "cpu_ms": cpu_ms, "file": path}), flush=True)


def open3d_rows(mesh_path, out_dir, counts):
    try:
        import open3d as o3d
    except Exception as e:  # reported, not raised: the Rust side goes on
        for n in counts:
            print(json.dumps({"peer": "open3d", "n": n, "error": f"import: {e}"}), flush=True)
        return
    mesh = o3d.io.read_triangle_mesh(mesh_path)
    for n in counts:
        try:
            cloud, ms, cpu_ms = timed(lambda: mesh.sample_points_poisson_disk(n))
            report("open3d", o3d.__version__, n, out_dir, cloud.points, ms, cpu_ms)
        except Exception as e:
            print(json.dumps({"peer": "open3d", "n": n, "error": str(e)}), flush=True)


def meshlab_rows(mesh_path, out_dir, counts):
    try:
        import pymeshlab
    except Exception as e:
        for n in counts:
            print(json.dumps({"peer": "meshlab", "n": n, "error": f"import: {e}"}), flush=True)
        return
    from importlib.metadata import version as package_version

    version = package_version("pymeshlab")
    for n in counts:
        try:
            ms_set = pymeshlab.MeshSet()
            ms_set.load_new_mesh(mesh_path)
            _, ms, cpu_ms = timed(lambda: ms_set.generate_sampling_poisson_disk(samplenum=n))
            # The filter adds the samples as a new layer and makes it current.
            points = ms_set.current_mesh().vertex_matrix()
            report("meshlab", version, n, out_dir, points, ms, cpu_ms)
        except Exception as e:
            print(json.dumps({"peer": "meshlab", "n": n, "error": str(e)}), flush=True)


def pcu_rows(mesh_path, out_dir, counts):
    try:
        import point_cloud_utils as pcu
    except Exception as e:
        for n in counts:
            print(json.dumps({"peer": "pcu", "n": n, "error": f"import: {e}"}), flush=True)
        return
    from importlib.metadata import version as package_version

    version = package_version("point-cloud-utils")
    v, f = pcu.load_mesh_vf(mesh_path)
    for n in counts:
        try:
            def call():
                fid, bc = pcu.sample_mesh_poisson_disk(v, f, num_samples=n)
                return pcu.interpolate_barycentric_coords(f, fid, bc, v)

            points, ms, cpu_ms = timed(call)
            report("pcu", version, n, out_dir, points, ms, cpu_ms)
        except Exception as e:
            print(json.dumps({"peer": "pcu", "n": n, "error": str(e)}), flush=True)


def main():
    mesh_path, out_dir = sys.argv[1], sys.argv[2]
    counts = [int(a) for a in sys.argv[3:]]
    peers = os.environ.get("BLUE_NOISE_PEERS", "open3d,meshlab,pcu").split(",")
    if "open3d" in peers:
        open3d_rows(mesh_path, out_dir, counts)
    if "meshlab" in peers:
        meshlab_rows(mesh_path, out_dir, counts)
    if "pcu" in peers:
        pcu_rows(mesh_path, out_dir, counts)


if __name__ == "__main__":
    main()
