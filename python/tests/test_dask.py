"""The Dask example gives the serial loop's arrays, bit for bit."""

import importlib.util
import pathlib

import numpy as np
import pytest

import trilux
from conftest import grid

EXAMPLE = pathlib.Path(__file__).resolve().parent.parent / "examples" / "dask_folder.py"


def example():
    spec = importlib.util.spec_from_file_location("dask_folder", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_dask_equals_serial(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    folder = tmp_path / "meshes"
    folder.mkdir()
    v, f, uv = grid(10)
    trilux.save(folder / "grid.ply", (v, f))
    trilux.save(folder / "wavy.obj", trilux.Mesh(v * 2, f, uv=uv))
    import trimesh

    trilux.save(folder / "sphere.obj", trimesh.creation.icosphere(subdivisions=3))
    ex = example()
    serial_out, dask_out = tmp_path / "serial", tmp_path / "dask"
    serial_out.mkdir()
    dask_out.mkdir()
    serial = ex.run_serial(folder, serial_out, 20_000)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        parallel = ex.run_dask(folder, dask_out, 20_000, client)
    assert sorted(serial) == sorted(parallel) == ["grid.ply", "sphere.obj", "wavy.obj"]
    for name in serial:
        assert sorted(serial[name]) == sorted(parallel[name])
        for key in serial[name]:
            assert np.array_equal(serial[name][key], parallel[name][key]), (name, key)
        a = np.load(serial_out / f"{pathlib.Path(name).stem}.npz")
        b = np.load(dask_out / f"{pathlib.Path(name).stem}.npz")
        assert all(np.array_equal(a[k], b[k]) for k in a.files)
    # Different meshes get different seeds.
    assert not np.array_equal(serial["grid.ply"]["points"], serial["wavy.obj"]["points"] / 2)
