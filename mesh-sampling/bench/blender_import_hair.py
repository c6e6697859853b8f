"""Blender's view of trilux's hair files (not in CI): imports a `.usda`
(BasisCurves + Points, `bpy.ops.wm.usd_import`) and a `.glb` (LINES + POINTS,
`bpy.ops.import_scene.gltf`) into empty scenes and prints what Blender made of
them: curves and their points, point clouds and their points, meshes and
their vertices and edges (glTF lines arrive as a mesh of loose edges).

    target/bpy-venv/bin/python mesh-sampling/bench/blender_import_hair.py \
        hair.usda hair.glb [--expect-strands S --expect-points P]

Blender 4.2+ as the `bpy` module. Exits 1 when --expect-* is given and
Blender's counts differ.
"""

import argparse
import sys

import bpy


def empty_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def counts():
    """Per object type: objects, curves, points, vertices, edges."""
    out = {"curves": 0, "curve_points": 0, "pointclouds": 0, "cloud_points": 0,
           "meshes": 0, "vertices": 0, "edges": 0, "faces": 0}
    for obj in bpy.context.scene.objects:
        data = obj.data
        if obj.type == "CURVES":
            out["curves"] += len(data.curves)
            out["curve_points"] += len(data.points)
        elif obj.type == "POINTCLOUD":
            out["pointclouds"] += 1
            out["cloud_points"] += len(data.points)
        elif obj.type == "MESH":
            out["meshes"] += 1
            out["vertices"] += len(data.vertices)
            out["edges"] += len(data.edges)
            out["faces"] += len(data.polygons)
    return out


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("usda")
    parser.add_argument("glb")
    parser.add_argument("--expect-strands", type=int)
    parser.add_argument("--expect-points", type=int)
    args = parser.parse_args()
    print(f"Blender {bpy.app.version_string}")
    ok = True

    empty_scene()
    bpy.ops.wm.usd_import(filepath=args.usda)
    usd = counts()
    print(f"USD  {args.usda}: {usd}")
    for obj in bpy.context.scene.objects:
        if obj.type in ("CURVES", "POINTCLOUD"):
            names = sorted(a.name for a in obj.data.attributes if not a.name.startswith("."))
            print(f"  {obj.type} {obj.name} attributes: {', '.join(names)}")

    empty_scene()
    bpy.ops.import_scene.gltf(filepath=args.glb)
    gltf = counts()
    print(f"glTF {args.glb}: {gltf}")

    if args.expect_strands is not None:
        s, p = args.expect_strands, args.expect_points
        checks = [
            ("USD curves", usd["curves"], s),
            ("USD curve points", usd["curve_points"], p),
            ("USD root points", usd["cloud_points"], s),
            ("glTF line vertices", gltf["vertices"] - s, p) if gltf["meshes"] >= 2
            else ("glTF line vertices", gltf["vertices"], p),
            ("glTF line edges", gltf["edges"], p - s),
        ]
        for name, got, want in checks:
            mark = "ok" if got == want else "MISMATCH"
            ok &= got == want
            print(f"{name}: {got} (written {want}) {mark}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
