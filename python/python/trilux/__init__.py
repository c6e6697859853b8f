"""trilux: fast random points on meshes (Šik & Křivánek 2013), light sampling
of emissive meshes for renderers, blue noise
(Yuksel 2015), mesh colours (Yuksel, Keyser & House 2010), isosurface
stuffing (Labelle & Shewchuk 2007) and TransCut diffusion (Li et al.), over
numpy arrays.

Every function takes a ``trilux.Mesh``, a ``trimesh.Trimesh`` (anything with
``.vertices`` and ``.faces``) or a ``(vertices, faces)`` pair, and returns
numpy arrays: float64 positions, int64 indices. Errors are ``trilux.Error``
subclasses (``InputError`` is a ``ValueError``, ``FileError`` an
``OSError``) carrying the Rust message. Heavy calls release the GIL.
"""

from ._trilux import (
    Distribution1D,
    Distribution2D,
    Emitter,
    Error,
    FileError,
    InputError,
    InternalError,
    Mesh,
    MeshColors,
    Object,
    Points,
    __version__,
    blue_noise,
    grow_hair,
    load,
    load_points,
    load_tets,
    media,
    render,
    sample_surface,
    sample_surface_even,
    save,
    save_points,
    save_tets,
    scatter,
    tetrahedralize,
)

__all__ = [
    "Distribution1D",
    "Distribution2D",
    "Emitter",
    "Error",
    "FileError",
    "InputError",
    "InternalError",
    "Mesh",
    "MeshColors",
    "Object",
    "Points",
    "__version__",
    "blue_noise",
    "grow_hair",
    "load",
    "load_points",
    "load_tets",
    "media",
    "render",
    "sample_surface",
    "sample_surface_even",
    "save",
    "save_points",
    "save_tets",
    "scatter",
    "tetrahedralize",
]
