"""glTF out of Python: trilux.save and trilux.save_points write .glb and
.gltf (+ .bin) with per-vertex colours and named attributes; trilux.load
and trimesh read them back; bad colours and attributes raise InputError
naming the argument, the attribute and the row."""

import json
import os
import shutil
import struct
import subprocess
import warnings

import numpy as np
import pytest

import trilux
from conftest import WORKSPACE, grid

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
        ({"colors": np.full((n, 3), np.nan)}, "colors: row 0 is [nan, nan, nan], outside [0, 1]"),
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
