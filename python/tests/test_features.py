"""The tour of the README, as tests: files, mesh colours, tetrahedra and
TransCut from Python."""

import numpy as np
import pytest

import trilux
from conftest import grid


def test_save_and_load_round_trip(tmp_path):
    v, f, uv = grid(4)
    m = trilux.Mesh(v, f, uv=uv)
    for ext in ("obj", "ply"):
        path = tmp_path / f"m.{ext}"
        trilux.save(path, m)
        back = trilux.load(path)
        # The OBJ reader numbers vertices by first use: compare corners.
        assert np.abs(back.vertices[back.faces] - v[f]).max() < 1e-6
        assert np.abs(back.uv[back.faces] - uv[f]).max() < 1e-6
    assert "trilux.Mesh(25 vertices, 32 faces, uv)" == repr(trilux.load(tmp_path / "m.obj"))


def test_points_to_ply(tmp_path):
    v, f, _ = grid(4)
    p, faces, normals = trilux.sample_surface((v, f), 100, seed=1, return_normal=True)
    path = tmp_path / "points.ply"
    trilux.save_points(path, p, normals=normals, face_index=faces)
    assert path.stat().st_size > 100 * 12


def test_mesh_colors_lookup_bake_save_load(tmp_path):
    v, f, uv = grid(6)
    # A texture that is linear in u: mesh colours reproduce it.
    image = np.zeros((32, 32, 3))
    image[..., 0] = np.linspace(0, 1, 32)[None, :]
    colors = trilux.MeshColors.from_texture(trilux.Mesh(v, f, uv=uv), image)
    assert colors.channels == 3 and colors.face_count == len(f)
    faces = np.arange(len(f))
    bary = np.full((len(f), 3), 1 / 3)
    rgb = colors.lookup(faces, bary)
    u_centre = uv[f].mean(axis=1)[:, 0]
    assert np.abs(rgb[:, 0] - np.interp(u_centre * 32 - 0.5, np.arange(32), np.linspace(0, 1, 32))).max() < 0.05
    nearest = colors.lookup(faces, bary, filter="nearest")
    mip = colors.lookup(faces, bary, filter="mip", footprint=np.full(len(f), 0.5))
    assert nearest.shape == mip.shape == rgb.shape
    baked, atlas = colors.bake()
    assert atlas.ndim == 3 and atlas.shape[2] == 4 and atlas.dtype == np.float32
    assert len(baked.faces) == len(f) and baked.uv is not None
    path = tmp_path / "c.meshcolors"
    colors.save(path)
    again = trilux.MeshColors.load(path, (v, f))
    assert np.array_equal(again.samples, colors.samples)


def test_tetrahedralize_and_tet_files(tmp_path):
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=3)
    nodes, tets, report = trilux.tetrahedralize(sphere, spacing=0.15, return_report=True)
    assert nodes.dtype == np.float64 and tets.dtype == np.int64
    assert report["tets"] == len(tets) and report["min_dihedral_deg"] > 5
    # The boundary within the spacing of the sphere, both ways.
    assert 0 < report["mean_distance"] < report["hausdorff"] < 0.15
    assert report["hausdorff"] == max(report["input_to_tets"], report["tets_to_input"])
    assert report["hausdorff_fraction"] == pytest.approx(report["hausdorff"] / report["diagonal"])
    assert report["left_out_triangles"] == 0 and min(report["distance_points"]) >= 65536
    t = nodes[tets]
    volume = np.einsum("ij,ij->i", np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), t[:, 3] - t[:, 0]) / 6
    assert (volume > 0).all() and abs(volume.sum() - 4 / 3 * np.pi) < 0.15
    graded = trilux.tetrahedralize(sphere, spacing=0.05, graded=True)
    assert len(graded[1]) < len(trilux.tetrahedralize(sphere, spacing=0.05)[1])
    trilux.save_tets(tmp_path / "s.node", nodes, tets)
    n2, t2 = trilux.load_tets(tmp_path / "s.node")
    assert np.array_equal(t2, tets) and np.abs(n2 - nodes).max() < 1e-9


def test_tetrahedralize_fits_a_box_to_an_envelope():
    import trimesh

    # A box whose corners fall between lattice points: the plain stuffing
    # cuts them off, the fit moves boundary vertices onto them.
    box = trimesh.creation.box(extents=[1.04, 0.93, 0.49])
    box.apply_translation([0.03, 0.017, 0.011])
    _, plain_tets, plain = trilux.tetrahedralize(box, spacing=0.1, return_report=True)
    nodes, tets, fitted = trilux.tetrahedralize(box, spacing=0.1, envelope=0.001, return_report=True)
    assert plain["envelope"] is None and plain["fitted_vertices"] == 0
    assert fitted["envelope"] == 0.001 and fitted["fitted_vertices"] > 0 and fitted["sharp_edges"] == 12
    # The fit may split boundary edges where moves are not enough (at most 3x).
    assert len(plain_tets) <= len(tets) <= 3 * len(plain_tets) and fitted["min_dihedral_deg"] >= 10
    assert fitted["dihedral_bound_deg"] == (9.0, 165.0) and plain["dihedral_bound_deg"] == (9.0, 162.0)
    assert fitted["input_to_tets"] < 0.5 * plain["input_to_tets"]
    corners = np.asarray(box.vertices)
    gap = max(np.linalg.norm(nodes - c, axis=1).min() for c in corners)
    assert gap < 1e-6  # the corners as float32 (the mesh is read in single precision)


def test_tetrahedralize_warns_of_a_sheet_it_leaves_out():
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=3)
    sheet_v = np.array([[3, -0.5, -0.5], [3, 0.5, -0.5], [3, 0.5, 0.5], [3, -0.5, 0.5]], dtype=float)
    v = np.vstack([sphere.vertices, sheet_v])
    n = len(sphere.vertices)
    f = np.vstack([sphere.faces, [[n, n + 1, n + 2], [n, n + 2, n + 3]]])
    with pytest.warns(UserWarning, match="2 triangles .* left out"):
        _, _, report = trilux.tetrahedralize((v, f), spacing=0.15, return_report=True)
    assert report["left_out_triangles"] == 2 and report["hausdorff"] < 0.15


def test_transcut_object_solve_cut_paint_fracture_render():
    import trimesh

    nodes, tets = trilux.tetrahedralize(trimesh.creation.icosphere(subdivisions=2), spacing=0.2)
    assert "marble" in trilux.media()
    obj = trilux.Object(nodes, tets, medium="marble", unit_mm=10.0)
    assert obj.add_light([0.3, 1.0, 0.6]) == 0
    report = obj.solve()
    assert report["levels"] >= 1 and len(report["iterations"]) == 3
    assert report["solver"] in ("Jacobi-PCG", "V-cycle-PCG"), report["solver_choice"]
    forced = obj.solve(solver="vcycle")
    assert forced["solver"] == "V-cycle-PCG" and forced["solver_choice"] == "V-cycle-PCG (as set)"
    with pytest.raises(ValueError, match="solver"):
        obj.solve(solver="multigrid")
    obj.solve()
    radiance = obj.radiance()
    assert radiance.shape == (len(obj.boundary_vertices), 3) and (radiance >= 0).all()
    lit = radiance[np.asarray(nodes)[obj.boundary_vertices] @ np.array([0.3, 1, 0.6]) > 0].mean()
    dark = radiance[np.asarray(nodes)[obj.boundary_vertices] @ np.array([0.3, 1, 0.6]) < -0.5].mean()
    assert lit > dark  # the lit side glows more
    image = obj.render(size=64)
    assert image.shape == (64, 64, 3) and image.dtype == np.float32 and image.max() > 0
    painted = obj.paint([0, 0, 0], 0.3, "ketchup")
    assert painted > 0
    cut = obj.cut([0, 0, 0], [0, 0, 1])
    assert cut["removed_tets"] > 0 and cut["split_tets"] > 0
    relaxed = trilux.Object(nodes, tets).cut([0, 0, 0], [0, 1, 0], method="relax", relax_sweeps=5)
    assert relaxed["removed_tets"] > 0 and relaxed["split_tets"] == 0
    # Ketchup's green and blue diffusion lengths are below this coarse
    # mesh's edges: solve says so, once per channel.
    with pytest.warns(UserWarning, match="diffusion length") as record:
        obj.solve()
    assert [str(w.message).split(" channel")[0] for w in record] == [
        "Object.solve: in the green", "Object.solve: in the blue"]
    a, b = trilux.Object(nodes, tets).fracture([0, 0, 0], [1, 0, 0], offset=0.5)
    whole = trilux.Object.recombine(a, b)
    # The fracture splits the tets the plane crosses; recombining joins
    # the pieces' tets back into one object.
    assert len(whole.mesh[1]) == len(a.mesh[1]) + len(b.mesh[1]) >= len(tets)
    a.solve()
    b.solve()
    both = trilux.render([a, b], size=32, exposure=None)
    assert both.shape == (32, 32, 3)


def test_load_tets_keeps_the_file_orientation_and_object_reorients(tmp_path):
    """load_tets returns a tet as the file stores it, inverted or not (as
    its docstring says); Object re-orients an inverted tet by swapping its
    first two nodes, so Object.mesh has positive volumes only."""
    nodes = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]])
    tets = np.array([[0, 1, 2, 3], [2, 1, 3, 4]])  # the second is inverted

    def volumes(n, t):
        p = n[t]
        return np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6

    assert volumes(nodes, tets)[1] < 0 < volumes(nodes, tets)[0]
    path = tmp_path / "two.mesh"
    trilux.save_tets(path, nodes, tets)
    n, t = trilux.load_tets(path)
    assert np.array_equal(t, tets) and np.array_equal(n, nodes)
    mesh_nodes, mesh_tets = trilux.Object(n, t).mesh
    assert mesh_tets.tolist() == [[0, 1, 2, 3], [1, 2, 3, 4]]
    assert (volumes(mesh_nodes, mesh_tets) > 0).all()
    assert "not\nre-oriented" in trilux.load_tets.__doc__ or "not re-oriented" in " ".join(
        trilux.load_tets.__doc__.split())
    assert "swapping its first two nodes" in " ".join(trilux.Object.__doc__.split())
