"""One run of a peer mesher for the `stuffing` example's `--envelope` table.

Usage: python peers.py TOOL PREFIX PARAM

Reads the surface from PREFIX.pos (little-endian f64, n x 3) and PREFIX.tri
(little-endian u32, m x 3, 0-based), runs TOOL (tetgen, gmsh or ftetwild)
once with PARAM (TetGen's maximum volume, Gmsh's largest element size,
fTetWild's ideal edge length, in the surface's unit), writes the nodes to
PREFIX.TOOL.node.raw (f64, k x 3) and the tetrahedra to PREFIX.TOOL.ele.raw
(u32, t x 4, 0-based), and prints one JSON line: {"ms": ..., "tets": ...}
with the meshing time only (no import, no file I/O), or {"error": "..."}
with the tool's own message when it refuses the input.
"""

import json
import math
import sys
import time

import numpy as np


def tetgen(v, f, max_volume):
    """TetGen 1.6 through the `tetgen` package: -p keeps the input
    triangles, -q1.2 bounds the radius-edge ratio, -a caps the volume."""
    import tetgen

    t = tetgen.TetGen(v, f)
    start = time.perf_counter()
    nodes, elems = t.tetrahedralize(switches=f"pq1.2a{max_volume:.6e}Q")[:2]
    return time.perf_counter() - start, nodes, elems


def gmsh(v, f, size):
    """Gmsh through its own Python API: the surface as a discrete entity
    (duplicate nodes merged, as merging an STL does), classified along
    sharp edges (40 degrees, as Gmsh's STL tutorial t13), one volume
    bounded by all of it, meshed in 3D with the default Delaunay algorithm
    and optimiser. Without createGeometry the input triangles are kept, as
    TetGen's -p keeps them; MeshSizeMax sets the interior size."""
    import gmsh

    gmsh.initialize(["-noenv"], readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        # Gmsh logs most failures instead of raising: keep the log to say why.
        gmsh.logger.start()
        gmsh.model.add("surface")
        start = time.perf_counter()
        s = gmsh.model.addDiscreteEntity(2)
        gmsh.model.mesh.addNodes(2, s, np.arange(1, len(v) + 1), v.ravel())
        gmsh.model.mesh.addElementsByType(s, 2, [], (f.astype(np.uint64) + 1).ravel())
        gmsh.model.mesh.removeDuplicateNodes()
        gmsh.model.mesh.classifySurfaces(40 * math.pi / 180, True, False, math.pi)
        surfaces = [tag for _, tag in gmsh.model.getEntities(2)]
        loop = gmsh.model.geo.addSurfaceLoop(surfaces)
        gmsh.model.geo.addVolume([loop])
        gmsh.model.geo.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.model.mesh.generate(3)
        elapsed = time.perf_counter() - start
        tags, coords, _ = gmsh.model.mesh.getNodes()
        _, tet_tags, tet_nodes = gmsh.model.mesh.getElements(3)
        if not tet_nodes:
            # An open surface floods its volume: Gmsh only warns.
            log = gmsh.logger.get()
            said = [m for m in log if m.startswith("Error")] or [
                m for m in log if m.startswith("Warning")
            ]
            raise RuntimeError("no tetrahedra" + (f" ({said[-1]})" if said else ""))
        index = np.zeros(int(tags.max()) + 1, dtype=np.int64)
        index[tags.astype(np.int64)] = np.arange(len(tags))
        elems = index[np.concatenate(tet_nodes).astype(np.int64)].reshape(-1, 4)
        return elapsed, coords.reshape(-1, 3), elems
    finally:
        gmsh.finalize()


def ftetwild(v, f, edge_length):
    """fTetWild through `pytetwild`, with its default envelope (1e-3 of the
    bounding-box diagonal) and optimisation, on all cores."""
    import pytetwild

    start = time.perf_counter()
    nodes, elems = pytetwild.tetrahedralize(
        v, f.astype(np.int32), edge_length_abs=edge_length, epsilon=1e-3, quiet=True
    )
    return time.perf_counter() - start, nodes, elems


def main():
    tool, prefix, param = sys.argv[1], sys.argv[2], float(sys.argv[3])
    v = np.fromfile(prefix + ".pos", dtype="<f8").reshape(-1, 3)
    f = np.fromfile(prefix + ".tri", dtype="<u4").reshape(-1, 3).astype(np.int32)
    run = {"tetgen": tetgen, "gmsh": gmsh, "ftetwild": ftetwild}[tool]
    try:
        seconds, nodes, elems = run(v, f, param)
    except Exception as e:  # the tool's own message, one line
        print(json.dumps({"error": " ".join(str(e).split()) or type(e).__name__}))
        return
    np.asarray(nodes, dtype="<f8").tofile(f"{prefix}.{tool}.node.raw")
    np.asarray(elems, dtype="<u4").tofile(f"{prefix}.{tool}.ele.raw")
    print(json.dumps({"ms": seconds * 1000.0, "tets": int(len(elems))}))


if __name__ == "__main__":
    main()
