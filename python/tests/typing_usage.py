"""A typed use of the API: `mypy --strict` checks it against the stubs
(run by .ci/run; see test_stubs.py for the runtime side)."""

from typing import Optional, Tuple

import numpy as np
import numpy.typing as npt

import trilux

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
F32 = npt.NDArray[np.float32]

def tour(path: str) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    mesh: trilux.Mesh = trilux.load(path)
    vertices: npt.NDArray[np.float64] = mesh.vertices
    skipped: list[str] = mesh.warnings
    points, faces = trilux.sample_surface(mesh, 1000, seed=1)
    more = trilux.sample_surface(mesh, 10, return_pdf=True, return_barycentric=True)
    assert len(more) == 4
    # Literal flags pick the overload: each array's type is known.
    p4, f4, bary4, pdf4 = more
    with_normals: Tuple[F64, I64, F64] = trilux.sample_surface(mesh, 10, return_normal=True)
    everything: Tuple[F64, I64, F64, F64, F64] = trilux.sample_surface(
        mesh, 10, return_barycentric=True, return_pdf=True, return_normal=True
    )
    plain: Tuple[F64, I64] = trilux.sample_surface(mesh, 10, return_pdf=False)
    blue_pdf: Tuple[F64, I64, F64] = trilux.blue_noise(mesh, 10, return_pdf=True)
    blue_all: Tuple[F64, I64, F64, F64, F64] = trilux.blue_noise(
        mesh, radius=0.1, return_barycentric=True, return_pdf=True, return_normal=True
    )
    scattered: Tuple[F64, I64, F64] = trilux.scatter(mesh, 100.0, max_density=1.0, return_pdf=True)
    del scattered
    # A plain bool gives one of the tuples: its length is checked at run time.
    flag: bool = len(path) > 3
    either = trilux.sample_surface(mesh, 10, return_pdf=flag)
    if len(either) == 3:
        chosen_pdf: F64 = either[2]
        del chosen_pdf
    some_tets = trilux.tetrahedralize(mesh, return_report=flag)
    some_tet_files = trilux.load_tets(path, return_warnings=flag)
    no_report: Tuple[F64, I64] = trilux.tetrahedralize(mesh, return_report=False)
    no_warnings: Tuple[F64, I64] = trilux.load_tets(path, return_warnings=False)
    del p4, f4, bary4, pdf4, with_normals, everything, plain, blue_pdf, blue_all, either
    del some_tets, some_tet_files, no_report, no_warnings
    blue, _ = trilux.blue_noise((vertices, mesh.faces), 100, seed=2)
    even, _ = trilux.sample_surface_even(mesh, 100)
    d = trilux.Distribution1D([1.0, 2.0])
    idx: npt.NDArray[np.int64] = d.sample(10, seed=3)
    env = trilux.Distribution2D.from_equirect(np.ones((4, 8)))
    dirs, pdf = env.sample_direction(10)
    nodes, tets = trilux.tetrahedralize(mesh, spacing=0.1)
    nodes2, tets2, report = trilux.tetrahedralize(mesh, return_report=True)
    tmin: float = report["min_dihedral_deg"]
    tet_nodes, tet_ids, tet_warnings = trilux.load_tets(path, return_warnings=True)
    first_warning: list[str] = tet_warnings
    obj = trilux.Object(nodes, tets, medium="marble", unit_mm=1000.0)
    light: int = obj.add_light([0.0, 1.0, 0.0])
    obj.solve()
    image: npt.NDArray[np.float32] = obj.render(size=16)
    a, b = obj.fracture([0, 0, 0], [1, 0, 0])
    whole: trilux.Object = trilux.Object.recombine(a, b)
    colors = trilux.MeshColors.from_texture(mesh, np.ones((2, 2, 3)))
    rgb: npt.NDArray[np.float32] = colors.lookup(faces, np.ones((len(faces), 3)) / 3)
    baked, atlas = colors.bake()
    trilux.save(path + ".glb", mesh, colors=np.ones((len(vertices), 3)), attributes={"PHI": vertices[:, 0]})
    trilux.save_points(path + ".glb", points, face_index=faces, attributes={"DEPTH": points[:, 2]})
    cloud: trilux.Points = trilux.load_points(path + ".glb")
    cloud_faces: Optional[I64] = cloud.face_index
    cloud_colors: Optional[F32] = cloud.colors
    depth: F32 = cloud.attributes["DEPTH"]
    n_points: int = len(cloud)
    trilux.save_points(path + ".ply", cloud.points, normals=cloud.normals, face_index=cloud.face_index)
    trilux.save_points(path + ".glb", cloud.points, colors=cloud.colors, attributes=cloud.attributes)
    loaded = trilux.load(path + ".glb")
    mesh_colors: Optional[F32] = loaded.colors
    trilux.save(path + ".glb", loaded, colors=loaded.colors, attributes=loaded.attributes)
    del cloud_faces, cloud_colors, depth, n_points, mesh_colors
    try:
        trilux.load("missing.obj")
    except trilux.FileError as e:
        message: str = str(e)
    del skipped, tet_nodes, tet_ids, first_warning
    del idx, dirs, pdf, nodes2, tets2, tmin, light, image, whole, rgb, baked, atlas, blue, even, message
    return points, faces


def next_event(mesh: trilux.Mesh, image: F64, shading_points: F64) -> F64:
    emitter = trilux.Emitter(mesh, image, strategy="texture-exact", two_sided=True, wrap="clamp")
    s = emitter.sample(len(shading_points), shading_points, seed=1)
    face: npt.NDArray[np.int64] = s["face_index"]
    pdf: F64 = emitter.pdf(face, s["barycentric"], shading_points)
    le: F64 = emitter.radiance(face, s["barycentric"])
    weights: F64 = emitter.triangle_power()
    total: float = emitter.power
    name: str = emitter.strategy
    per_face = trilux.Emitter(mesh, face_radiance=np.ones((3, 3)), strategy="triangle-power")
    inside = emitter.sample_in_triangle(face, np.full((len(face), 2), 0.5))
    inside_pdf: F64 = emitter.pdf_in_triangle(face, inside["barycentric"])
    lower, upper, normal = emitter.triangle_bounds()
    del le, weights, total, name, per_face, inside_pdf, lower, upper, normal
    return pdf
