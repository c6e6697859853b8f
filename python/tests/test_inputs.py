"""Any array-like in (dtypes, memory layouts, lists, trimesh objects),
numpy arrays of the documented dtypes out."""

import numpy as np
import pytest

import trilux
from conftest import grid


def base():
    v, f, uv = grid(5)
    return v.astype(np.float32).astype(np.float64), f, uv  # exact in float32


def strided(a):
    """A non-contiguous view with a's values."""
    big = np.zeros((a.shape[0], 2 * a.shape[1]), dtype=a.dtype)
    big[:, ::2] = a
    return big[:, ::2]


VERTEX_FORMS = {
    "float64": lambda v: v,
    "float32": lambda v: v.astype(np.float32),
    "fortran": lambda v: np.asfortranarray(v),
    "strided": strided,
    "list": lambda v: v.tolist(),
}
FACE_FORMS = {
    "int64": lambda f: f,
    "int32": lambda f: f.astype(np.int32),
    "uint32": lambda f: f.astype(np.uint32),
    "uint64": lambda f: f.astype(np.uint64),
    "fortran": lambda f: np.asfortranarray(f.astype(np.int32)),
    "strided": strided,
    "reversed-copy": lambda f: f[::-1][::-1],
    "list": lambda f: f.tolist(),
}


@pytest.mark.parametrize("vname", VERTEX_FORMS)
@pytest.mark.parametrize("fname", FACE_FORMS)
def test_every_dtype_and_layout_gives_the_same_points(vname, fname):
    v, f, _ = base()
    want_p, want_f = trilux.sample_surface((v, f), 5000, seed=3)
    p, faces = trilux.sample_surface((VERTEX_FORMS[vname](v), FACE_FORMS[fname](f)), 5000, seed=3)
    assert p.dtype == np.float64 and faces.dtype == np.int64
    assert p.shape == (5000, 3) and faces.shape == (5000,)
    assert p.flags.c_contiguous
    assert np.array_equal(p, want_p) and np.array_equal(faces, want_f)


def test_mesh_class_and_objects_with_vertices_and_faces():
    v, f, uv = base()

    class Duck:
        vertices = v
        faces = f

    m = trilux.Mesh(v, f, uv=uv)
    assert m.vertices.dtype == np.float64 and m.faces.dtype == np.int64
    assert np.array_equal(m.vertices, v) and np.array_equal(m.faces, f)
    assert np.allclose(m.uv, uv, atol=1e-7)
    want = trilux.sample_surface((v, f), 1000, seed=1)
    for mesh in (m, Duck()):
        got = trilux.sample_surface(mesh, 1000, seed=1)
        assert all(np.array_equal(a, b) for a, b in zip(got, want))


def test_density_weights_in_any_dtype():
    v, f, _ = base()
    w = np.arange(1, len(f) + 1)
    want = trilux.sample_surface((v, f), 2000, face_weight=w.astype(np.float64), seed=2)
    for form in (w.astype(np.int32), w.astype(np.float32), w.tolist(), w[::-1][::-1]):
        got = trilux.sample_surface((v, f), 2000, face_weight=form, seed=2)
        assert all(np.array_equal(a, b) for a, b in zip(got, want))


def test_far_from_origin_vertices_keep_their_precision():
    v, f, _ = base()
    far = v * 0.01 + np.array([4.0e5, 4.6e6, 10.0])
    m = trilux.Mesh(far, f)
    assert np.abs(m.vertices - far).max() < 1e-6
    assert (m.origin != 0).any()
    p, faces = trilux.sample_surface(m, 1000, seed=1)
    assert np.abs(p.mean(axis=0) - far.mean(axis=0)).max() < 0.01


trimesh = pytest.importorskip("trimesh")


def test_trimesh_objects_are_accepted():
    sphere = trimesh.creation.icosphere(subdivisions=3)
    p, faces = trilux.sample_surface(sphere, 20_000, seed=1)
    assert np.allclose(np.linalg.norm(p, axis=1), 1, atol=0.02)
    assert faces.max() < len(sphere.faces)
    tets = trilux.tetrahedralize(sphere, spacing=0.1)
    assert tets[0].shape[1] == 3 and tets[1].shape[1] == 4
    # trilux's output goes straight back into trimesh.
    cloud = trimesh.PointCloud(p)
    assert len(cloud.vertices) == 20_000
    baked, atlas = trilux.MeshColors.from_texture(
        trimesh.Trimesh(sphere.vertices, sphere.faces, visual=trimesh.visual.TextureVisuals(
            uv=(sphere.vertices[:, :2] + 1) / 2, image=None)),
        np.ones((4, 4, 3)),
    ).bake()
    again = trimesh.Trimesh(baked.vertices, baked.faces)
    assert len(again.faces) == len(sphere.faces) and atlas.shape[2] == 4


def test_textured_trimesh_brings_its_uv_and_texture(data):
    spot = trimesh.load(data / "meshes" / "spot.obj", process=False)
    from PIL import Image

    image = Image.open(data / "textures" / "spot_texture.png")
    spot.visual = trimesh.visual.TextureVisuals(uv=spot.visual.uv, image=image)
    p, faces, bary = trilux.sample_surface(
        spot, 100_000, density=np.asarray(image), seed=1, return_barycentric=True
    )
    corners = spot.vertices[spot.faces[faces]]
    assert np.abs(np.einsum("nk,nkd->nd", bary, corners) - p).max() < 1e-5
    colors = trilux.MeshColors.from_texture(spot)
    assert colors.face_count == len(spot.faces)
    # The same cow read by trilux, with the same texture, converts alike.
    own = trilux.MeshColors.from_texture(trilux.load(data / "meshes" / "spot.obj"), data / "textures" / "spot_texture.png")
    assert abs(colors.sample_count - own.sample_count) <= own.sample_count // 100
    rgb = colors.lookup(faces[:1000], bary[:1000])
    assert rgb.shape == (1000, 3) and rgb.dtype == np.float32 and (rgb >= 0).all()


def test_palette_pil_images_are_read_as_their_colours():
    """trimesh keeps palette PNGs as PIL images of mode "P": their array is
    palette indices, so they are converted to RGB first (as PIL shows them)."""
    from PIL import Image

    rng = np.random.default_rng(3)
    rgb = Image.fromarray(rng.integers(0, 255, (16, 16, 3), dtype=np.uint8))
    palette = rgb.quantize(colors=8)
    assert palette.mode == "P"
    as_rgb = np.asarray(palette.convert("RGB"))
    a = trilux.Distribution2D(palette)
    b = trilux.Distribution2D(as_rgb)
    u = rng.random((1000, 2))
    assert np.array_equal(a.sample_u(u)[0], b.sample_u(u)[0])
    indices = np.asarray(palette)  # what a plain array conversion would read
    c = trilux.Distribution2D(indices)
    assert not np.array_equal(a.sample_u(u)[0], c.sample_u(u)[0])
