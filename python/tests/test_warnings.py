"""`Mesh.warnings` and `load_tets(..., return_warnings=True)`: what a
reader skipped without refusing the file, as the str trilux info prints,
naming the file and what was skipped; empty for intact files and meshes
made of arrays."""

import numpy as np

import trilux

SQUARE_WITHOUT_VT = """v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vn 0 0 1
f 1/1/1 2/2/1 3/3/1
f 1/1/1 3/3/1 4/4/1
"""

# Gmsh 2.2 ASCII: one tetrahedron and one boundary triangle (type 2).
TET_AND_TRIANGLE = """$MeshFormat
2.2 0 8
$EndMeshFormat
$Nodes
4
1 0 0 0
2 1 0 0
3 0 1 0
4 0 0 1
$EndNodes
$Elements
2
1 2 2 0 0 1 2 3
2 4 2 0 0 1 2 3 4
$EndElements
"""


def test_mesh_warnings_name_the_file_and_what_was_skipped(tmp_path):
    path = tmp_path / "square.obj"
    path.write_text(SQUARE_WITHOUT_VT)
    mesh = trilux.load(path)
    assert mesh.faces.shape == (2, 3)
    warnings = mesh.warnings
    assert isinstance(warnings, list) and len(warnings) == 1
    assert isinstance(warnings[0], str)
    assert "square.obj" in warnings[0] and "`vt`" in warnings[0], warnings
    # The same text as the Rust reader's, so a user can grep for it.
    assert mesh.uv is None


def test_intact_files_and_array_meshes_have_no_warnings(tmp_path):
    path = tmp_path / "tri.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert trilux.load(path).warnings == []
    mesh = trilux.Mesh(np.eye(3), [[0, 1, 2]])
    assert mesh.warnings == []


def test_load_tets_returns_the_warnings_when_asked(tmp_path):
    path = tmp_path / "mixed.msh"
    path.write_text(TET_AND_TRIANGLE)
    nodes, tets = trilux.load_tets(path)
    assert nodes.shape == (4, 3) and tets.shape == (1, 4)
    nodes2, tets2, warnings = trilux.load_tets(path, return_warnings=True)
    assert np.array_equal(nodes2, nodes) and np.array_equal(tets2, tets)
    assert len(warnings) == 1 and isinstance(warnings[0], str)
    assert "mixed.msh" in warnings[0] and "1 of type 2" in warnings[0], warnings
    trilux.save_tets(tmp_path / "clean.node", nodes, tets)
    assert trilux.load_tets(tmp_path / "clean.node", return_warnings=True)[2] == []


class _Unreadable:
    """What trimesh hands out for `material.image` when Pillow is missing:
    a placeholder that raises as soon as it is touched."""

    def __array__(self, *args, **kwargs):
        raise ModuleNotFoundError("No module named 'PIL'")

    def __getattr__(self, name):
        raise ModuleNotFoundError("No module named 'PIL'")


class _Material:
    image = _Unreadable()


class _Visual:
    def __init__(self, n):
        self.uv = np.zeros((n, 2))
        self.material = _Material()


class _TexturedMesh:
    def __init__(self):
        self.vertices = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
        self.faces = np.array([[0, 1, 2]])
        self.visual = _Visual(3)


def test_an_unreadable_texture_is_left_out_with_a_warning_not_an_error():
    import pytest

    with pytest.warns(UserWarning, match=r"mesh\.visual\.material\.image could not be read.*PIL"):
        points, faces = trilux.sample_surface(_TexturedMesh(), 100, seed=1)
    assert points.shape == (100, 3)
    assert (faces == 0).all()


class _PlainMaterial:
    def __init__(self, image):
        self.image = image


class _MeshWithImage:
    def __init__(self, image):
        self.vertices = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
        self.faces = np.array([[0, 1, 2]])
        self.visual = _Visual(3)
        self.visual.uv = np.array([[0.0, 0], [1, 0], [0, 1]])
        self.visual.material = _PlainMaterial(image)


def test_trimesh_single_colour_placeholder_is_no_texture():
    """trimesh's `empty_material` (an OBJ with UVs and no texture) is a 2×2
    image of one colour: it is not the file's texture, so mesh colours from
    it are refused with the message that asks for one, not baked grey."""
    import pytest

    grey = np.full((2, 2, 3), 102, dtype=np.uint8)
    with pytest.raises(trilux.InputError, match=r"no material with a texture: give one"):
        trilux.MeshColors.from_texture(_MeshWithImage(grey))
    # A real texture (more than 4 texels, or not one colour) is used.
    texture = np.random.default_rng(1).integers(0, 255, (8, 8, 3), dtype=np.uint8)
    trilux.MeshColors.from_texture(_MeshWithImage(texture))
    two = np.array([[[0, 0, 0], [255, 255, 255]]], dtype=np.uint8)
    trilux.MeshColors.from_texture(_MeshWithImage(two))


NODES = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])


def _lit_tet():
    obj = trilux.Object(NODES, [[0, 1, 2, 3]], medium="marble", unit_mm=1.0)
    obj.add_light([0.0, 1.0, 0.0])
    return obj


def test_results_of_an_unsolved_object_warn():
    import warnings

    import pytest

    obj = _lit_tet()
    for name, call in [
        ("Object.render", lambda: obj.render(size=8)),
        ("Object.radiance", obj.radiance),
        ("Object.fluence", lambda: obj.fluence),
        (r"render \(objects\[0\]\)", lambda: trilux.render([obj], size=8)),
    ]:
        with pytest.warns(UserWarning, match=name + ": the object has not been solved"):
            call()
    obj.solve()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        obj.render(size=8)
        obj.radiance()
        obj.fluence
        trilux.render([obj], size=8)
    # A change makes the solution stale again.
    obj.add_light([1.0, 0.0, 0.0])
    with pytest.warns(UserWarning, match="Object.render: the object has not been solved"):
        obj.render(size=8)
    obj.solve()
    obj.paint([0, 0, 0], 0.1, "marble")
    with pytest.warns(UserWarning, match="Object.fluence"):
        obj.fluence
    # A call that raises does not also warn.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(trilux.InputError, match="size: 0 is not in 1..8192"):
            obj.render(size=0)


def test_solve_warns_when_the_mesh_cannot_resolve_the_medium():
    import warnings

    import pytest

    # Ketchup's green and blue diffusion lengths (about 0.6 and 0.4 mm) are
    # below this tet's mean edge (3.6 mm at 3 mm per unit); its red one
    # (4.8 mm) is not.
    obj = trilux.Object(NODES, [[0, 1, 2, 3]], medium="ketchup", unit_mm=3.0)
    obj.add_light([0.0, 1.0, 0.0])
    with pytest.warns(UserWarning) as record:
        obj.solve()
    messages = [str(w.message) for w in record]
    assert len(messages) == 2, messages
    assert messages[0].startswith("Object.solve: in the green channel the diffusion length "), messages
    assert messages[1].startswith("Object.solve: in the blue channel the diffusion length "), messages
    assert all("(the medium of tetrahedron 0) is below the mesh's mean edge length" in m for m in messages)
    # Marble at 1 mm per unit is resolved: no warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _lit_tet().solve()
