"""trilux.Emitter: next-event estimates of the irradiance from a
constant-radiance square against Lambert's closed form for every strategy
(and a wrong twin that fails), pdfs and radiance from (face, barycentric)
against the samples', far-from-origin meshes, determinism, errors."""

import numpy as np
import pytest

import trilux

STRATEGIES = ["area", "triangle-power", "texture", "texture-exact"]
LIT = np.array([2.0, 1.0, 0.5])


def ceiling(n=5, z=1.0):
    """[-1, 2]² at height z in n × n cells, facing down (counter-clockwise
    seen from below), UVs [0, 1]² (OpenGL convention)."""
    s, t = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    s, t = s.ravel(), t.ravel()
    vertices = np.stack([3 * s - 1, 3 * t - 1, np.full_like(s, z)], axis=1)
    faces = []
    for y in range(n):
        for x in range(n):
            a = y * (n + 1) + x
            faces += [[a, a + n + 1, a + 1], [a + 1, a + n + 1, a + n + 2]]
    return vertices, np.array(faces, dtype=np.int64), np.stack([s, t], axis=1)


def lit_square():
    """12 × 12 texels, black but the middle 4 × 4: on `ceiling` (nearest
    filtering) exactly the unit square [0, 1]² lit with LIT."""
    image = np.zeros((12, 12, 3))
    image[4:8, 4:8] = LIT
    return image


def lambert(radiance, corners, x, n):
    """Irradiance at x (normal n) from a polygon of constant radiance."""
    u = corners - x
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    total = 0.0
    for i in range(len(u)):
        a, b = u[i], u[(i + 1) % len(u)]
        g = np.cross(a, b)
        total += np.arccos(np.clip(a @ b, -1, 1)) * (n @ (g / np.linalg.norm(g)))
    return radiance * 0.5 * abs(total)


SQUARE = np.array([[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=np.float64)
X = np.array([0.3, 0.4, 0.0])
N = np.array([0.3, 0.1, 1.0]) / np.linalg.norm([0.3, 0.1, 1.0])


def estimate(s, twin=False):
    """Red-channel irradiance at X per sample: Le cos / pdf_ω (or, the wrong
    twin, the area pdf used as if it were solid angle)."""
    pdf = s["pdf_area"] if twin else s["pdf_solid_angle"]
    cos = np.clip(s["direction"] @ N, 0, None)
    ok = s["pdf_solid_angle"] > 0
    out = np.zeros(len(pdf))
    out[ok] = s["radiance"][ok, 0] * cos[ok] / pdf[ok]
    return out


@pytest.mark.parametrize("strategy", STRATEGIES)
def test_next_event_estimates_match_the_closed_form(strategy):
    v, f, uv = ceiling()
    e = trilux.Emitter((v, f), lit_square(), uv=uv, filter="nearest", strategy=strategy)
    assert e.strategy == strategy and not e.two_sided
    s = e.sample(200_000, X, seed=3)
    want = lambert(LIT[0], SQUARE, X, N)
    values = estimate(s)
    mean, se = values.mean(), values.std(ddof=1) / np.sqrt(len(values))
    assert abs(mean - want) < 4 * se and se < 0.015 * want, (mean, se, want)
    wrong = estimate(s, twin=True)
    assert abs(wrong.mean() - want) > 10 * wrong.std(ddof=1) / np.sqrt(len(wrong))


@pytest.mark.parametrize("strategy", STRATEGIES)
def test_per_face_radiance_estimates_match_the_closed_form(strategy):
    v, f, _ = ceiling(4)
    radiance = np.zeros((len(f), 3))
    radiance[::3, 0] = 1.0 + 0.1 * np.arange(len(f))[::3]
    e = trilux.Emitter((v, f), face_radiance=radiance, strategy=strategy)
    want = sum(lambert(radiance[k, 0], v[f[k]], X, N) for k in range(0, len(f), 3))
    values = estimate(e.sample(100_000, X, seed=5))
    mean, se = values.mean(), values.std(ddof=1) / np.sqrt(len(values))
    assert abs(mean - want) < 4 * se and se < 0.02 * want
    area = 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
    y = radiance @ [0.2126, 0.7152, 0.0722]
    assert np.allclose(e.triangle_power(), np.pi * y * area)
    assert np.isclose(e.power, np.pi * (y * area).sum())


@pytest.mark.parametrize("strategy", STRATEGIES)
def test_pdf_and_radiance_from_face_and_barycentric_equal_the_samples(strategy):
    v, f, uv = ceiling()
    e = trilux.Emitter((v, f), lit_square(), uv=uv, strategy=strategy, two_sided=strategy == "area")
    refs = np.random.default_rng(1).uniform([-1, -1, -0.5], [2, 2, 2.5], size=(5000, 3))
    s = e.sample(5000, refs, seed=2)
    face, bary = s["face_index"], s["barycentric"]
    assert np.array_equal(e.pdf(face, bary, refs), s["pdf_solid_angle"])
    assert np.array_equal(e.pdf(face, bary), s["pdf_area"])
    assert np.array_equal(e.radiance(face, bary, refs), s["radiance"])
    # Points rebuilt from (face, barycentric) are the positions.
    rebuilt = np.einsum("nk,nkd->nd", bary, v[f[face]])
    assert np.abs(rebuilt - s["positions"]).max() < 1e-5
    assert np.allclose(s["normals"], [0, 0, -1])
    # One-sided: references above the ceiling see its back.
    above = refs[:, 2] > 1
    if not e.two_sided:
        assert (s["pdf_solid_angle"][above] == 0).all()
        assert (s["radiance"][above] == 0).all()
    assert (s["pdf_area"] > 0).all()


@pytest.mark.parametrize("strategy", STRATEGIES)
def test_a_light_tree_through_sample_in_triangle_matches_the_closed_form(strategy):
    v, f, uv = ceiling()
    e = trilux.Emitter((v, f), lit_square(), uv=uv, filter="nearest", strategy=strategy)
    power = e.triangle_power()
    assert np.isclose(power.sum(), e.power)
    rng = np.random.default_rng(7)
    n = 100_000
    chosen = rng.choice(len(f), size=n, p=power / power.sum())
    s = e.sample_in_triangle(chosen, rng.uniform(0, 1, (n, 2)))
    assert np.array_equal(s["face_index"], chosen)
    assert np.array_equal(e.pdf_in_triangle(chosen, s["barycentric"]), s["pdf_area"])
    d = s["positions"] - X
    r2 = (d * d).sum(axis=1)
    w = d / np.sqrt(r2)[:, None]
    cos_light = w[:, 2]  # the normal is -z: cos at the light is w·z
    pdf = s["pdf_area"] * power[chosen] / power.sum() * r2 / cos_light
    values = s["radiance"][:, 0] * np.clip(w @ N, 0, None) / pdf
    want = lambert(LIT[0], SQUARE, X, N)
    mean, se = values.mean(), values.std(ddof=1) / np.sqrt(n)
    assert abs(mean - want) < 4 * se and se < 0.015 * want, (mean, se, want)


def test_triangle_bounds_hold_the_triangles():
    v, f, uv = ceiling(3)
    e = trilux.Emitter((v + [10, 0, 0], f), lit_square(), uv=uv)
    lower, upper, normal = e.triangle_bounds()
    corners = v[f] + [10, 0, 0]
    assert np.allclose(lower, corners.min(axis=1)) and np.allclose(upper, corners.max(axis=1))
    assert np.allclose(normal, [0, 0, -1])
    lit = int(np.argmax(e.triangle_power()))
    with pytest.raises(trilux.InputError, match=r"u: row 0 is \[1.5, 0\]"):
        e.sample_in_triangle([lit], [[1.5, 0.0]])
    with pytest.raises(trilux.InputError, match="entry 0: triangle 0 has no area or no emission"):
        e.sample_in_triangle([0], [[0.5, 0.5]])


def test_far_from_the_origin_the_same_estimate():
    v, f, uv = ceiling()
    shift = np.array([1e6, -2e6, 5e5])
    near = trilux.Emitter((v, f), lit_square(), uv=uv, filter="nearest")
    far = trilux.Emitter((v + shift, f), lit_square(), uv=uv, filter="nearest")
    a = near.sample(20_000, X, seed=9)
    b = far.sample(20_000, X + shift, seed=9)
    assert np.abs(b["positions"] - shift - a["positions"]).max() < 1e-3
    assert np.allclose(a["pdf_solid_angle"], b["pdf_solid_angle"], rtol=1e-3)
    assert np.allclose(
        far.pdf(b["face_index"], b["barycentric"], X + shift), b["pdf_solid_angle"]
    )


def test_seeds_and_scale():
    v, f, uv = ceiling()
    e = trilux.Emitter((v, f), lit_square(), uv=uv, scale=3.0)
    a, b = e.sample(1000, seed=4), e.sample(1000, seed=4)
    assert all(np.array_equal(a[k], b[k]) for k in a)
    assert not np.array_equal(a["positions"], e.sample(1000, seed=5)["positions"])
    plain = trilux.Emitter((v, f), lit_square(), uv=uv)
    assert np.isclose(e.power, 3 * plain.power)
    assert np.isclose(e.triangle_power().sum(), e.power)
    assert set(a) == {
        "positions", "normals", "shading_normals", "face_index", "barycentric", "radiance", "pdf_area"
    }
    assert "Emitter(50 faces" in repr(e)


def test_bad_input_raises_input_errors_naming_the_argument():
    v, f, uv = ceiling(2)
    image = lit_square()
    with pytest.raises(trilux.InputError, match="exactly one of emission"):
        trilux.Emitter((v, f), image, uv=uv, face_radiance=np.ones((8, 3)))
    with pytest.raises(trilux.InputError, match="exactly one of emission"):
        trilux.Emitter((v, f), uv=uv)
    with pytest.raises(trilux.InputError, match="strategy"):
        trilux.Emitter((v, f), image, uv=uv, strategy="uniform")
    with pytest.raises(trilux.InputError, match="scale"):
        trilux.Emitter((v, f), image, uv=uv, scale=-1.0)
    with pytest.raises(trilux.InputError, match="texture coordinates"):
        trilux.Emitter((v, f), image)
    with pytest.raises(trilux.InputError, match=r"emission texel \(1, 0\) has B = -1"):
        negative = np.ones((2, 2, 3))
        negative[0, 1, 2] = -1
        trilux.Emitter((v, f), negative, uv=uv)
    with pytest.raises(trilux.InputError, match="zero everywhere"):
        trilux.Emitter((v, f), np.zeros((4, 4, 3)), uv=uv)
    with pytest.raises(trilux.InputError, match="face 2"):
        bad = np.ones((8, 3))
        bad[2, 1] = -1
        trilux.Emitter((v, f), face_radiance=bad)
    with pytest.raises(trilux.InputError, match="3 given for 8 faces"):
        trilux.Emitter((v, f), face_radiance=np.ones((3, 3)))
    with pytest.raises(trilux.InputError, match="wrap"):
        trilux.Emitter((v, f), face_radiance=np.ones((8, 3)), wrap="clamp")
    e = trilux.Emitter((v, f), image, uv=uv)
    with pytest.raises(trilux.InputError, match="entry 1 is 8"):
        e.pdf([0, 8], [[1, 0, 0], [1, 0, 0]])
    with pytest.raises(trilux.InputError, match="2 rows for 1 entries"):
        e.pdf([0], [[1, 0, 0], [1, 0, 0]])
    with pytest.raises(trilux.InputError, match="reference_points: 2 points for 3 samples"):
        e.sample(3, np.zeros((2, 3)))
    with pytest.raises(trilux.InputError, match="not finite"):
        e.sample(3, [np.nan, 0, 0])
    with pytest.raises(trilux.FileError):
        trilux.Emitter((v, f), "no-such-image.exr", uv=uv)


def test_the_readme_light_sampling_example_runs_as_written():
    """The README's light-sampling block, with the README's HDR image: its
    pdfs and radiance from (face, barycentric) are the samples'."""
    import pathlib
    import re

    text = (pathlib.Path(__file__).resolve().parent.parent / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    (block,) = [b for b in blocks if b.startswith("# A 1 × 1 panel at z = 1")]
    hdr = np.full((256, 512, 3), 0.5, np.float32)
    hdr[60:64, 300:304] = 5e4
    ns = {"np": np, "trilux": trilux, "hdr_image": hdr}
    exec(block, ns)
    s = ns["s"]
    assert np.array_equal(ns["pdf_light"], s["pdf_solid_angle"])
    assert np.array_equal(ns["le"], s["radiance"])
    assert np.isclose(ns["weights"].sum(), ns["light"].power)
    assert (ns["irradiance"] > 0).all()


@pytest.mark.skipif(not hasattr(__import__("os"), "fork"), reason="needs os.fork")
def test_a_forked_child_gets_an_error_not_a_hang():
    import os
    import warnings

    v, f, uv = ceiling(2)
    e = trilux.Emitter((v, f), lit_square(), uv=uv)
    read, write = os.pipe()
    with warnings.catch_warnings():
        # Python 3.12+ warns that forking a threaded process may deadlock:
        # what this test shows the emitter does not do.
        warnings.simplefilter("ignore", DeprecationWarning)
        pid = os.fork()
    if pid == 0:  # the child: no thread holds the emitter here
        try:
            e.sample(10)
            os.write(write, b"no error")
        except trilux.InputError as err:
            os.write(write, str(err).encode())
        finally:
            os._exit(0)
    os.close(write)
    message = os.read(read, 1000).decode()
    os.waitpid(pid, 0)
    assert "another process" in message, message
    assert len(e.sample(10)["positions"]) == 10  # the parent's still works
