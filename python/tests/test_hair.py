"""trilux.grow_hair: strands from sampled roots — exact geometry of straight
and combed strands, per-root arrays, determinism, errors naming the argument,
and the files written."""

import numpy as np
import pytest

import trilux


def plane(n=8):
    """An n×n grid in the xy plane (normal +z) with UVs."""
    u, v = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    vertices = np.stack([u.ravel(), v.ravel(), np.zeros(u.size)], axis=1)
    faces = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            faces += [[a, a + 1, a + n + 1], [a + 1, a + n + 2, a + n + 1]]
    return vertices, np.array(faces)


def roots(count=500, seed=1):
    mesh = plane()
    p, f, b = trilux.sample_surface(mesh, count, seed=seed, return_barycentric=True)
    return mesh, p, f, b


def test_straight_strands_stand_on_their_roots_with_their_lengths():
    mesh, p, f, b = roots()
    lengths = np.linspace(0.1, 0.6, len(f))
    out = trilux.grow_hair(mesh, f, b, lengths, segments=4)
    pts = out["points"]
    assert pts.shape == (len(f), 5, 3) and pts.dtype == np.float64
    np.testing.assert_allclose(pts[:, 0], p, atol=1e-6)
    np.testing.assert_allclose(pts[:, :, 2], lengths[:, None] * np.arange(5) / 4, atol=1e-6)
    np.testing.assert_allclose(pts[:, :, :2], np.repeat(p[:, None, :2], 5, axis=1), atol=1e-6)
    np.testing.assert_array_equal(out["face_index"], f)
    np.testing.assert_allclose(out["barycentric"], b, atol=1e-7)
    np.testing.assert_allclose(out["normal"], np.tile([0.0, 0.0, 1.0], (len(f), 1)))
    assert out["uv"] is None
    assert out["widths"].shape == (len(f), 5)
    np.testing.assert_allclose(out["widths"][:, 0], 0.01 * lengths, rtol=1e-6)


def test_comb_tilts_by_its_angle_and_curl_keeps_its_radius():
    mesh, p, f, b = roots(200)
    # Degrees, as `--hair-comb X,Y,Z:ANGLE` and Blender's UI.
    out = trilux.grow_hair(mesh, f, b, 1.0, comb=[0, 1, 0], comb_angle=np.degrees(0.5))
    axis = out["points"][:, -1] - out["points"][:, 0]
    np.testing.assert_allclose(axis, np.tile([0, np.sin(0.5), np.cos(0.5)], (len(f), 1)), atol=1e-5)
    out = trilux.grow_hair(mesh, f, b, 1.0, segments=16, curl_radius=0.2, curl_turns=2.0)
    rel = out["points"] - out["points"][:, :1]
    s = np.arange(17) / 16
    np.testing.assert_allclose(np.hypot(rel[..., 0], rel[..., 1]), 0.2 * s[None, :] * np.ones((len(f), 1)), atol=1e-5)


def test_same_seed_same_strands_and_clumps_pull_tips_together():
    mesh, p, f, b = roots(3000)
    kw = dict(segments=6, curl_radius=0.02, curl_turns=1.0, noise=0.01, seed=4)
    a = trilux.grow_hair(mesh, f, b, 0.3, **kw)
    again = trilux.grow_hair(mesh, f, b, 0.3, **kw)
    np.testing.assert_array_equal(a["points"], again["points"])
    other = trilux.grow_hair(mesh, f, b, 0.3, **{**kw, "seed": 5})
    assert not np.array_equal(a["points"], other["points"])
    clumped = trilux.grow_hair(mesh, f, b, 0.3, clumps=30, clump=1.0, **kw)
    tips = np.unique(np.round(clumped["points"][:, -1], 6), axis=0)
    assert len(tips) <= 30, "clump=1 puts every tip on one of the centres' tips"
    np.testing.assert_array_equal(clumped["points"][:, 0], a["points"][:, 0])


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        (dict(length=-1.0), "length[0] = -1"),
        (dict(length=np.array([0.1, np.nan])), "length: one value or one per root"),
        (dict(length=0.1, segments=0), "segments"),
        (dict(length=0.1, clump=2.0), "clump[0] = 2"),
        (dict(length=0.1, comb=[1, 0]), "comb"),
        (dict(length=0.1, comb=[0, 0, 0]), "comb = [0, 0, 0]: a direction"),
        (dict(length=0.1, comb=[0, 1, 0], comb_angle=200), "comb_angle[0] = 200: must be in [0, 180] degrees"),
        (dict(length=0.1, comb=[0, 1, 0], comb_angle=-1), "comb_angle[0] = -1"),
        (dict(length=0.1, path="strands.obj"), ".usda"),
    ],
)
def test_bad_arguments_name_themselves(kwargs, needle):
    mesh, p, f, b = roots(5)
    with pytest.raises(trilux.Error) as e:
        trilux.grow_hair(mesh, f, b, **kwargs)
    assert needle in str(e.value), str(e.value)


@pytest.mark.parametrize("scale", [5.0, -1.0])
def test_barycentrics_that_are_not_barycentric_are_named(scale):
    # bary * 5 sums to 5, -bary has negative coordinates: both would put
    # roots off the surface.
    mesh, p, f, b = roots(5)
    bad = b.astype(np.float64).copy()
    bad[2] *= scale
    with pytest.raises(trilux.InputError, match=r"barycentric\[2\] = .*not barycentric"):
        trilux.grow_hair(mesh, f, bad, 0.1)
    # The f32 rounding of sample_surface's own coordinates is accepted.
    trilux.grow_hair(mesh, f, b.astype(np.float32), 0.1)


def test_usd_is_written_as_usd_text_and_a_path_is_replaced(tmp_path):
    mesh, p, f, b = roots(20)
    trilux.grow_hair(mesh, f, b, 0.2, segments=3, path=tmp_path / "a.usda")
    path = tmp_path / "a.usd"
    path.write_text("old")
    trilux.grow_hair(mesh, f, b, 0.2, segments=3, path=path)
    assert path.read_bytes() == (tmp_path / "a.usda").read_bytes()


def test_a_face_index_outside_the_mesh_is_named():
    mesh, p, f, b = roots(5)
    f = f.copy()
    f[3] = 10**6
    with pytest.raises(trilux.InputError, match=r"face_index\[3\]"):
        trilux.grow_hair(mesh, f, b, 0.1)


def test_files_written_hold_the_strands(tmp_path):
    v, faces = plane()
    mesh = trilux.Mesh(v, faces, uv=v[:, :2].copy())
    p, f, b = trilux.sample_surface(mesh, 100, seed=2, return_barycentric=True)
    for ext in ("usda", "hair", "glb"):
        path = tmp_path / f"strands.{ext}"
        out = trilux.grow_hair(mesh, f, b, 0.2, segments=3, path=path)
        assert path.stat().st_size > 0
    # The roots' UVs, OpenGL convention as Mesh.uv: here the xy position.
    np.testing.assert_allclose(out["uv"], p[:, :2], atol=1e-6)
    text = (tmp_path / "strands.usda").read_text()
    assert "def BasisCurves" in text and 'upAxis = "Y"' in text
    roots_back = trilux.load_points(tmp_path / "strands.glb")
    np.testing.assert_allclose(roots_back.points, out["points"][:, 0], atol=1e-6)
    data = (tmp_path / "strands.hair").read_bytes()
    assert data[:4] == b"HAIR" and int.from_bytes(data[4:8], "little") == 100
