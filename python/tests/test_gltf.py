"""glTF out of Python: trilux.save and trilux.save_points write .glb and
.gltf (+ .bin) with per-vertex colours and named attributes; trilux.load
(Mesh.colors, Mesh.attributes), trilux.load_points and trimesh read them
back; bad colours and attributes raise InputError naming the argument,
the attribute and the row; bad paths raise FileError naming the path."""

import json
import os
import re
import shutil
import struct
import subprocess
import warnings

import numpy as np
import pytest

import trilux
from conftest import HERE, WORKSPACE, grid

NPM = WORKSPACE / "target" / "browser-e2e"
VALIDATE = WORKSPACE / "test-support" / "src" / "gltf_validate.mjs"


def validate(path):
    """The Khronos glTF-Validator on `path` (test_support::gltf::validate's
    script, run by node from target/browser-e2e, where .ci/run installs
    gltf-validator): no error and no warning. Without node or the package
    it warns and returns, unless CI is set."""
    missing = None
    if shutil.which("node") is None:
        missing = "no node"
    elif not (NPM / "node_modules" / "gltf-validator").is_dir():
        missing = f"gltf-validator is not installed in {NPM} (see .ci/run)"
    if missing:
        assert "CI" not in os.environ, f"CI must run the glTF-Validator, but {missing}"
        warnings.warn(f"the glTF-Validator check is skipped: {missing}")
        return
    out = subprocess.run(["node", "--input-type=module", "-", str(path)], cwd=NPM,
                         input=VALIDATE.read_text(), capture_output=True, text=True)
    assert out.returncode == 0, out.stderr + out.stdout
    lines = [line.split("\t") for line in out.stdout.splitlines()]
    bad = [line for line in lines if line[0] == "issue" and line[1] in ("error", "warning")]
    assert not bad, f"{path}: {bad}"
    counts = [line for line in lines if line[0] == "counts"]
    assert counts and counts[0][1:3] == ["0", "0"], out.stdout


def glb_json(path):
    """The JSON chunk of a .glb file, parsed."""
    data = path.read_bytes()
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    assert (magic, version, length) == (b"glTF", 2, len(data))
    chunk, kind = struct.unpack_from("<I4s", data, 12)
    assert kind == b"JSON"
    return json.loads(data[20 : 20 + chunk])


def accessor(path, doc, name, mesh=0):
    """The values of attribute `name` of the first primitive of `mesh` in a
    .glb, as float32 rows (numpy reads the BIN chunk at the view)."""
    data = path.read_bytes()
    chunk = struct.unpack_from("<I", data, 12)[0]
    bin_start = 20 + chunk + 8
    a = doc["accessors"][doc["meshes"][mesh]["primitives"][0]["attributes"][name]]
    view = doc["bufferViews"][a["bufferView"]]
    assert a["componentType"] == 5126  # float32
    k = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[a["type"]]
    start = bin_start + view.get("byteOffset", 0) + a.get("byteOffset", 0)
    values = np.frombuffer(data, np.float32, a["count"] * k, start)
    return values.reshape(a["count"], k)


def test_a_mesh_with_colours_and_attributes_round_trips_through_glb_and_gltf(tmp_path):
    v, f, uv = grid(4)
    n = len(v)
    rng = np.random.default_rng(1)
    colors = rng.random((n, 3))
    phi = rng.random((n, 3)) * 100
    depth = v[:, 2].copy()
    mesh = trilux.Mesh(v, f, uv=uv)
    for ext in ("glb", "gltf"):
        path = tmp_path / f"m.{ext}"
        trilux.save(path, mesh, colors=colors, attributes={"PHI": phi, "_DEPTH": depth})
        validate(path)
        back = trilux.load(path)
        assert np.abs(back.vertices - v).max() < 1e-6
        assert np.array_equal(back.faces, f)
        assert np.abs(back.uv - uv).max() < 1e-6
    assert (tmp_path / "m.bin").is_file()
    doc = glb_json(tmp_path / "m.glb")
    attributes = doc["meshes"][0]["primitives"][0]["attributes"]
    assert set(attributes) == {"POSITION", "TEXCOORD_0", "COLOR_0", "_PHI", "_DEPTH"}
    path = tmp_path / "m.glb"
    assert np.array_equal(accessor(path, doc, "COLOR_0"), colors.astype(np.float32))
    assert np.array_equal(accessor(path, doc, "_PHI"), phi.astype(np.float32))
    assert np.array_equal(accessor(path, doc, "_DEPTH")[:, 0], depth.astype(np.float32))


def test_a_plain_glb_needs_no_extras_and_trimesh_reads_it(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    v, f, _ = grid(3)
    path = tmp_path / "plain.glb"
    trilux.save(path, (v, f))
    validate(path)
    assert "COLOR_0" not in glb_json(path)["meshes"][0]["primitives"][0]["attributes"]
    scene = trimesh.load(path)
    loaded = scene.to_geometry() if hasattr(scene, "to_geometry") else scene.dump(concatenate=True)
    assert len(loaded.faces) == len(f)
    assert np.abs(np.sort(loaded.vertices, axis=0) - np.sort(v, axis=0)).max() < 1e-6


def test_eight_bit_colours_are_srgb_and_rgba_keeps_alpha(tmp_path):
    v, f, _ = grid(2)
    n = len(v)
    rgba = np.zeros((n, 4), np.uint8)
    rgba[:, 0] = 188  # sRGB 188 is linear 0.5029...
    rgba[:, 3] = 128
    path = tmp_path / "c.glb"
    trilux.save(path, (v, f), colors=rgba)
    validate(path)
    doc = glb_json(path)
    c = accessor(path, doc, "COLOR_0")
    assert c.shape == (n, 4)
    assert np.allclose(c[:, 0], 0.50289, atol=1e-4)
    assert np.allclose(c[:, 3], 128 / 255)
    # Linear floats are written as they are; all-opaque RGBA becomes RGB.
    trilux.save(path, (v, f), colors=np.full((n, 4), [0.25, 0.5, 1.0, 1.0]))
    c = accessor(path, glb_json(path), "COLOR_0")
    assert c.shape == (n, 3) and np.array_equal(c[0], [0.25, 0.5, 1.0])


def test_points_with_normals_faces_colours_and_attributes_to_glb(tmp_path):
    v, f, _ = grid(4)
    p, faces, normals = trilux.sample_surface((v, f), 200, seed=1, return_normal=True)
    colors = np.column_stack([faces / faces.max(), np.zeros(200), np.ones(200)])
    path = tmp_path / "points.glb"
    trilux.save_points(path, p, normals=normals, face_index=faces, colors=colors,
                       attributes={"HEIGHT": p[:, 2]})
    validate(path)
    doc = glb_json(path)
    primitive = doc["meshes"][0]["primitives"][0]
    assert primitive["mode"] == 0  # POINTS
    assert set(primitive["attributes"]) == {"POSITION", "NORMAL", "COLOR_0", "_FACE", "_HEIGHT"}
    assert np.array_equal(accessor(path, doc, "_FACE")[:, 0], faces.astype(np.float32))
    assert np.array_equal(accessor(path, doc, "_HEIGHT")[:, 0], p[:, 2].astype(np.float32))
    positions = accessor(path, doc, "POSITION").astype(np.float64)
    offset = np.array(doc["nodes"][0].get("translation", [0, 0, 0]))
    assert np.abs(positions + offset - p).max() < 1e-6
    # .gltf writes the .bin beside it; PLY stays as it was.
    trilux.save_points(tmp_path / "points.gltf", p, face_index=faces)
    validate(tmp_path / "points.gltf")
    assert (tmp_path / "points.bin").is_file()
    trilux.save_points(tmp_path / "points.ply", p, face_index=faces)
    assert (tmp_path / "points.ply").read_bytes().startswith(b"ply\n")


def test_far_away_points_keep_their_precision_in_glb(tmp_path):
    p = np.array([[4.0e5, 4.6e6, 10.0], [4.0e5 + 0.001, 4.6e6, 10.0], [4.0e5, 4.6e6 + 0.002, 10.0]])
    path = tmp_path / "far.glb"
    trilux.save_points(path, p)
    validate(path)
    doc = glb_json(path)
    positions = accessor(path, doc, "POSITION").astype(np.float64)
    offset = np.array(doc["nodes"][0]["translation"])
    # Millimetre offsets survive (float32 alone would round them to 0.25 m).
    assert np.abs(positions + offset - p).max() < 1e-4


def raises(kind, match, f, *args, **kwargs):
    with pytest.raises(kind) as e:
        f(*args, **kwargs)
    assert match in str(e.value), str(e.value)
    return e.value


def test_bad_colours_and_attributes_are_input_errors_naming_them(tmp_path):
    v, f, _ = grid(2)
    n = len(v)
    glb = tmp_path / "x.glb"
    ok = np.full((n, 3), 0.5)
    cases = [
        ({"colors": np.full((n, 3), 1.5)}, "colors: row 0 is [1.5, 1.5, 1.5], outside [0, 1]"),
        ({"colors": np.full((n, 3), np.nan)}, "colors: row 0 is not finite ([nan, nan, nan])"),
        ({"colors": np.array([[0.5, 0.5, 0.5]] * 7 + [[0.5, np.nan, 0.5]] + [[0.5] * 3] * (n - 8))},
         "colors: row 7 is not finite ([0.5, nan, 0.5])"),
        ({"colors": np.full((n, 4), np.inf)}, "colors: row 0 is not finite ([inf, inf, inf, inf])"),
        ({"colors": np.full((n, 3), 1 + 2e-5)}, "colors: row 0 is [1.00002, 1.00002, 1.00002], outside [0, 1] (linear colours; values within 1e-5 of it are clamped"),
        ({"colors": np.full((n, 3), -2e-5)}, "colors: row 0 is [-2e-05, -2e-05, -2e-05], outside [0, 1]"),
        ({"colors": np.ones((n - 1, 3))}, f"colors: {n - 1} rows for {n} vertices (one per vertex)"),
        ({"colors": np.ones((n, 2))}, "colors: expected an array of shape (n, 3) or (n, 4), got shape"),
        ({"colors": np.ones((n, 3), np.int64)}, "colors: expected floats in [0, 1] (linear) or uint8 (sRGB), got int64"),
        ({"colors": ok, "attributes": {"a b": np.ones(n)}}, "attributes: the name 'a b' may hold only"),
        ({"attributes": {"": np.ones(n)}}, "attributes: the name '' may hold only"),
        ({"attributes": {"PHI": np.ones(n), "_PHI": np.ones(n)}}, "attributes: '_PHI' names the attribute _PHI a second time"),
        ({"attributes": {"PHI": np.ones(n + 1)}}, f"attributes['PHI']: {n + 1} rows for {n} vertices"),
        ({"attributes": {"PHI": np.ones((n, 5))}}, "attributes['PHI']: expected an array of shape (n,) or (n, k)"),
        ({"attributes": {"PHI": np.array([1.0] * (n - 1) + [np.inf])}}, f"attributes['PHI']: row {n - 1} is not finite"),
        ({"attributes": {"PHI": np.full(n, 1e39)}}, "attributes['PHI']: row 0 is not finite (in float32"),
        ({"attributes": {"PHI": np.array(["a"] * n)}}, "attributes['PHI']: expected a real (float or integer) dtype"),
        ({"attributes": {3: np.ones(n)}}, "attributes: the key 3 is not a str"),
        ({"attributes": [np.ones(n)]}, "attributes: expected a dict of names to arrays"),
    ]
    for kwargs, message in cases:
        e = raises(trilux.InputError, message, trilux.save, glb, (v, f), **kwargs)
        assert isinstance(e, ValueError)
        assert not glb.exists(), kwargs
    # Only glTF keeps them: an OBJ or PLY path with them is refused.
    for ext in ("obj", "ply"):
        path = tmp_path / f"x.{ext}"
        raises(trilux.InputError, f"colors: only glTF files (.glb, .gltf) keep per-vertex colours and attributes, and {path} is not one",
               trilux.save, path, (v, f), colors=ok)
        assert not path.exists()
    raises(trilux.InputError, "attributes: only glTF files", trilux.save_points,
           tmp_path / "p.ply", v, attributes={"A": np.ones(n)})
    raises(trilux.InputError, f"colors: {n - 1} rows for {n} points (one per point)", trilux.save_points,
           glb, v, colors=np.ones((n - 1, 3)))
    raises(trilux.InputError, "attributes: FACE is where face_index goes", trilux.save_points,
           glb, v, face_index=np.zeros(n, int), attributes={"FACE": np.ones(n)})
    big = np.zeros(n, np.int64)
    big[2] = 1 << 24
    raises(trilux.InputError, "face_index: entry 2 is 16777216; glTF stores face ids as float32", trilux.save_points,
           glb, v, face_index=big)
    assert not glb.exists()
    # An unknown extension for points is a FileError, as for meshes.
    e = raises(trilux.FileError, "unknown extension \"xyz\" for points (write .ply, .glb or .gltf)",
               trilux.save_points, tmp_path / "p.xyz", v)
    assert str(tmp_path / "p.xyz") in str(e)
    # None is the same as leaving them out.
    trilux.save(glb, (v, f), colors=None, attributes=None)
    assert glb.is_file()


def readme_block(first_line):
    """The README's ```python block that starts with `first_line`."""
    text = (HERE.parent / "README.md").read_text()
    blocks = [b for b in re.findall(r"```python\n(.*?)```", text, re.S) if b.startswith(first_line)]
    assert len(blocks) == 1, first_line
    return blocks[0]


def test_the_readme_gltf_example_runs_as_written(data, tmp_path, monkeypatch):
    """The README's lines as written: the cow and its texture (the density
    block), mesh colours looked up at sampled points (linear interpolation
    in float32 gives 1.0000001 for white texels), then the glTF block,
    whose save_points takes those colours (clamped into [0, 1]) and whose
    load and load_points read the files back."""
    pytest.importorskip("PIL")
    trimesh = pytest.importorskip("trimesh")
    monkeypatch.chdir(tmp_path)
    ns = {"np": np, "trimesh": trimesh, "trilux": trilux, "data": data}
    for first in ("from PIL import Image", "colors = trilux.MeshColors.from_texture", "rgb_per_vertex ="):
        exec(readme_block(first), ns)
    rgb, p, f = ns["rgb"], ns["p"], ns["f"]
    # The rounding that made this example fail: within the tolerance.
    assert 1 < rgb.max() <= 1 + 1e-5 and rgb.min() >= -1e-5
    cloud = ns["cloud"]
    assert np.array_equal(cloud.colors, np.clip(rgb, 0, 1))
    assert np.array_equal(cloud.face_index, f)
    assert np.abs(cloud.points - p).max() < 1e-6
    assert cloud.normals is None and cloud.attributes == {} and cloud.warnings == []
    m = ns["m"]
    assert np.array_equal(m.colors, ns["rgb_per_vertex"])
    assert np.array_equal(m.attributes["DENSITY"], ns["d"].astype(np.float32))
    validate(tmp_path / "points.glb")
    validate(tmp_path / "cow.glb")


def test_colours_within_1e5_of_the_unit_range_are_clamped_into_it(tmp_path):
    v, f, _ = grid(2)
    n = len(v)
    colors = np.full((n, 3), 0.5)
    colors[0] = [1 + 1e-5, -1e-5, 1.0000001]
    colors[1] = [np.float32(1.0000001), -0.0, 1.0]
    path = tmp_path / "c.glb"
    trilux.save(path, (v, f), colors=colors)
    validate(path)
    stored = accessor(path, glb_json(path), "COLOR_0")
    assert stored[0].tolist() == [1.0, 0.0, 1.0] and stored[1].tolist() == [1.0, 0.0, 1.0]
    assert np.array_equal(stored[2:], colors[2:].astype(np.float32))
    assert np.array_equal(trilux.load(path).colors, stored)
    trilux.save_points(tmp_path / "p.glb", v, colors=colors)
    assert np.array_equal(trilux.load_points(tmp_path / "p.glb").colors, stored)
    # Beyond the tolerance it is still an error, naming the row.
    for bad in (1 + 1.1e-5, -1.1e-5):
        colors[3, 1] = bad
        raises(trilux.InputError, "colors: row 3 is [0.5, ", trilux.save_points, tmp_path / "q.glb", v, colors=colors)
    assert not (tmp_path / "q.glb").exists()
    doc = " ".join(trilux.save.__doc__.split())
    assert "within 1e-5 of [0, 1]" in doc and "clamped" in doc


def test_non_finite_positions_and_normals_are_input_errors_naming_the_row(tmp_path):
    v, f, _ = grid(2)
    n = len(v)
    bad = v.copy()
    bad[3, 0] = np.nan
    for ext in ("glb", "gltf", "obj", "ply"):
        path = tmp_path / f"m.{ext}"
        e = raises(trilux.InputError, "mesh: vertex 3 is not finite ([nan, 0.5, ", trilux.save, path, (bad, f))
        assert isinstance(e, ValueError) and not path.exists()
    raises(trilux.InputError, "mesh: vertex 3 is not finite", trilux.save, tmp_path / "m.glb", trilux.Mesh(bad, f),
           colors=np.full((n, 3), 0.5))
    for ext in ("glb", "ply"):
        path = tmp_path / f"p.{ext}"
        raises(trilux.InputError, "points: row 3 is not finite ([nan, 0.5, ", trilux.save_points, path, bad)
        normals = np.tile([0.0, 0.0, 1.0], (n, 1))
        normals[5] = [np.inf, 0, 0]
        raises(trilux.InputError, "normals: row 5 is not finite ([inf, 0.0, 0.0])", trilux.save_points, path, v,
               normals=normals)
        assert not path.exists()
    # What the Rust writer refuses of the data is an InputError too.
    e = raises(trilux.InputError, "cannot write this data: a mesh of 9 vertices and no triangles", trilux.save,
               tmp_path / "m.glb", (v, np.zeros((0, 3), np.int64)))
    assert str(tmp_path / "m.glb") in str(e)


def test_paths_are_checked_before_writing_and_errors_name_the_path_given(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    v, f, uv = grid(2)
    n = len(v)
    # An unknown extension is a FileError whether colours are given or not.
    for extras in ({}, {"colors": np.full((n, 3), 0.5)}, {"attributes": {"A": np.ones(n)}}):
        e = raises(trilux.FileError, 'x.txt: unknown extension "txt" for a mesh (write .obj, .ply, .glb or .gltf)',
                   trilux.save, "x.txt", (v, f), **extras)
        assert isinstance(e, OSError)
        raises(trilux.FileError, "noext: the path has no extension, and the extension picks the format of a mesh "
               "(write .obj, .ply, .glb or .gltf)", trilux.save, "noext", (v, f), **extras)
        raises(trilux.FileError, 'p.txt: unknown extension "txt" for points (write .ply, .glb or .gltf)',
               trilux.save_points, "p.txt", v, **extras)
        raises(trilux.FileError, "noext: the path has no extension, and the extension picks the format of points "
               "(write .ply, .glb or .gltf)", trilux.save_points, "noext", v, **extras)
    # A missing folder is named with the path given (not the .bin a .gltf
    # writes first).
    for ext in ("gltf", "glb", "obj", "ply"):
        raises(trilux.FileError, f"nodir/x.{ext}: the folder nodir does not exist", trilux.save, f"nodir/x.{ext}",
               (v, f))
    raises(trilux.FileError, "nodir/x.gltf: the folder nodir does not exist", trilux.save_points, "nodir/x.gltf", v,
           colors=np.full((n, 3), 0.5))
    nodes = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    raises(trilux.FileError, "nodir/t.node: the folder nodir does not exist", trilux.save_tets, "nodir/t.node",
           nodes, [[0, 1, 2, 3]])
    colors = trilux.MeshColors.from_texture(trilux.Mesh(v, f, uv=uv), np.ones((2, 2, 3)))
    raises(trilux.FileError, "nodir/c.meshcolors: the folder nodir does not exist", colors.save,
           "nodir/c.meshcolors")
    (tmp_path / "file").write_text("")
    raises(trilux.FileError, "file/x.glb: the folder file is not a folder", trilux.save, "file/x.glb", (v, f))
    assert sorted(os.listdir(tmp_path)) == ["file"]


def test_attributes_are_float32_and_integers_must_be_exact_in_it(tmp_path):
    v, f, _ = grid(2)
    n = len(v)
    path = tmp_path / "i.glb"
    ids = np.array([0, 1, -5, 2**24, -(2**24), 2**25, 2**40, 3 * 2**30, 7])
    trilux.save(path, (v, f), attributes={"ID": ids, "U8": np.arange(n, dtype=np.uint8),
                                          "FLAG": np.arange(n) % 2 == 0, "BIG": np.full(n, 2.0**24 + 1)})
    back = trilux.load(path).attributes
    assert all(a.dtype == np.float32 for a in back.values())
    assert np.array_equal(back["ID"].astype(np.int64), ids)
    assert np.array_equal(back["U8"], np.arange(n)) and np.array_equal(back["FLAG"], np.arange(n) % 2 == 0)
    # Floats are rounded to float32, as documented.
    assert np.array_equal(back["BIG"], np.full(n, 2.0**24))
    inexact = ids.copy()
    inexact[4] = 2**24 + 1
    raises(trilux.InputError, "attributes['ID']: row 4 holds the integer 16777217, which float32", trilux.save,
           path, (v, f), attributes={"ID": inexact})
    pairs = np.zeros((n, 2), np.int32)
    pairs[3, 1] = -(2**24 + 3)
    raises(trilux.InputError, "attributes['P']: row 3 holds the integer -16777219", trilux.save_points,
           path, v, attributes={"P": pairs})
    raises(trilux.InputError, "attributes['U']: row 0 holds the integer 18446744073709551615", trilux.save_points,
           path, v, attributes={"U": np.full(n, 2**64 - 1, np.uint64)})
    for doc in (trilux.save.__doc__, trilux.save_points.__doc__):
        doc = " ".join(doc.split())
        assert "stored as float32" in doc and "prefixed with `_`" in doc, doc


def test_names_get_the_underscore_and_zero_normals_become_z(tmp_path):
    v, f, _ = grid(2)
    n = len(v)
    path = tmp_path / "n.glb"
    trilux.save(path, (v, f), attributes={"COLOR_0": np.full((n, 3), 0.25)})
    validate(path)
    attributes = glb_json(path)["meshes"][0]["primitives"][0]["attributes"]
    assert "_COLOR_0" in attributes and "COLOR_0" not in attributes
    m = trilux.load(path)
    assert m.colors is None and list(m.attributes) == ["COLOR_0"]
    assert "`\"COLOR_0\"` `_COLOR_0`" in " ".join(trilux.save.__doc__.split())
    normals = np.tile([0.0, 0.0, 2.0], (n, 1))
    normals[2] = 0
    normals[4] = [3, 0, 4]
    trilux.save_points(tmp_path / "z.glb", v, normals=normals)
    validate(tmp_path / "z.glb")
    back = trilux.load_points(tmp_path / "z.glb").normals
    assert back[2].tolist() == [0, 0, 1] and back[0].tolist() == [0, 0, 1]
    assert np.abs(back[4] - [0.6, 0, 0.8]).max() < 1e-7
    # PLY keeps them as given.
    trilux.save_points(tmp_path / "z.ply", v, normals=normals)
    assert np.array_equal(trilux.load_points(tmp_path / "z.ply").normals, normals)
    assert "a zero one becomes `(0, 0, 1)`" in " ".join(trilux.save_points.__doc__.split())


def test_a_mesh_gives_back_its_colours_and_attributes(tmp_path):
    v, f, uv = grid(4)
    n = len(v)
    rng = np.random.default_rng(2)
    rgb = rng.random((n, 3))
    rgba = np.column_stack([rgb, rng.random(n)])
    attributes = {"PHI": rng.random((n, 3)) * 100, "_DEPTH": v[:, 2], "UV2": rng.random((n, 2)),
                  "Q": rng.random((n, 4)), "ONE": rng.random((n, 1))}

    def same(m, colors):
        assert m.colors.dtype == np.float32 and np.array_equal(m.colors, colors.astype(np.float32))
        assert set(m.attributes) == {"PHI", "DEPTH", "UV2", "Q", "ONE"}
        for name, values in attributes.items():
            want = values.astype(np.float32)
            want = want[:, 0] if want.shape[1:] == (1,) else want  # (n, 1) comes back (n,)
            got = m.attributes[name.lstrip("_")]
            assert got.dtype == np.float32 and np.array_equal(got, want), name

    for ext in ("glb", "gltf"):
        for colors in (rgb, rgba):
            path = tmp_path / f"m.{ext}"
            trilux.save(path, trilux.Mesh(v, f, uv=uv), colors=colors, attributes=attributes)
            m = trilux.load(path)
            same(m, colors)
            assert m.warnings == [] and np.abs(m.vertices - v).max() < 1e-6
            assert repr(m).startswith("trilux.Mesh(25 vertices, 32 faces, uv, colors, attributes ")
            # What load gives, save takes.
            again = tmp_path / f"again.{ext}"
            trilux.save(again, m, colors=m.colors, attributes=m.attributes)
            same(trilux.load(again), colors)
    # uint8 colours are sRGB: they come back linear.
    srgb = np.zeros((n, 3), np.uint8)
    srgb[:, 0] = 188
    trilux.save(tmp_path / "s.glb", (v, f), colors=srgb)
    assert np.abs(trilux.load(tmp_path / "s.glb").colors[:, 0] - 0.50289).max() < 1e-4
    # Other formats and plain files have none.
    for name in ("m.obj", "plain.glb"):
        trilux.save(tmp_path / name, (v, f))
        m = trilux.load(tmp_path / name)
        assert m.colors is None and m.attributes == {}
    assert repr(trilux.Mesh(v, f)) == "trilux.Mesh(25 vertices, 32 faces)"


def test_points_round_trip_through_load_points(tmp_path):
    v, f, _ = grid(4)
    p, faces, normals = trilux.sample_surface((v, f), 300, seed=3, return_normal=True)
    rng = np.random.default_rng(3)
    colors = rng.random((300, 4))
    attributes = {"HEIGHT": p[:, 2], "DIR": rng.random((300, 3))}
    for ext in ("glb", "gltf"):
        path = tmp_path / f"p.{ext}"
        trilux.save_points(path, p, normals=normals, face_index=faces, colors=colors, attributes=attributes)
        c = trilux.load_points(path)
        assert isinstance(c, trilux.Points) and len(c) == 300
        assert c.points.dtype == np.float64 and np.abs(c.points - p).max() < 1e-6
        assert c.normals.dtype == np.float64 and np.abs(c.normals - normals).max() < 1e-6
        assert c.face_index.dtype == np.int64 and np.array_equal(c.face_index, faces)
        assert c.colors.dtype == np.float32 and np.array_equal(c.colors, colors.astype(np.float32))
        assert set(c.attributes) == {"HEIGHT", "DIR"}
        for name, values in attributes.items():
            assert np.array_equal(c.attributes[name], values.astype(np.float32)), name
        assert c.uv is None and c.warnings == [] and np.array_equal(c.origin, [0, 0, 0])
        assert repr(c).startswith("trilux.Points(300 points, normals, face_index, colors, attributes ")
        # What load_points gives, save_points takes.
        again = tmp_path / f"again.{ext}"
        trilux.save_points(again, c.points, normals=c.normals, face_index=c.face_index, colors=c.colors,
                           attributes=c.attributes)
        d = trilux.load_points(again)
        for name in ("points", "normals", "face_index", "colors"):
            assert np.array_equal(getattr(d, name), getattr(c, name)), name
        assert all(np.array_equal(d.attributes[k], c.attributes[k]) for k in c.attributes)
    # PLY keeps positions, normals and face ids.
    trilux.save_points(tmp_path / "p.ply", p, normals=normals, face_index=faces)
    c = trilux.load_points(tmp_path / "p.ply")
    assert np.abs(c.points - p).max() < 1e-6 and np.abs(c.normals - normals).max() < 1e-6
    assert np.array_equal(c.face_index, faces) and c.colors is None and c.attributes == {} and c.warnings == []
    # Positions alone: the rest is None or empty.
    trilux.save_points(tmp_path / "bare.glb", p)
    c = trilux.load_points(tmp_path / "bare.glb")
    assert (c.normals, c.face_index, c.colors, c.uv, c.attributes) == (None, None, None, None, {})
    assert repr(c) == "trilux.Points(300 points)"
    # Far from the origin, the shift keeps millimetres.
    far = np.array([[4.0e5, 4.6e6, 10.0], [4.0e5 + 0.001, 4.6e6, 10.0], [4.0e5, 4.6e6 + 0.002, 10.0]])
    for ext in ("glb", "ply"):
        trilux.save_points(tmp_path / f"far.{ext}", far)
        c = trilux.load_points(tmp_path / f"far.{ext}")
        assert np.abs(c.points - far).max() < 1e-4 and np.abs(c.origin).max() > 1e5


def test_load_and_load_points_point_to_each_other(tmp_path):
    v, f, _ = grid(2)
    points = tmp_path / "p.glb"
    trilux.save_points(points, v)
    m = trilux.load(points)
    assert len(m.vertices) == 0 and len(m.faces) == 0
    assert m.warnings == [f"{points}: the file also holds 9 points (POINTS primitives), which a triangle mesh "
                          "does not keep; trilux.load_points(path) reads them"]
    mesh = tmp_path / "m.glb"
    trilux.save(mesh, (v, f))
    c = trilux.load_points(mesh)
    assert len(c) == 0 and c.points.shape == (0, 3)
    assert c.warnings == [f"{mesh}: the file holds no points (POINTS primitives) but a mesh of 8 triangles, "
                          "which are not points; trilux.load reads it"]
    trilux.save(tmp_path / "m.ply", (v, f))
    c = trilux.load_points(tmp_path / "m.ply")
    assert len(c) == 9 and np.abs(c.points - v).max() < 1e-6
    assert c.warnings == [f"{tmp_path / 'm.ply'}: the file's 8 triangles are left out of the points (its "
                          "vertices); trilux.load reads the mesh"]
    # Paths: the same classes as load.
    raises(trilux.FileError, 'unknown extension "obj" for points (read .ply, .glb or .gltf)', trilux.load_points,
           tmp_path / "m.obj")
    e = raises(trilux.FileError, "", trilux.load_points, tmp_path / "missing.glb")
    assert str(tmp_path / "missing.glb") in str(e)
    raises(trilux.FileError, f"{tmp_path}: is a directory, not a point file (.ply, .glb or .gltf)",
           trilux.load_points, tmp_path)
    raises(trilux.InputError, "path: expected a path", trilux.load_points, 3)
