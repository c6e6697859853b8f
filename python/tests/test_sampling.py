"""Statistics of the samplers through Python: chi-square per face against
the area and density masses, each with a deliberately wrong twin that the
same test rejects; blue-noise spacing; the discrete distributions."""

import numpy as np
import pytest

import trilux
from conftest import areas, chi_square, chi_square_critical, grid

N = 400_000


def passes(faces, probabilities):
    counts = np.bincount(faces, minlength=len(probabilities)).astype(np.float64)
    stat, dof = chi_square(counts, probabilities)
    return stat < chi_square_critical(dof)


def test_uniform_counts_follow_area_and_the_naive_twin_fails():
    v, f, _ = grid(12)
    a = areas(v, f)
    _, faces = trilux.sample_surface((v, f), N, seed=1)
    assert passes(faces, a / a.sum())
    # The wrong twin: a triangle chosen uniformly (the article's biased
    # sampler), made here with equal face weights.
    _, naive = trilux.sample_surface((v, f), N, seed=1, face_weight=np.ones(len(f)))
    assert not passes(naive, a / a.sum())
    assert passes(naive, np.full(len(f), 1 / len(f)))


def test_uniform_points_lie_on_their_faces_and_pdf_is_one_over_area():
    v, f, _ = grid(6)
    p, faces, bary, pdf, normals = trilux.sample_surface(
        (v, f), 10_000, seed=2, return_barycentric=True, return_pdf=True, return_normal=True
    )
    corners = v[f[faces]]
    rebuilt = np.einsum("nk,nkd->nd", bary, corners)
    assert np.abs(rebuilt - p).max() < 1e-5
    assert np.allclose(bary.sum(axis=1), 1, atol=1e-6) and (bary >= -1e-7).all()
    assert np.allclose(pdf, 1 / areas(v, f).sum(), rtol=1e-5)
    assert np.allclose(np.linalg.norm(normals, axis=1), 1, atol=1e-5)


def test_face_weights_are_trimesh_probabilities_and_the_density_twin_fails():
    v, f, _ = grid(10)
    w = np.random.default_rng(5).uniform(0.1, 3.0, len(f))
    a = areas(v, f)
    _, faces = trilux.sample_surface((v, f), N, face_weight=w, seed=3)
    assert passes(faces, w / w.sum())
    # Reading the weights as densities (mass w·A) is the wrong twin.
    _, twin = trilux.sample_surface((v, f), N, face_weight=w * a, seed=3)
    assert not passes(twin, w / w.sum())


def block_soup(rng, count=120):
    """Triangles, each with UVs inside one 4×4-texel block of an 8×8
    density image (at least a texel from the block's edges, so that the
    bilinear density is constant over the triangle): vertices, faces, UVs
    (OpenGL convention), the image, and each triangle's density."""
    blocks = np.array([[1.0, 4.0], [0.5, 9.0]])  # [row, col] of the image
    image = np.kron(blocks, np.ones((4, 4)))
    vertices, uvs, value = [], [], []
    for _ in range(count):
        row, col = rng.integers(0, 2, size=2)
        # u in the block's columns; v up, so image row r is v in (1 - (r+1)/2, 1 - r/2).
        u = col * 0.5 + rng.uniform(0.15, 0.35, 3)
        vv = 1 - (row * 0.5 + rng.uniform(0.15, 0.35, 3))
        uvs += list(zip(u, vv))
        vertices += list(rng.normal(size=(3, 3)) * rng.uniform(0.2, 2.0))
        value.append(blocks[row, col])
    faces = np.arange(3 * count).reshape(-1, 3)
    return np.array(vertices), faces, np.array(uvs), image, np.array(value)


@pytest.mark.parametrize("method", ["subdivision", "exact", "rejection"])
def test_density_texture_counts_follow_density_times_area(method):
    v, f, uv, image, value = block_soup(np.random.default_rng(9))
    mass = value * areas(v, f)
    _, faces = trilux.sample_surface((v, f), N, density=image, uv=uv, method=method, seed=4)
    assert passes(faces, mass / mass.sum())
    # The wrong twin: the image read bottom row first (v not flipped).
    flipped = uv.copy()
    flipped[:, 1] = 1 - flipped[:, 1]
    _, twin = trilux.sample_surface((v, f), N, density=image, uv=flipped, method=method, seed=4)
    assert not passes(twin, mass / mass.sum())


def test_density_channels_and_integer_images():
    v, f, uv, image, value = block_soup(np.random.default_rng(2))
    mass = value * areas(v, f)
    rgb = np.zeros(image.shape + (3,))
    rgb[..., 1] = image
    _, faces = trilux.sample_surface((v, f), N, density=rgb, uv=uv, channel="g", seed=5)
    assert passes(faces, mass / mass.sum())
    as_u8 = np.round(image / 9 * 255).astype(np.uint8)
    _, faces8 = trilux.sample_surface((v, f), N, density=as_u8, uv=uv, seed=5)
    m8 = np.round(value / 9 * 255) * areas(v, f)
    assert passes(faces8, m8 / m8.sum())


def nearest_distances(p):
    d = np.linalg.norm(p[:, None, :] - p[None, :, :], axis=2)
    np.fill_diagonal(d, np.inf)
    return d.min(axis=1)


def test_blue_noise_keeps_its_distance_and_random_points_do_not():
    v, f, _ = grid(16)
    total = areas(v, f).sum()
    n = 1500
    r_max = np.sqrt(total / (2 * np.sqrt(3) * n))
    p, faces = trilux.blue_noise((v, f), n, seed=6)
    assert p.shape == (n, 3) and faces.shape == (n,)
    rho = nearest_distances(p).min() / (2 * r_max)
    q, _ = trilux.sample_surface((v, f), n, seed=6)
    rho_random = nearest_distances(q).min() / (2 * r_max)
    assert rho > 0.4 > 0.1 > rho_random
    even, _ = trilux.sample_surface_even((v, f), n, seed=6)
    assert np.array_equal(even, p)
    by_radius, _ = trilux.blue_noise((v, f), radius=r_max, seed=6)
    assert abs(len(by_radius) - n) <= 2


def test_dense_packing_is_the_default_and_packs_tighter_than_elimination():
    v, f, _ = grid(16)
    total = areas(v, f).sum()
    n = 2000
    r_max = np.sqrt(total / (2 * np.sqrt(3) * n))

    def rho(p):
        return nearest_distances(p).min() / (2 * r_max)

    dense, _ = trilux.blue_noise((v, f), n, seed=4)
    named, _ = trilux.blue_noise((v, f), n, seed=4, packing="dense")
    plain, _ = trilux.blue_noise((v, f), n, seed=4, packing="elimination")
    assert np.array_equal(dense, named) and len(plain) == n
    # The dense packing clears 0.75 (point-cloud-utils: 0.75), elimination
    # alone does not (about 0.69).
    assert rho(dense) >= 0.75 > rho(plain) > 0.6, (rho(dense), rho(plain))
    # Progressive order: the same points, reordered.
    ordered, _ = trilux.blue_noise((v, f), n, seed=4, progressive=True)
    assert np.array_equal(np.unique(ordered, axis=0), np.unique(dense, axis=0))
    with pytest.raises(trilux.InputError, match="packing='tight' is not a packing"):
        trilux.blue_noise((v, f), n, packing="tight")


def test_the_default_dense_packing_runs_at_a_hundred_thousand_points():
    # It was refused above about 2.5e5 points (7.8 kB per point); now
    # tiles keep it near 400 B per point (1e6 points take about 0.4 GB).
    v, f, _ = grid(16)
    total = areas(v, f).sum()
    n = 100_000
    r_max = np.sqrt(total / (2 * np.sqrt(3) * n))
    p, faces = trilux.blue_noise((v, f), n, seed=3)
    assert p.shape == (n, 3) and faces.shape == (n,)
    # A cube of side d / sqrt(3) holds two points only if they are closer
    # than d: with d = 2 * 0.7 * r_max, at most one point per cell means
    # rho >= 0.7 (the dense packing: about 0.77; random points fail).
    side = 2 * 0.7 * r_max / np.sqrt(3)

    def crowded(points):
        cells = np.floor(points / side).astype(np.int64)
        return len(cells) - len(np.unique(cells, axis=0))

    q, _ = trilux.sample_surface((v, f), n, seed=3)
    assert crowded(p) == 0 < crowded(q)


def test_distribution1d_counts_and_the_uniform_twin_fails():
    w = np.array([5.0, 1.0, 0.0, 2.0, 7.5, 0.25])
    d = trilux.Distribution1D(w)
    s = d.sample(200_000, seed=1)
    assert s.dtype == np.int64 and not (s == 2).any()
    assert passes(s, w / w.sum())
    assert not passes(trilux.Distribution1D(np.ones(6)).sample(200_000, seed=1), w / w.sum())
    assert np.allclose(d.pdf(np.arange(6)), w / w.sum())
    u = d.invert(np.arange(6))
    assert np.array_equal(d.sample_u(u[[0, 1, 3, 4, 5]]), [0, 1, 3, 4, 5])
    assert len(d) == 6


def test_distribution2d_cells_and_directions():
    rng = np.random.default_rng(3)
    image = rng.uniform(0, 1, (6, 10))
    d = trilux.Distribution2D(image)
    pts, pdf = d.sample(300_000, seed=2)
    cells = (np.floor(pts[:, 1] * 6) * 10 + np.floor(pts[:, 0] * 10)).astype(np.int64)
    assert passes(cells, (image / image.sum()).ravel())
    assert np.allclose(d.pdf(pts[:100]), pdf[:100])
    env = trilux.Distribution2D.from_equirect(image)
    dirs, dpdf = env.sample_direction(1000, seed=4)
    assert np.allclose(np.linalg.norm(dirs, axis=1), 1)
    assert np.allclose(env.pdf_direction(dirs), dpdf, rtol=1e-9)
    # The density over directions integrates to one (Monte Carlo, uniform directions).
    u = rng.normal(size=(200_000, 3))
    assert abs(env.pdf_direction(u).mean() * 4 * np.pi - 1) < 0.02
