"""Python wall time of trilux against the libraries Python users sample
and tetrahedralize meshes with, arrays in memory, medians of repeats;
Markdown tables on stdout (run it through run.sh, which sets up the venv).

    TRILUX_DATA=../shared/data python python/bench/bench.py [--repeats 5] [--quick]

A peer that is not installed is skipped with a line saying so."""

import argparse
import importlib
import os
import pathlib
import re
import statistics
import sys
import time

import numpy as np

import trilux


def peer(name):
    try:
        return importlib.import_module(name)
    except Exception as e:  # not installed, or broken on this machine
        print(f"> {name} is not available ({type(e).__name__}: {e}); its rows are skipped.\n")
        return None


# fTetWild's default edge length (0.05 of the diagonal) took over 70 s a
# call here, and 0.1 once 1747 s on the open bunny: one call, in a child
# process stopped after PYTETWILD_LIMIT seconds, so the table always ends.
PYTETWILD_LIMIT = 300
PYTETWILD_CALL = """
import sys, time, numpy as np, trimesh, pytetwild
m = trimesh.load(sys.argv[1], process=False)
start = time.perf_counter()
_, tets = pytetwild.tetrahedralize(np.asarray(m.vertices), np.asarray(m.faces), edge_length_fac=0.1)
print(len(tets), time.perf_counter() - start)
"""


def pytetwild_row(mesh_path):
    import subprocess

    name = "pytetwild (edge_length_fac 0.1, one call)"
    try:
        done = subprocess.run([sys.executable, "-c", PYTETWILD_CALL, str(mesh_path)],
                              capture_output=True, text=True, timeout=PYTETWILD_LIMIT)
    except subprocess.TimeoutExpired:
        return [name, "not finished", f"> {PYTETWILD_LIMIT}", "—"]
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["no message"])[-1]
        return [name, f"failed: {last[:60]}", "—", "—"]
    count, seconds = done.stdout.split()[-2:]
    return [name, count, f"{float(seconds):.3f}", "—"]


def median_seconds(call, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def cell(value):
    """A table cell: a peer's error text may hold `|` (which would end the
    cell) or newlines (which would end the table), so `|` is escaped and
    each run of line breaks becomes one space."""
    return re.sub(r"\s*[\r\n]+\s*", " ", str(value).replace("|", "\\|")).strip()


def row(cells):
    print("| " + " | ".join(cell(c) for c in cells) + " |")


def nearest_rho(points, area):
    """Relative radius ρ = min nearest-neighbour distance / (2 r_max),
    r_max = sqrt(A / (2 sqrt(3) N)) (Yuksel 2015, Eq. 4)."""
    from scipy.spatial import cKDTree  # noqa: F401  (optional; numpy fallback below)

    tree = cKDTree(points)
    d, _ = tree.query(points, k=2)
    r_max = np.sqrt(area / (2 * np.sqrt(3) * len(points)))
    return d[:, 1].min() / (2 * r_max)


def rho(points, area):
    try:
        return nearest_rho(points, area)
    except ImportError:
        # Grid hashing in numpy: exact nearest neighbours within a cell radius.
        r_max = np.sqrt(area / (2 * np.sqrt(3) * len(points)))
        best = np.inf
        for i in range(0, len(points), 200):
            block = points[i : i + 200]
            d = np.linalg.norm(block[:, None, :] - points[None, :, :], axis=2)
            d[np.arange(len(block)), np.arange(i, i + len(block))] = np.inf
            best = min(best, d.min())
        return best / (2 * r_max)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="10^5 / 10^6 points, one repeat (a smoke run)")
    args = parser.parse_args()
    data = pathlib.Path(os.environ.get("TRILUX_DATA", "../shared/data"))
    repeats = 1 if args.quick else args.repeats
    counts = [10**5, 10**6] if args.quick else [10**6, 10**7]
    blue_n = 10**4 if args.quick else 10**5

    import trimesh

    o3d = peer("open3d")
    pcu = peer("point_cloud_utils")
    pytetwild = peer("pytetwild")
    pymeshlab = peer("pymeshlab")
    tetgen = peer("tetgen")

    bunny = trimesh.load(data / "meshes" / "stanford-bunny.obj", process=False)
    v, f = np.asarray(bunny.vertices), np.asarray(bunny.faces)
    mesh = trilux.Mesh(v, f)
    area = bunny.area
    print(f"Bunny: {len(f)} triangles; medians of {repeats}; load average {os.getloadavg()[0]:.2f}; "
          f"{os.cpu_count()} cores.\n")

    print("### Uniform points on the bunny (Python wall time, s)\n")
    row(["points", "trilux.sample_surface", "trimesh.sample.sample_surface", "Open3D sample_points_uniformly",
         "pcu.sample_mesh_random", "vs trimesh", "vs pcu"])
    row(["---"] * 7)
    if o3d is not None:
        o3d_mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(v), o3d.utility.Vector3iVector(f))
    for n in counts:
        t = median_seconds(lambda: trilux.sample_surface(mesh, n, seed=1), repeats)
        tm = median_seconds(lambda: trimesh.sample.sample_surface(bunny, n, seed=1), repeats)
        to = median_seconds(lambda: o3d_mesh.sample_points_uniformly(n), repeats) if o3d else None
        tp = median_seconds(lambda: pcu.sample_mesh_random(v, f, n), repeats) if pcu else None
        fmt = lambda x: "skipped" if x is None else f"{x:.3f}"  # noqa: E731
        row([f"{n:.0e}", fmt(t), fmt(tm), fmt(to), fmt(tp), f"{tm / t:.1f}×", "—" if tp is None else f"{tp / t:.1f}×"])
    print()

    spot = trilux.load(data / "meshes" / "spot.obj")
    texture = trimesh.load(data / "meshes" / "spot.obj", process=False)
    from PIL import Image

    image = np.asarray(Image.open(data / "textures" / "spot_texture.png").convert("L"), dtype=np.float64) / 255
    n = counts[0]
    print(f"### With a density ({n:.0e} points on the textured cow, s)\n")
    t = median_seconds(lambda: trilux.sample_surface(spot, n, density=image, seed=1), repeats)
    te = median_seconds(lambda: trilux.sample_surface(spot, n, density=image, method="exact", seed=1), repeats)

    def trimesh_route():
        # The trimesh user's way: density at each face's UV centroid × area as face weights.
        uv = np.asarray(texture.visual.uv)[texture.faces].mean(axis=1)
        h, w = image.shape
        x = np.clip((uv[:, 0] * w).astype(int), 0, w - 1)
        y = np.clip(((1 - uv[:, 1]) * h).astype(int), 0, h - 1)
        weight = image[y, x] * texture.area_faces
        return trimesh.sample.sample_surface(texture, n, face_weight=weight, seed=1)

    tt = median_seconds(trimesh_route, repeats)
    row(["method", "seconds", "vs trimesh face weights"])
    row(["---"] * 3)
    row(["trilux subdivision (Šik & Křivánek)", f"{t:.3f}", f"{tt / t:.1f}×"])
    row(["trilux exact", f"{te:.3f}", f"{tt / te:.1f}×"])
    row(["trimesh face weights (density at face centroids: per-face constant)", f"{tt:.3f}", "1.0×"])
    print()

    print(f"### Blue noise, {blue_n} points on the bunny (s; ρ = min distance / (2 r_max), higher is better)\n")
    row(["library", "seconds", "ρ"])
    row(["---"] * 3)
    # The default (dense) packing answers #28's bar against pcu (and #29's
    # against MeshLab); elimination alone is Open3D's algorithm.
    t = median_seconds(lambda: trilux.blue_noise(mesh, blue_n, seed=1), repeats)
    p, _ = trilux.blue_noise(mesh, blue_n, seed=1)
    row(["trilux.blue_noise (default: packing='dense')", f"{t:.3f}", f"{rho(p, area):.3f}"])
    t = median_seconds(lambda: trilux.blue_noise(mesh, blue_n, seed=1, packing="elimination"), repeats)
    p, _ = trilux.blue_noise(mesh, blue_n, seed=1, packing="elimination")
    row(["trilux.blue_noise(packing='elimination')", f"{t:.3f}", f"{rho(p, area):.3f}"])
    if pymeshlab is not None:
        def meshlab():
            ms = pymeshlab.MeshSet()
            ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_matrix=f.astype(np.int32)))
            start = time.perf_counter()
            ms.generate_sampling_poisson_disk(samplenum=blue_n)
            return time.perf_counter() - start, ms.current_mesh().vertex_matrix()

        try:
            runs = [meshlab() for _ in range(repeats)]
            t = statistics.median(r[0] for r in runs)
            q = runs[-1][1]
            row([f"pymeshlab generate_sampling_poisson_disk ({len(q)} points)", f"{t:.3f}", f"{rho(q, area):.3f}"])
        except Exception as e:
            row(["pymeshlab generate_sampling_poisson_disk", f"failed: {type(e).__name__}: {e}", "—"])
    else:
        row(["pymeshlab generate_sampling_poisson_disk", "skipped", "—"])
    if pcu is not None:
        t = median_seconds(lambda: pcu.sample_mesh_poisson_disk(v, f, blue_n), repeats)
        fid, bc = pcu.sample_mesh_poisson_disk(v, f, blue_n)
        q = pcu.interpolate_barycentric_coords(f, fid, bc, v)
        row([f"pcu.sample_mesh_poisson_disk ({len(q)} points)", f"{t:.3f}", f"{rho(q, area):.3f}"])
    else:
        row(["pcu.sample_mesh_poisson_disk", "skipped", "—"])
    if o3d is not None:
        t = median_seconds(lambda: o3d_mesh.sample_points_poisson_disk(blue_n), repeats)
        q = np.asarray(o3d_mesh.sample_points_poisson_disk(blue_n).points)
        row(["Open3D sample_points_poisson_disk", f"{t:.3f}", f"{rho(q, area):.3f}"])
    else:
        row(["Open3D sample_points_poisson_disk", "skipped", "—"])
    print()

    print("### Tetrahedra of the bunny (s)\n")
    row(["library", "tetrahedra", "seconds", "dihedral range (°)"])
    row(["---"] * 4)
    t = median_seconds(lambda: trilux.tetrahedralize(mesh), repeats)
    nodes, tets, report = trilux.tetrahedralize(mesh, return_report=True)
    row(["trilux.tetrahedralize (default spacing)", len(tets), f"{t:.3f}",
         f"{report['min_dihedral_deg']:.1f} .. {report['max_dihedral_deg']:.1f}"])
    if pytetwild is not None:
        row(pytetwild_row(data / "meshes" / "stanford-bunny.obj"))
    else:
        row(["pytetwild", "skipped", "—", "—"])
    if tetgen is not None:
        try:
            # The bunny is open (5 holes): TetGen needs a closed surface, so
            # it gets the boundary of trilux's tetrahedra (same volume).
            surf = np.sort(np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 3, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 1]]]), axis=1)
            uniq, counts_ = np.unique(surf, axis=0, return_counts=True)
            boundary = uniq[counts_ == 1]
            volume = np.mean(np.abs(np.einsum("ij,ij->i", np.cross(nodes[tets[:, 1]] - nodes[tets[:, 0]], nodes[tets[:, 2]] - nodes[tets[:, 0]]), nodes[tets[:, 3]] - nodes[tets[:, 0]]) / 6))

            def run_tetgen():
                return tetgen.TetGen(nodes, boundary).tetrahedralize(order=1, mindihedral=10, minratio=1.5, maxvolume=volume)

            t = median_seconds(run_tetgen, repeats)
            out = run_tetgen()
            row(["tetgen (trilux's boundary, same mean volume)", len(out[1]), f"{t:.3f}", "—"])
        except Exception as e:
            row(["tetgen", f"failed: {type(e).__name__}: {e}", "—", "—"])
    else:
        row(["tetgen", "skipped", "—", "—"])


if __name__ == "__main__":
    sys.exit(main())
