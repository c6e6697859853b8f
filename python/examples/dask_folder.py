"""Many assets on Dask: sample N points (with normals) on every mesh in a
folder, and bake mesh colours for the textured ones, on any Dask cluster.

    python examples/dask_folder.py MESHES/ OUT/ -n 1000000             # a LocalCluster
    python examples/dask_folder.py MESHES/ OUT/ --scheduler tcp://host:8786   # your cluster
    python examples/dask_folder.py MESHES/ OUT/ --serial               # no Dask

Each mesh gives OUT/<name>.npz (points float64 (N, 3), normals, face_index
int64) and OUT/<name>.ply; a mesh with UVs and a texture also
OUT/<name>_atlas.npz (the baked atlas and its mesh). The seed of a mesh is
derived from its name, so the results do not depend on the order, on the
number of workers or on whether Dask runs them: `process` is a pure
function of (path, N, seed). Workers need `trilux` installed (the same
wheel); each call releases the GIL, so threads of one worker run in
parallel too.
"""

import argparse
import pathlib
import zlib

import numpy as np

import trilux

EXTENSIONS = {".obj", ".ply", ".gltf", ".glb"}


def seed_of(path, base_seed=0):
    """A seed per mesh from its file name (stable across runs and machines)."""
    return (base_seed << 32) ^ zlib.crc32(pathlib.Path(path).name.encode())


def process(path, out_dir, n, base_seed=0):
    """Samples `n` points with normals on the mesh at `path` and writes
    them; bakes mesh colours when the mesh has a texture. Returns the
    arrays written (a dict of numpy arrays)."""
    path, out_dir = pathlib.Path(path), pathlib.Path(out_dir)
    mesh = trilux.load(path)
    points, faces, normals = trilux.sample_surface(mesh, n, seed=seed_of(path, base_seed), return_normal=True)
    result = {"points": points, "normals": normals, "face_index": faces}
    np.savez(out_dir / f"{path.stem}.npz", **result)
    trilux.save_points(out_dir / f"{path.stem}.ply", points, normals=normals, face_index=faces)
    textured = mesh.uv is not None and any(m["texture"] is not None or m["texture_path"] for m in mesh.materials)
    if textured:
        baked, atlas = trilux.MeshColors.from_texture(mesh).bake()
        result.update(atlas=atlas, atlas_vertices=baked.vertices, atlas_faces=baked.faces, atlas_uv=baked.uv)
        np.savez(out_dir / f"{path.stem}_atlas.npz", atlas=atlas, vertices=baked.vertices,
                 faces=baked.faces, uv=baked.uv)
    return result


def meshes(folder):
    return sorted(p for p in pathlib.Path(folder).iterdir() if p.suffix.lower() in EXTENSIONS)


def run_serial(folder, out_dir, n, base_seed=0):
    """The plain loop: {file name: arrays}."""
    return {p.name: process(p, out_dir, n, base_seed) for p in meshes(folder)}


def run_dask(folder, out_dir, n, client, base_seed=0):
    """The same on a Dask cluster (one task per mesh): {file name: arrays}."""
    paths = meshes(folder)
    futures = client.map(process, [str(p) for p in paths], out_dir=str(out_dir), n=n, base_seed=base_seed, pure=True)
    return dict(zip((p.name for p in paths), client.gather(futures)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder")
    parser.add_argument("out")
    parser.add_argument("-n", type=int, default=100_000, help="points per mesh")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster)")
    parser.add_argument("--serial", action="store_true", help="no Dask: the plain loop")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.serial:
        results = run_serial(args.folder, out, args.n, args.seed)
    else:
        from dask.distributed import Client, LocalCluster

        if args.scheduler:
            client = Client(args.scheduler)
        else:
            client = Client(LocalCluster(n_workers=2, threads_per_worker=1))
        with client:
            results = run_dask(args.folder, out, args.n, client, args.seed)
    for name, r in results.items():
        print(f"{name}: {len(r['points'])} points" + (", atlas " + "x".join(map(str, r["atlas"].shape[:2])) if "atlas" in r else ""))


if __name__ == "__main__":
    main()
