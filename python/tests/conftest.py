"""Shared fixtures: the data folder, small meshes, and the Rust reference
binary (python/examples/reference.rs) that the bit-for-bit tests compare
against."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

HERE = pathlib.Path(__file__).resolve().parent
WORKSPACE = HERE.parent.parent


def data_dir():
    """$TRILUX_DATA (relative to the workspace, as CI sets it), or None."""
    value = os.environ.get("TRILUX_DATA")
    if not value:
        return None
    path = pathlib.Path(value)
    if not path.is_absolute():
        path = WORKSPACE / path
    return path if path.is_dir() else None


@pytest.fixture(scope="session")
def data():
    path = data_dir()
    if path is None:
        pytest.skip("TRILUX_DATA is not set: the real-data tests are skipped")
    return path


@pytest.fixture(scope="session")
def reference_bin():
    """The reference example, built by .ci/run (TRILUX_REFERENCE_BIN) or here."""
    path = os.environ.get("TRILUX_REFERENCE_BIN")
    if path:
        return pathlib.Path(path)
    subprocess.run(
        ["cargo", "build", "-q", "-p", "trilux-python", "--example", "reference"],
        cwd=WORKSPACE,
        check=True,
    )
    return WORKSPACE / "target" / "debug" / "examples" / "reference"


def grid(n=8):
    """A wavy n×n grid of 2 n² triangles with UVs (OpenGL convention), whose
    triangles differ in area: float64 vertices, int64 faces."""
    u, v = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    u, v = u.ravel(), v.ravel()
    x = u + 0.3 * u**2
    z = 0.1 * np.sin(3 * v)
    vertices = np.stack([x, v, z], axis=1)
    faces = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 1, a + n + 2
            faces += [[a, b, d], [a, d, c]]
    return vertices, np.array(faces, dtype=np.int64), np.stack([u, v], axis=1)


def areas(vertices, faces):
    t = vertices[faces]
    return 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)


def chi_square(counts, probabilities):
    """Pearson's statistic and its degrees of freedom, cells with expected
    count >= 5 only (the rest pooled)."""
    n = counts.sum()
    expected = n * probabilities
    big = expected >= 5
    stat = (((counts[big] - expected[big]) ** 2) / expected[big]).sum()
    rest_e, rest_c = expected[~big].sum(), counts[~big].sum()
    dof = big.sum() - 1
    if rest_e > 0:
        stat += (rest_c - rest_e) ** 2 / rest_e
        dof += 1
    return stat, dof


def chi_square_critical(dof):
    """The 0.999 quantile of chi-square (Wilson–Hilferty), no scipy needed."""
    z = 3.090232306167813
    return dof * (1 - 2 / (9 * dof) + z * np.sqrt(2 / (9 * dof))) ** 3
