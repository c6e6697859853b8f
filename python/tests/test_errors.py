"""Every error path raises a trilux.Error subclass (InputError is a
ValueError, FileError an OSError) whose message is the Rust message."""

import numpy as np
import pytest

import trilux
from conftest import grid

V, F, UV = grid(3)


def raises(kind, message, call, *args, **kwargs):
    with pytest.raises(kind) as info:
        call(*args, **kwargs)
    assert isinstance(info.value, trilux.Error)
    if message is not None:
        assert str(info.value) == message, str(info.value)
    return info.value


def test_hierarchy():
    assert issubclass(trilux.InputError, ValueError) and issubclass(trilux.InputError, trilux.Error)
    assert issubclass(trilux.FileError, OSError) and issubclass(trilux.FileError, trilux.Error)
    assert issubclass(trilux.InternalError, RuntimeError)
    assert trilux.Error.__module__ == "trilux"


def test_array_errors():
    raises(trilux.InputError, "vertices: expected an array of shape (n, 3), got shape (16, 2)",
           trilux.sample_surface, (V[:, :2], F), 10)
    raises(trilux.InputError, "faces: expected an integer dtype, got float64",
           trilux.sample_surface, (V, F.astype(float)), 10)
    raises(trilux.InputError, "faces: row 0 references vertex 99, but there are only 16 vertices",
           trilux.sample_surface, (V, np.array([[0, 1, 99]])), 10)
    raises(trilux.InputError, "faces: row 0 references vertex -1, but there are only 16 vertices",
           trilux.sample_surface, (V, np.array([[0, 1, -1]])), 10)
    raises(trilux.InputError, "uv: 3 rows for 16 vertices (one per vertex)",
           trilux.sample_surface, (V, F), 10, uv=UV[:3], density=np.ones((2, 2)))
    raises(trilux.InputError, None, trilux.sample_surface, "not a mesh", 10)
    # Dtypes as numpy prints them, not numpy's bit-count names (str672).
    raises(trilux.InputError, "faces: expected an integer dtype, got <U168 (strings)",
           trilux.sample_surface, (V, np.array([["x" * 168] * 3])), 10)
    raises(trilux.InputError, "vertices: expected a real (float or integer) dtype, got object (Python objects)",
           trilux.sample_surface, (np.array([[None] * 3] * 3), F[:1]), 10)


def test_argument_errors():
    raises(trilux.InputError, "count: -1 is not a count (0 or more)", trilux.sample_surface, (V, F), -1)
    raises(trilux.InputError, "seed: -1 is not in 0..2**64", trilux.sample_surface, (V, F), 1, seed=-1)
    raises(trilux.InputError, "method: \"bogus\" is not one of 'uniform', 'subdivision', 'exact', 'rejection'",
           trilux.sample_surface, (V, F), 1, method="bogus")
    raises(trilux.InputError, "give at most one of density, face_weight and vertex_weight",
           trilux.sample_surface, (V, F), 1, density=np.ones((2, 2)), face_weight=np.ones(len(F)))
    raises(trilux.InputError, "give exactly one of count and radius", trilux.blue_noise, (V, F))
    raises(trilux.InputError, "channel: 5 is not a channel of a 3-channel density image (0..2)",
           trilux.sample_surface, (V, F), 1, uv=UV, density=np.ones((2, 2, 3)), channel=5)


def test_rust_errors_keep_their_message():
    # mesh-sampling's own messages, unchanged.
    raises(trilux.InputError, "a texture density needs texture coordinates, and the mesh has none",
           trilux.sample_surface, (V, F), 10, density=np.ones((2, 2)))
    w = np.ones(len(F))
    w[3] = -1
    raises(trilux.InputError, "face 3 has weight -1: weights must be finite and >= 0",
           trilux.sample_surface, (V, F), 10, face_weight=w)
    raises(trilux.InputError, "the mesh has no triangles", trilux.sample_surface, (V, np.zeros((0, 3), int)), 10)
    raises(trilux.InputError, "weight 1 is negative (-1); weights must be >= 0", trilux.Distribution1D, [1, -1])
    raises(trilux.InputError, "no weights: a distribution needs at least one entry", trilux.Distribution1D, [])
    raises(trilux.InputError,
           "no measured material is called \"jelly\"; the names are those of Jensen et al. 2001 (apple, chicken1, "
           "chicken2, cream, ketchup, marble, potato, skimmilk, skin1, skin2, spectralon, wholemilk)",
           trilux.Object, np.eye(4, 3), [[0, 1, 2, 3]], medium="jelly")
    raises(trilux.InputError, "converting a texture to mesh colours needs texture coordinates, and the mesh has none",
           trilux.MeshColors.from_texture, (V, F), np.ones((2, 2, 3)))
    one = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    e = raises(trilux.InputError, None, trilux.tetrahedralize, (one, [[0, 1, 2]]), spacing=0.1)
    # A single triangle bounds no volume at any spacing: the message says so.
    assert str(e).startswith("the surface encloses no volume: none of its 1 triangles bounds one"), e
    assert "smaller spacing" not in str(e)
    raises(trilux.InputError, "envelope=1.5: the envelope is a fraction of the bounding box's diagonal, between 0 and 1 (e.g. 0.002)",
           trilux.tetrahedralize, (V, F), envelope=1.5)


def test_file_errors(tmp_path):
    missing = tmp_path / "missing.obj"
    e = raises(trilux.FileError, None, trilux.load, missing)
    assert isinstance(e, OSError) and str(missing) in str(e)
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    e = raises(trilux.FileError, None, trilux.load, bad)
    assert "bad.obj" in str(e) and "line 4" in str(e)
    raises(trilux.FileError, None, trilux.load_tets, tmp_path / "missing.node")
    # A folder is named as one, not as a file with the extension "".
    raises(trilux.FileError, f"{tmp_path}: is a directory, not a mesh file (.obj, .gltf, .glb or .ply)",
           trilux.load, tmp_path)
    e = raises(trilux.FileError, None, trilux.load_tets, tmp_path)
    assert "is a directory" in str(e)
    e = raises(trilux.FileError, None, trilux.save, tmp_path / "mesh.xyz", (V, F))
    assert "xyz" in str(e)
    junk = tmp_path / "junk.meshcolors"
    junk.write_bytes(b"not mesh colours")
    e = raises(trilux.FileError, None, trilux.MeshColors.load, junk, (V, F))
    assert str(junk) in str(e)


def test_wrong_mesh_for_mesh_colors(tmp_path):
    colors = trilux.MeshColors.from_texture(trilux.Mesh(V, F, uv=UV), np.ones((4, 4, 3)))
    path = tmp_path / "c.meshcolors"
    colors.save(path)
    other_v, other_f, _ = grid(4)
    e = raises(trilux.InputError, None, trilux.MeshColors.load, path, (other_v, other_f))
    assert str(e).startswith(f"{path}: these mesh colours belong to a mesh of 16 vertices and 18 faces")


def test_transcut_errors():
    nodes = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    obj = trilux.Object(nodes, [[0, 1, 2, 3]])
    raises(trilux.InputError, "add_light: give exactly one of direction, position and envmap", obj.add_light)
    raises(trilux.InputError, "the cut removes all 1 tetrahedra: nothing would be left",
           obj.cut, [-1, 0, 0], [1, 0, 0])
    raises(trilux.InputError, "method: \"saw\" is not 'exact' or 'relax'", obj.cut, [0, 0, 0], [1, 0, 0], method="saw")
    raises(trilux.InputError, "tets: row 0 references node 4, but there are only 4 nodes",
           trilux.Object, nodes, [[1, 2, 3, 4]])


def test_distribution1d_index_out_of_range_is_an_error_naming_it():
    # Before: pdf gave 0 and invert NaN for such an index, which a caller
    # would take for a probability and a variate.
    d = trilux.Distribution1D([1.0, 2.0, 3.0])
    raises(trilux.InputError, "index: entry 1 is 3, not an index of the 3 entries (0..2)", d.pdf, [0, 3])
    raises(trilux.InputError, "index: entry 0 is -1, not an index of the 3 entries (0..2)", d.pdf, [-1, 0])
    raises(trilux.InputError, "index: entry 2 is 7, not an index of the 3 entries (0..2)", d.invert, [0, 1, 7])
    assert np.allclose(d.pdf([0, 1, 2]), [1 / 6, 2 / 6, 3 / 6])
    assert np.allclose(d.invert([0, 1, 2]), [0, 1 / 6, 3 / 6])


def test_variates_outside_the_unit_interval_are_errors_naming_them():
    d = trilux.Distribution1D([1.0, 2.0, 3.0])
    raises(trilux.InputError, "u: entry 1 is 1, not in [0, 1)", d.sample_u, [0.5, 1.0])
    raises(trilux.InputError, "u: entry 0 is -0.1, not in [0, 1)", d.sample_u, [-0.1])
    raises(trilux.InputError, "u: entry 2 is NaN, not in [0, 1)", d.sample_u, [0.0, 0.5, np.nan])
    assert d.sample_u([0.0, 0.999]).tolist() == [0, 2]
    d2 = trilux.Distribution2D(np.ones((4, 4)))
    raises(trilux.InputError, "u: row 1 is [0.5, 1], not in [0, 1)²", d2.sample_u, [[0.5, 0.5], [0.5, 1.0]])
    raises(trilux.InputError, "u: row 0 is [-0.5, 0.5], not in [0, 1)²", d2.sample_u, [[-0.5, 0.5]])
    raises(trilux.InputError, "points: row 0 is [NaN, 0.2], not in [0, 1)²", d2.pdf, [[np.nan, 0.2]])
    raises(trilux.InputError, "points: row 1 is [0.2, 1.5], not in [0, 1)²", d2.pdf, [[0.2, 0.2], [0.2, 1.5]])
    raises(trilux.InputError, "directions: row 1 is [inf, 0, 0], not a finite direction",
           d2.pdf_direction, [[0, 0, 1], [np.inf, 0, 0]])
    raises(trilux.InputError, "directions: row 0 is [0, NaN, 1], not a finite direction",
           d2.pdf_direction, [[0, np.nan, 1]])
    assert np.allclose(d2.pdf([[0.2, 0.7]]), [1.0])
    # A zero direction is still a density of 0, not an error.
    assert d2.pdf_direction([[0.0, 0.0, 0.0]]).tolist() == [0.0]


def test_too_many_points_names_count_in_python_words():
    e = raises(trilux.InputError, None, trilux.sample_surface, (V, F), 2**27 + 1)
    assert str(e) == (
        "count: 134217729 points is more than one call returns (at most 134217728 = 2**27); "
        "ask for fewer, and call again with another seed for more"
    )
    # Not the Rust message, which points at an API Python does not have.
    assert "sample_stream" not in str(e)


def test_integer_arguments_name_themselves_in_type_errors():
    def type_error(message, call, *args, **kwargs):
        with pytest.raises(TypeError) as info:
            call(*args, **kwargs)
        assert str(info.value) == message, str(info.value)

    type_error("count must be an int, got str", trilux.sample_surface, (V, F), "10")
    type_error("count must be an int, got float", trilux.sample_surface, (V, F), count=1.5)
    type_error("count must be an int, got bool", trilux.sample_surface, (V, F), True)
    type_error("count must be an int, got float", trilux.blue_noise, (V, F), 10.0)
    type_error("count must be an int, got float", trilux.sample_surface_even, (V, F), 2.0)
    type_error("seed must be an int, got float", trilux.sample_surface, (V, F), 10, seed=1.0)
    d = trilux.Distribution1D([1.0, 2.0])
    type_error("n must be an int, got str", d.sample, "3")
    type_error("seed must be an int, got str", d.sample, 3, seed="x")
    type_error("n must be an int, got float", trilux.Distribution2D(np.ones((2, 2))).sample_direction, 2.5)
    nodes = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    obj = trilux.Object(nodes, [[0, 1, 2, 3]])
    type_error("envmap_samples must be an int, got float", obj.add_light, envmap=np.ones((4, 8, 3)),
               envmap_samples=2.5)
    type_error("relax_sweeps must be an int, got str", obj.cut, [0, 0, 0], [1, 0, 0], method="relax",
               relax_sweeps="3")
    type_error("size must be an int, got float", obj.render, size=2.0)
    type_error("gutter must be an int, got float",
               trilux.MeshColors.from_texture(trilux.Mesh(V, F, uv=UV), np.ones((4, 4, 3))).bake, gutter=1.0)
    # numpy integers are integers; too large or negative ones are InputErrors naming the argument.
    assert trilux.sample_surface((V, F), np.int32(10), seed=np.uint64(3))[0].shape == (10, 3)
    raises(trilux.InputError, f"count: {2**200} is too large a count", trilux.sample_surface, (V, F), 2**200)
    raises(trilux.InputError, "seed: 18446744073709551616 is not in 0..2**64",
           trilux.sample_surface, (V, F), 1, seed=2**64)
    raises(trilux.InputError, "envmap_samples: 0 is not in 1.. (an environment light needs at least one sample)",
           obj.add_light, envmap=np.ones((4, 8, 3)), envmap_samples=0)
    raises(trilux.InputError, "relax_sweeps: -1 is not in 0..", obj.cut, [0, 0, 0], [1, 0, 0], method="relax",
           relax_sweeps=-1)


TET = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])


def test_messages_name_the_python_arguments():
    # tet-diffusion calls it length_unit_mm; the Object's argument is unit_mm.
    raises(trilux.InputError, "unit_mm is -1: millimetres per mesh unit must be positive and finite",
           trilux.Object, TET, [[0, 1, 2, 3]], unit_mm=-1.0)
    raises(trilux.InputError, "eta (the index of refraction) is 0: it must be positive and finite",
           trilux.Object, TET, [[0, 1, 2, 3]], eta=0.0)
    # The positions of a tet mesh are its nodes (Object(nodes, tets)), not vertices.
    bad = TET.copy()
    bad[2, 1] = np.nan
    raises(trilux.InputError, "nodes: node 2 has a non-finite position [0, NaN, 0]", trilux.Object, bad, [[0, 1, 2, 3]])
    raises(trilux.InputError, "tets: row 0 repeats node 1", trilux.Object, TET, [[0, 1, 1, 3]])
    raises(trilux.InputError, "nodes: node 4 is used by no tetrahedron (1 such nodes); drop unused nodes (and "
           "renumber tets) before making the Object", trilux.Object, np.vstack([TET, [[5.0, 5, 5]]]), [[0, 1, 2, 3]])
    flat = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    e = raises(trilux.InputError, None, trilux.Object, flat, [[0, 1, 2, 3]])
    assert str(e).startswith("tets: row 0 (nodes [0, 1, 2, 3]) has zero volume"), str(e)
    # The stuffing's lattice spacing h is tetrahedralize's spacing.
    octahedron = (np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]),
                  [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    raises(trilux.InputError, "spacing: -1 is not a positive finite length (mesh units)",
           trilux.tetrahedralize, octahedron, spacing=-1.0)
    e = raises(trilux.InputError, None, trilux.tetrahedralize, octahedron, spacing=1e-4)
    assert str(e).startswith("spacing=1e-4: the lattice over this surface needs "), str(e)
    assert str(e).endswith("; choose a larger spacing"), str(e)
    # mesh-sampling's "approximate mode" is method='subdivision' here.
    rng = np.random.default_rng(0)
    e = raises(trilux.InputError, None, trilux.sample_surface, (V, F), 10, uv=UV * 1e5,
               density=rng.random((64, 64)), method="exact")
    assert str(e).startswith("integrating the density exactly over the mesh would visit "), str(e)
    assert str(e).endswith("its UVs tile the texture too many times for method='exact' or method='rejection' "
                           "(use method='subdivision', the default with a texture)"), str(e)
    assert "approximate mode" not in str(e)
    # The way to give a texture is the image argument, not the command line's --texture.
    raises(trilux.InputError, "the mesh has no material with a texture: give one "
           "(MeshColors.from_texture(mesh, image), image an array or an image file)",
           trilux.MeshColors.from_texture, trilux.Mesh(V, F, uv=UV))
    # Blue noise's budget names the argument as the caller gave it.
    raises(trilux.InputError, "count=1099511627776: 1099511627776 points is more than a run can index "
           "(4294967294); ask for fewer points (count)", trilux.blue_noise, (V, F), 2**40)
    raises(trilux.InputError, "radius: -1 is not a positive finite length (mesh units)",
           trilux.blue_noise, (V, F), radius=-1.0)
