"""Imports glTF files that trilux wrote into Blender and prints what it finds.

Blender is what most artists open a GLB in, so this checks trilux's glTF
output with Blender's own importer (``bpy.ops.import_scene.gltf``): per
file, the mesh objects with their vertex and face counts (and vertex-only
meshes, which is how Blender imports POINTS primitives), the colour and
custom attributes, and the image textures on the materials. Each file's
line ends with the values the caller expects, checked here; the script
exits non-zero on any mismatch.

Not part of CI (``bpy`` is about 1 GB). Set up once, then run on files
written by ``trilux``:

    ~/.pyenv/versions/3.13.0/bin/python -m venv target/bpy-venv
    target/bpy-venv/bin/pip install bpy
    target/bpy-venv/bin/python cli/tests/blender/check_gltf.py \\
        spot_atlas.glb:vertices=...,faces=...,texture=1 points.glb:points=100000

Each argument is ``FILE[:key=value,...]`` with the keys ``vertices``,
``faces``, ``points`` (the vertices of meshes without faces), ``texture``
(the number of distinct image textures) and ``attributes`` (names joined
by ``+``, e.g. ``_PHI+_RADIANCE+Col``) that the file must show.
"""

import sys

import bpy


def summary(path):
    """Imports `path` into an empty scene and counts what Blender made."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    result = bpy.ops.import_scene.gltf(filepath=path)
    if result != {"FINISHED"}:
        raise RuntimeError(f"{path}: the importer returned {result}")
    found = {"vertices": 0, "faces": 0, "points": 0, "attributes": set(), "images": set()}
    for obj in bpy.context.scene.objects:
        if obj.type != "MESH":
            continue
        mesh = obj.data
        if len(mesh.polygons) == 0:
            found["points"] += len(mesh.vertices)
        else:
            found["vertices"] += len(mesh.vertices)
            found["faces"] += len(mesh.polygons)
        for attribute in mesh.attributes:
            if not attribute.name.startswith(".") and attribute.name not in (
                "position",
                "sharp_face",
                "UVMap",
            ):
                found["attributes"].add(attribute.name)
        for slot in obj.material_slots:
            material = slot.material
            if material is None or material.node_tree is None:
                continue
            for node in material.node_tree.nodes:
                if node.type == "TEX_IMAGE" and node.image is not None:
                    size = tuple(node.image.size)
                    found["images"].add((node.image.name, size))
    return found


def check(path, expected):
    """Prints what Blender found in `path`; the mismatches with `expected`."""
    found = summary(path)
    images = ", ".join(f"{name} {w}x{h}" for name, (w, h) in sorted(found["images"]))
    print(
        f"{path}: {found['vertices']} vertices, {found['faces']} faces, "
        f"{found['points']} points; attributes {sorted(found['attributes'])}; "
        f"images [{images}]"
    )
    problems = []
    for key in ("vertices", "faces", "points"):
        if key in expected and found[key] != int(expected[key]):
            problems.append(f"{key}: expected {expected[key]}, Blender has {found[key]}")
    if "texture" in expected and len(found["images"]) != int(expected["texture"]):
        problems.append(f"image textures: expected {expected['texture']}, found {len(found['images'])}")
    for name in filter(None, expected.get("attributes", "").split("+")):
        if name not in found["attributes"]:
            problems.append(f"attribute {name} missing")
    return [f"{path}: {p}" for p in problems]


def main(arguments):
    problems = []
    for argument in arguments:
        path, _, spec = argument.partition(":")
        expected = dict(item.split("=", 1) for item in spec.split(",") if item)
        problems += check(path, expected)
    for problem in problems:
        print(problem, file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
