"""Same seed, same points as the Rust crates, bit for bit."""

import subprocess

import numpy as np

import trilux


def rust_points(reference_bin, mesh, n, seed, prefix, density=None):
    args = [str(reference_bin), str(mesh), str(n), str(seed), str(prefix)]
    if density is not None:
        args.append(str(density))
    subprocess.run(args, check=True)

    def read(what):
        p = np.fromfile(f"{prefix}.{what}.f64", dtype="<f8").reshape(-1, 3)
        f = np.fromfile(f"{prefix}.{what}.i64", dtype="<i8")
        return p, f

    return read


def test_uniform_and_blue_noise_match_rust_bit_for_bit(data, reference_bin, tmp_path):
    path = data / "meshes" / "stanford-bunny.obj"
    read = rust_points(reference_bin, path, 100_000, 7, tmp_path / "bunny")
    mesh = trilux.load(path)
    points, faces = trilux.sample_surface(mesh, 100_000, seed=7)
    rp, rf = read("uniform")
    assert points.dtype == np.float64 and faces.dtype == np.int64
    assert np.array_equal(points, rp) and np.array_equal(faces, rf)
    # The arrays of a trilux.Mesh given back as plain arrays: the same bits.
    points2, faces2 = trilux.sample_surface((mesh.vertices, mesh.faces), 100_000, seed=7)
    assert np.array_equal(points2, rp) and np.array_equal(faces2, rf)
    bp, bf = trilux.blue_noise(mesh, 10_000, seed=7, packing="elimination")
    rbp, rbf = read("blue")
    assert np.array_equal(bp, rbp) and np.array_equal(bf, rbf)
    # The default packing is the dense one.
    dp, df = trilux.blue_noise(mesh, 10_000, seed=7)
    rdp, rdf = read("dense")
    assert np.array_equal(dp, rdp) and np.array_equal(df, rdf)
    assert not np.array_equal(dp, bp)
    # Another seed gives other points.
    other, _ = trilux.sample_surface(mesh, 1000, seed=8)
    assert not np.array_equal(other, rp[:1000])


def test_density_texture_matches_rust_bit_for_bit(data, reference_bin, tmp_path):
    path = data / "meshes" / "spot.obj"
    texture = data / "textures" / "spot_texture.png"
    read = rust_points(reference_bin, path, 50_000, 3, tmp_path / "spot", texture)
    points, faces = trilux.sample_surface(trilux.load(path), 50_000, density=texture, seed=3)
    rp, rf = read("density")
    assert np.array_equal(points, rp) and np.array_equal(faces, rf)


def test_same_seed_same_points_across_calls_and_threads():
    from conftest import grid

    v, f, uv = grid(16)
    a = trilux.sample_surface((v, f), 200_000, seed=11)
    b = trilux.sample_surface((v, f), 200_000, seed=11)
    assert all(np.array_equal(x, y) for x, y in zip(a, b))
