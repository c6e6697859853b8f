"""Blender's Distribute Points on Faces, the peer of the blue_noise example's
scatter rows (issue 47). Runs in Blender's Python (Blender as a module, PyPI
`bpy`, a benchmark-only venv; never in CI):

    target/bpy-venv/bin/python mesh-sampling/bench/blender_scatter.py \
        MESH.obj OUT_DIR [--random N] [--poisson N] [--repeats R]

Builds a geometry-nodes modifier (Group Input -> Distribute Points on Faces ->
Group Output) on the mesh read from MESH.obj and times its evaluation (the
depsgraph update after a seed change; loading and reading the points back are
not timed), median of R runs (3), for:

- random: method Random, Density = N / area (N = 6e6 by default);
- random-vertex: method Random with a per-vertex density, the mesh attribute
  `density` = w / mean(w) * N / area, w = exp(2 sin(4x') sin(4y') sin(4z'))
  over the bounding box scaled to [0, 2 pi] (about 1:50), read by a Named
  Attribute node into Density: Blender's only kind of density, per
  vertex/face (a density texture inside each triangle is trilux's alone);
- poisson: method Poisson Disk with Density Max = k * N / area for k in
  POISSON_FACTORS and Distance Min calibrated (untimed, by scaling with the
  square root of the count ratio, a few rounds) so that about N points come
  out (N = 1e5 by default).

Writes each case's points as little-endian float32 x, y, z triples to
OUT_DIR/blender_<case>.f32 (so that the Rust side measures ρ exactly as it
measures its own) and prints one JSON object per case on stdout:

  {"peer": "blender", "version": ..., "case": ..., "n": <asked>,
   "points": <count>, "ms": <median>, "runs_ms": [...], "threads": ...,
   "distance_min": ..., "density_max": ..., "file": ...}

Blender's evaluation is multi-threaded (TBB, all cores); "threads" is what
bpy reports (bpy.utils.threads or os.cpu_count()).
"""

import json
import math
import os
import statistics
import sys
import time

import bpy
import numpy as np

POISSON_FACTORS = [2.0, 5.0, 10.0]


def load(path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.obj_import(filepath=path)
    obj = bpy.context.selected_objects[0]
    bpy.context.view_layer.objects.active = obj
    return obj


def area_of(mesh):
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float64)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    mesh.calc_loop_triangles()
    tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int64)
    mesh.loop_triangles.foreach_get("vertices", tris)
    t = co[tris.reshape(-1, 3)]
    return 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum(), co


def scatter_tree(method, readable):
    """Group Input -> Distribute Points on Faces [-> Points to Vertices] -> Output."""
    tree = bpy.data.node_groups.new(f"scatter-{method}-{readable}", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    group_in = tree.nodes.new("NodeGroupInput")
    group_out = tree.nodes.new("NodeGroupOutput")
    dist = tree.nodes.new("GeometryNodeDistributePointsOnFaces")
    dist.distribute_method = method
    tree.links.new(group_in.outputs[0], dist.inputs["Mesh"])
    last = dist.outputs["Points"]
    if readable:
        # Only for reading the points back (untimed): a mesh's vertices.
        to_verts = tree.nodes.new("GeometryNodePointsToVertices")
        tree.links.new(last, to_verts.inputs["Points"])
        last = to_verts.outputs["Mesh"]
    tree.links.new(last, group_out.inputs[0])
    return tree, dist


def named_density(tree, dist):
    attr = tree.nodes.new("GeometryNodeInputNamedAttribute")
    attr.data_type = "FLOAT"
    attr.inputs["Name"].default_value = "density"
    tree.links.new(attr.outputs["Attribute"], dist.inputs["Density"])


def evaluate(obj):
    obj.update_tag()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    return obj.evaluated_get(depsgraph)


def configure(dist, settings, seed):
    for key, value in settings.items():
        dist.inputs[key].default_value = value
    dist.inputs["Seed"].default_value = seed


def timed_runs(obj, dist, settings, repeats):
    """Median ms of `repeats` evaluations (seeds 1..repeats)."""
    runs = []
    for seed in range(1, repeats + 1):
        configure(dist, settings, seed)
        t0 = time.perf_counter()
        evaluate(obj)
        runs.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(runs), runs


def points_of(obj, settings, method, density_attr):
    """The points of seed 1 for `settings`, read through Points to Vertices."""
    tree, dist = scatter_tree(method, readable=True)
    if density_attr:
        named_density(tree, dist)
    mod = obj.modifiers[0]
    timed_tree = mod.node_group
    mod.node_group = tree
    configure(dist, settings, 1)
    mesh = evaluate(obj).data
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    mod.node_group = timed_tree
    return co.reshape(-1, 3)


def count_of(obj, settings, method):
    return len(points_of(obj, settings, method, False))


def report(case, n, points, ms, runs, out_dir, extra):
    path = os.path.join(out_dir, f"blender_{case}.f32")
    np.asarray(points, dtype="<f4").tofile(path)
    threads = bpy.utils.threads() if hasattr(bpy.utils, "threads") else os.cpu_count()
    row = {"peer": "blender", "version": bpy.app.version_string, "case": case, "n": n,
           "points": len(points), "ms": ms, "runs_ms": runs, "threads": threads, "file": path}
    row.update(extra)
    print(json.dumps(row), flush=True)


def main():
    args = sys.argv[1:]
    mesh_path, out_dir = args[0], args[1]
    opts = {"--random": 6_000_000, "--poisson": 100_000, "--repeats": 3}
    i = 2
    while i < len(args):
        opts[args[i]] = int(float(args[i + 1]))
        i += 2
    n_random, n_poisson, repeats = opts["--random"], opts["--poisson"], opts["--repeats"]
    obj = load(mesh_path)
    area, co = area_of(obj.data)
    mod = obj.modifiers.new("scatter", "NODES")

    # Random, uniform.
    tree, dist = scatter_tree("RANDOM", readable=False)
    mod.node_group = tree
    settings = {"Density": n_random / area}
    evaluate(obj)  # warm-up
    ms, runs = timed_runs(obj, dist, settings, repeats)
    report("random", n_random, points_of(obj, settings, "RANDOM", False), ms, runs, out_dir,
           {"density": settings["Density"]})

    # Random with a per-vertex density attribute.
    lo, hi = co.min(axis=0), co.max(axis=0)
    u = (co - lo) / np.maximum(hi - lo, 1e-12) * 2 * math.pi
    w = np.exp(2 * np.sin(4 * u[:, 0]) * np.sin(4 * u[:, 1]) * np.sin(4 * u[:, 2]))
    w = (w / w.mean() * n_random / area).astype(np.float32)
    attr = obj.data.attributes.new("density", "FLOAT", "POINT")
    attr.data.foreach_set("value", w)
    np.asarray(w, dtype="<f4").tofile(os.path.join(out_dir, "blender_vertex_weights.f32"))
    tree, dist = scatter_tree("RANDOM", readable=False)
    named_density(tree, dist)
    mod.node_group = tree
    evaluate(obj)
    ms, runs = timed_runs(obj, dist, {}, repeats)
    report("random-vertex", n_random, points_of(obj, {}, "RANDOM", True), ms, runs, out_dir, {})

    # Poisson disk, Distance Min calibrated to about n_poisson points.
    for factor in POISSON_FACTORS:
        tree, dist = scatter_tree("POISSON", readable=False)
        mod.node_group = tree
        density_max = factor * n_poisson / area
        # Start from a hexagonal packing's spacing of n_poisson points.
        d = 0.8 * 2 * math.sqrt(area / (2 * math.sqrt(3) * n_poisson))
        for _ in range(4):
            c = count_of(obj, {"Distance Min": d, "Density Max": density_max}, "POISSON")
            if c == 0 or abs(c / n_poisson - 1) < 0.02:
                break
            d *= math.sqrt(c / n_poisson)
        settings = {"Distance Min": d, "Density Max": density_max}
        evaluate(obj)
        ms, runs = timed_runs(obj, dist, settings, repeats)
        report(f"poisson-x{factor:g}", n_poisson, points_of(obj, settings, "POISSON", False), ms,
               runs, out_dir, {"distance_min": d, "density_max": density_max})


if __name__ == "__main__":
    main()
