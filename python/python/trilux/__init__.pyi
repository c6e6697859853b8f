# Type stubs of trilux (the compiled module trilux._trilux, re-exported).
# Kept in sync with the module by tests/test_stubs.py (names, signatures,
# and an overload per value of every `return_*` flag, plus a plain-`bool`
# fallback), and checked by `mypy --strict` on tests/typing_usage.py.
import os
from typing import Any, Literal, Mapping, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
PathLike = Union[str, "os.PathLike[str]"]
F64 = npt.NDArray[np.float64]
F32 = npt.NDArray[np.float32]
I64 = npt.NDArray[np.int64]
MeshLike = Any
Channel = Union[Literal["r", "g", "b", "a", "luminance"], int]
Method = Literal["uniform", "subdivision", "exact", "rejection"]
Packing = Literal["dense", "elimination"]
Strategy = Literal["area", "triangle-power", "texture", "texture-exact"]
Wrap = Literal["repeat", "mirror", "clamp"]
Filter = Literal["bilinear", "nearest"]
MediumLike = Union[str, Tuple[Sequence[float], Sequence[float]]]
# What sample_surface / blue_noise return when the flags are plain bools.
PointArrays = Union[
    Tuple[F64, I64],
    Tuple[F64, I64, F64],
    Tuple[F64, I64, F64, F64],
    Tuple[F64, I64, F64, F64, F64],
]

class Error(Exception): ...
class InputError(Error, ValueError): ...
class FileError(Error, OSError): ...
class InternalError(Error, RuntimeError): ...

class Mesh:
    def __init__(
        self,
        vertices: ArrayLike,
        faces: ArrayLike,
        uv: Optional[ArrayLike] = None,
        normals: Optional[ArrayLike] = None,
    ) -> None: ...
    @property
    def vertices(self) -> F64: ...
    @property
    def faces(self) -> I64: ...
    @property
    def uv(self) -> Optional[F64]: ...
    @property
    def normals(self) -> Optional[F64]: ...
    # A glTF file's COLOR_0 (float32 (n, 3), or (n, 4) when an alpha is not
    # 1) and _NAME attributes (names without the underscore, float32 (n,) or
    # (n, k)); None and {} for other files.
    @property
    def colors(self) -> Optional[F32]: ...
    @property
    def attributes(self) -> dict[str, F32]: ...
    @property
    def origin(self) -> F64: ...
    @property
    def materials(self) -> list[dict[str, Any]]: ...
    @property
    def objects(self) -> list[Tuple[str, int, int, Optional[int]]]: ...
    @property
    def warnings(self) -> list[str]: ...

def load(path: PathLike) -> Mesh: ...
# save / save_points: colors and attributes go into glTF files (.glb, .gltf)
# only: colors (n, 3) or (n, 4), floats in [0, 1] (linear; within 1e-5 of it
# clamped) or uint8 (sRGB); attributes {name: (n,) or (n, k) array, k from 1
# to 4}, stored as float32 (integers must be exact in it) under _NAME.
def save(
    path: PathLike,
    mesh: MeshLike,
    *,
    colors: Optional[ArrayLike] = None,
    attributes: Optional[Mapping[str, ArrayLike]] = None,
) -> None: ...

# sample_surface / blue_noise return (points, face_index) and then, in this
# order, barycentric, pdf and normals for each flag that is True: all float64,
# so the type only depends on how many flags are set.
@overload
def sample_surface(
    mesh: MeshLike,
    count: int,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    return_barycentric: Literal[False] = False,
    return_pdf: Literal[False] = False,
    return_normal: Literal[False] = False,
) -> Tuple[F64, I64]: ...
@overload
def sample_surface(
    mesh: MeshLike,
    count: int,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    return_barycentric: Literal[False] = False,
    return_pdf: Literal[False] = False,
    return_normal: Literal[True],
) -> Tuple[F64, I64, F64]: ...
@overload
def sample_surface(
    mesh: MeshLike,
    count: int,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    return_barycentric: Literal[False] = False,
    return_pdf: Literal[True],
    return_normal: Literal[False] = False,
) -> Tuple[F64, I64, F64]: ...
@overload
def sample_surface(
    mesh: MeshLike,
    count: int,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    return_barycentric: Literal[False] = False,
    return_pdf: Literal[True],
    return_normal: Literal[True],
) -> Tuple[F64, I64, F64, F64]: ...
@overload
def sample_surface(
    mesh: MeshLike,
    count: int,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    return_barycentric: Literal[True],
    return_pdf: Literal[False] = False,
    return_normal: Literal[False] = False,
) -> Tuple[F64, I64, F64]: ...
@overload
def sample_surface(
    mesh: MeshLike,
    count: int,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    return_barycentric: Literal[True],
    return_pdf: Literal[False] = False,
    return_normal: Literal[True],
) -> Tuple[F64, I64, F64, F64]: ...
@overload
def sample_surface(
    mesh: MeshLike,
    count: int,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    return_barycentric: Literal[True],
    return_pdf: Literal[True],
    return_normal: Literal[False] = False,
) -> Tuple[F64, I64, F64, F64]: ...
@overload
def sample_surface(
    mesh: MeshLike,
    count: int,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    return_barycentric: Literal[True],
    return_pdf: Literal[True],
    return_normal: Literal[True],
) -> Tuple[F64, I64, F64, F64, F64]: ...
@overload
def sample_surface(
    mesh: MeshLike,
    count: int,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    return_barycentric: bool = False,
    return_pdf: bool = False,
    return_normal: bool = False,
) -> PointArrays: ...
@overload
def blue_noise(
    mesh: MeshLike,
    count: Optional[int] = None,
    *,
    radius: Optional[float] = None,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    progressive: bool = False,
    packing: Optional[Packing] = None,
    return_barycentric: Literal[False] = False,
    return_pdf: Literal[False] = False,
    return_normal: Literal[False] = False,
) -> Tuple[F64, I64]: ...
@overload
def blue_noise(
    mesh: MeshLike,
    count: Optional[int] = None,
    *,
    radius: Optional[float] = None,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    progressive: bool = False,
    packing: Optional[Packing] = None,
    return_barycentric: Literal[False] = False,
    return_pdf: Literal[False] = False,
    return_normal: Literal[True],
) -> Tuple[F64, I64, F64]: ...
@overload
def blue_noise(
    mesh: MeshLike,
    count: Optional[int] = None,
    *,
    radius: Optional[float] = None,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    progressive: bool = False,
    packing: Optional[Packing] = None,
    return_barycentric: Literal[False] = False,
    return_pdf: Literal[True],
    return_normal: Literal[False] = False,
) -> Tuple[F64, I64, F64]: ...
@overload
def blue_noise(
    mesh: MeshLike,
    count: Optional[int] = None,
    *,
    radius: Optional[float] = None,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    progressive: bool = False,
    packing: Optional[Packing] = None,
    return_barycentric: Literal[False] = False,
    return_pdf: Literal[True],
    return_normal: Literal[True],
) -> Tuple[F64, I64, F64, F64]: ...
@overload
def blue_noise(
    mesh: MeshLike,
    count: Optional[int] = None,
    *,
    radius: Optional[float] = None,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    progressive: bool = False,
    packing: Optional[Packing] = None,
    return_barycentric: Literal[True],
    return_pdf: Literal[False] = False,
    return_normal: Literal[False] = False,
) -> Tuple[F64, I64, F64]: ...
@overload
def blue_noise(
    mesh: MeshLike,
    count: Optional[int] = None,
    *,
    radius: Optional[float] = None,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    progressive: bool = False,
    packing: Optional[Packing] = None,
    return_barycentric: Literal[True],
    return_pdf: Literal[False] = False,
    return_normal: Literal[True],
) -> Tuple[F64, I64, F64, F64]: ...
@overload
def blue_noise(
    mesh: MeshLike,
    count: Optional[int] = None,
    *,
    radius: Optional[float] = None,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    progressive: bool = False,
    packing: Optional[Packing] = None,
    return_barycentric: Literal[True],
    return_pdf: Literal[True],
    return_normal: Literal[False] = False,
) -> Tuple[F64, I64, F64, F64]: ...
@overload
def blue_noise(
    mesh: MeshLike,
    count: Optional[int] = None,
    *,
    radius: Optional[float] = None,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    progressive: bool = False,
    packing: Optional[Packing] = None,
    return_barycentric: Literal[True],
    return_pdf: Literal[True],
    return_normal: Literal[True],
) -> Tuple[F64, I64, F64, F64, F64]: ...
@overload
def blue_noise(
    mesh: MeshLike,
    count: Optional[int] = None,
    *,
    radius: Optional[float] = None,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_weight: Optional[ArrayLike] = None,
    vertex_weight: Optional[ArrayLike] = None,
    method: Optional[Method] = None,
    seed: Optional[int] = None,
    progressive: bool = False,
    packing: Optional[Packing] = None,
    return_barycentric: bool = False,
    return_pdf: bool = False,
    return_normal: bool = False,
) -> PointArrays: ...
def sample_surface_even(
    mesh: MeshLike, count: int, radius: Optional[float] = None, seed: Optional[int] = None
) -> Tuple[F64, I64]: ...

class Distribution1D:
    def __init__(self, weights: ArrayLike) -> None: ...
    def sample(self, n: int, seed: Optional[int] = None) -> I64: ...
    def sample_u(self, u: ArrayLike) -> I64: ...
    def pdf(self, index: ArrayLike) -> F64: ...
    def invert(self, index: ArrayLike) -> F64: ...
    def __len__(self) -> int: ...

class Distribution2D:
    def __init__(self, image: ArrayLike) -> None: ...
    @staticmethod
    def from_equirect(image: ArrayLike) -> Distribution2D: ...
    @property
    def shape(self) -> Tuple[int, int]: ...
    def sample(self, n: int, seed: Optional[int] = None) -> Tuple[F64, F64]: ...
    def sample_u(self, u: ArrayLike) -> Tuple[F64, F64]: ...
    def pdf(self, points: ArrayLike) -> F64: ...
    def sample_direction(self, n: int, seed: Optional[int] = None) -> Tuple[F64, F64]: ...
    def pdf_direction(self, directions: ArrayLike) -> F64: ...

class Emitter:
    def __init__(
        self,
        mesh: MeshLike,
        emission: Optional[Union[ArrayLike, PathLike]] = None,
        *,
        face_radiance: Optional[ArrayLike] = None,
        uv: Optional[ArrayLike] = None,
        scale: float = 1.0,
        strategy: Optional[Strategy] = None,
        two_sided: bool = False,
        wrap: Optional[Wrap] = None,
        filter: Optional[Filter] = None,
    ) -> None: ...
    @property
    def power(self) -> float: ...
    @property
    def strategy(self) -> Strategy: ...
    @property
    def two_sided(self) -> bool: ...
    @property
    def defensive_fraction(self) -> float: ...
    def triangle_power(self) -> F64: ...
    def sample(
        self, n: int, reference_points: Optional[ArrayLike] = None, *, seed: Optional[int] = None
    ) -> dict[str, npt.NDArray[Any]]: ...
    def pdf(
        self, face_index: ArrayLike, barycentric: ArrayLike, reference_points: Optional[ArrayLike] = None
    ) -> F64: ...
    def radiance(
        self, face_index: ArrayLike, barycentric: ArrayLike, reference_points: Optional[ArrayLike] = None
    ) -> F64: ...
    def sample_in_triangle(self, face_index: ArrayLike, u: ArrayLike) -> dict[str, npt.NDArray[Any]]: ...
    def pdf_in_triangle(self, face_index: ArrayLike, barycentric: ArrayLike) -> F64: ...
    def triangle_bounds(self) -> Tuple[F64, F64, F64]: ...

class MeshColors:
    @staticmethod
    def from_texture(
        mesh: MeshLike,
        image: Union[ArrayLike, PathLike, None] = None,
        *,
        density: float = 1.0,
        max_level: int = 8,
        max_samples: Optional[int] = None,
    ) -> MeshColors: ...
    @staticmethod
    def load(path: PathLike, mesh: MeshLike) -> MeshColors: ...
    def save(self, path: PathLike) -> None: ...
    def lookup(
        self,
        face: ArrayLike,
        barycentric: ArrayLike,
        *,
        filter: Literal["linear", "nearest", "mip"] = "linear",
        footprint: Optional[ArrayLike] = None,
    ) -> F32: ...
    def bake(self, *, gutter: int = 1) -> Tuple[Mesh, F32]: ...
    @property
    def channels(self) -> int: ...
    @property
    def face_count(self) -> int: ...
    @property
    def sample_count(self) -> int: ...
    @property
    def resolutions(self) -> I64: ...
    @property
    def samples(self) -> F32: ...
    @property
    def vertices(self) -> F64: ...
    @property
    def faces(self) -> I64: ...

# scatter: points by rate (a Poisson process of rate × density points per
# unit area; the count is random); returns as sample_surface does, the pdf
# being the intensity rate × density at each point.
@overload
def scatter(
    mesh: MeshLike,
    rate: float,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_density: Optional[ArrayLike] = None,
    vertex_density: Optional[ArrayLike] = None,
    max_density: Optional[float] = None,
    clamp: bool = False,
    seed: Optional[int] = None,
    return_barycentric: Literal[False] = False,
    return_pdf: Literal[False] = False,
    return_normal: Literal[False] = False,
) -> Tuple[F64, I64]: ...
@overload
def scatter(
    mesh: MeshLike,
    rate: float,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_density: Optional[ArrayLike] = None,
    vertex_density: Optional[ArrayLike] = None,
    max_density: Optional[float] = None,
    clamp: bool = False,
    seed: Optional[int] = None,
    return_barycentric: Literal[False] = False,
    return_pdf: Literal[False] = False,
    return_normal: Literal[True],
) -> Tuple[F64, I64, F64]: ...
@overload
def scatter(
    mesh: MeshLike,
    rate: float,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_density: Optional[ArrayLike] = None,
    vertex_density: Optional[ArrayLike] = None,
    max_density: Optional[float] = None,
    clamp: bool = False,
    seed: Optional[int] = None,
    return_barycentric: Literal[False] = False,
    return_pdf: Literal[True],
    return_normal: Literal[False] = False,
) -> Tuple[F64, I64, F64]: ...
@overload
def scatter(
    mesh: MeshLike,
    rate: float,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_density: Optional[ArrayLike] = None,
    vertex_density: Optional[ArrayLike] = None,
    max_density: Optional[float] = None,
    clamp: bool = False,
    seed: Optional[int] = None,
    return_barycentric: Literal[False] = False,
    return_pdf: Literal[True],
    return_normal: Literal[True],
) -> Tuple[F64, I64, F64, F64]: ...
@overload
def scatter(
    mesh: MeshLike,
    rate: float,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_density: Optional[ArrayLike] = None,
    vertex_density: Optional[ArrayLike] = None,
    max_density: Optional[float] = None,
    clamp: bool = False,
    seed: Optional[int] = None,
    return_barycentric: Literal[True],
    return_pdf: Literal[False] = False,
    return_normal: Literal[False] = False,
) -> Tuple[F64, I64, F64]: ...
@overload
def scatter(
    mesh: MeshLike,
    rate: float,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_density: Optional[ArrayLike] = None,
    vertex_density: Optional[ArrayLike] = None,
    max_density: Optional[float] = None,
    clamp: bool = False,
    seed: Optional[int] = None,
    return_barycentric: Literal[True],
    return_pdf: Literal[False] = False,
    return_normal: Literal[True],
) -> Tuple[F64, I64, F64, F64]: ...
@overload
def scatter(
    mesh: MeshLike,
    rate: float,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_density: Optional[ArrayLike] = None,
    vertex_density: Optional[ArrayLike] = None,
    max_density: Optional[float] = None,
    clamp: bool = False,
    seed: Optional[int] = None,
    return_barycentric: Literal[True],
    return_pdf: Literal[True],
    return_normal: Literal[False] = False,
) -> Tuple[F64, I64, F64, F64]: ...
@overload
def scatter(
    mesh: MeshLike,
    rate: float,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_density: Optional[ArrayLike] = None,
    vertex_density: Optional[ArrayLike] = None,
    max_density: Optional[float] = None,
    clamp: bool = False,
    seed: Optional[int] = None,
    return_barycentric: Literal[True],
    return_pdf: Literal[True],
    return_normal: Literal[True],
) -> Tuple[F64, I64, F64, F64, F64]: ...
@overload
def scatter(
    mesh: MeshLike,
    rate: float,
    *,
    density: Union[ArrayLike, PathLike, None] = None,
    uv: Optional[ArrayLike] = None,
    channel: Optional[Channel] = None,
    face_density: Optional[ArrayLike] = None,
    vertex_density: Optional[ArrayLike] = None,
    max_density: Optional[float] = None,
    clamp: bool = False,
    seed: Optional[int] = None,
    return_barycentric: bool = False,
    return_pdf: bool = False,
    return_normal: bool = False,
) -> PointArrays: ...

Scalars = Union[float, ArrayLike]

def grow_hair(
    mesh: MeshLike,
    face_index: ArrayLike,
    barycentric: ArrayLike,
    length: Scalars,
    *,
    segments: int = 8,
    comb: Optional[ArrayLike] = None,
    comb_angle: Optional[Scalars] = None,  # degrees from the normal, 0 to 180 (as --hair-comb)
    curl_radius: Optional[Scalars] = None,
    curl_turns: Optional[Scalars] = None,
    noise: Optional[Scalars] = None,
    clumps: int = 0,
    clump: Optional[Scalars] = None,
    width: Optional[Scalars] = None,
    tip_width: Optional[Scalars] = None,
    seed: Optional[int] = None,
    path: Optional[PathLike] = None,
) -> dict[str, Any]: ...

@overload
def tetrahedralize(
    mesh: MeshLike,
    *,
    spacing: Optional[float] = None,
    graded: bool = False,
    envelope: Optional[float] = None,
    return_report: Literal[False] = False,
) -> Tuple[F64, I64]: ...
@overload
def tetrahedralize(
    mesh: MeshLike,
    *,
    spacing: Optional[float] = None,
    graded: bool = False,
    envelope: Optional[float] = None,
    return_report: Literal[True],
) -> Tuple[F64, I64, dict[str, Any]]: ...
@overload
def tetrahedralize(
    mesh: MeshLike,
    *,
    spacing: Optional[float] = None,
    graded: bool = False,
    envelope: Optional[float] = None,
    return_report: bool = False,
) -> Union[Tuple[F64, I64], Tuple[F64, I64, dict[str, Any]]]: ...
# load_tets: the tets as the file stores them, in its node order, not
# re-oriented (a tet may have negative signed volume, det[p1 - p0, p2 - p0,
# p3 - p0] < 0); trilux.Object accepts either orientation and re-orients an
# inverted tet by swapping its first two nodes.
@overload
def load_tets(path: PathLike, *, return_warnings: Literal[False] = False) -> Tuple[F64, I64]: ...
@overload
def load_tets(path: PathLike, *, return_warnings: Literal[True]) -> Tuple[F64, I64, list[str]]: ...
@overload
def load_tets(
    path: PathLike, *, return_warnings: bool = False
) -> Union[Tuple[F64, I64], Tuple[F64, I64, list[str]]]: ...
def save_tets(path: PathLike, nodes: ArrayLike, tets: ArrayLike) -> None: ...
def save_points(
    path: PathLike,
    points: ArrayLike,
    *,
    normals: Optional[ArrayLike] = None,
    face_index: Optional[ArrayLike] = None,
    colors: Optional[ArrayLike] = None,
    attributes: Optional[Mapping[str, ArrayLike]] = None,
) -> None: ...

class Points:
    """A point cloud read by load_points: properties named as save_points'
    arguments (None, or {}, when the file has none of them)."""

    @property
    def points(self) -> F64: ...
    @property
    def normals(self) -> Optional[F64]: ...
    @property
    def face_index(self) -> Optional[I64]: ...
    @property
    def colors(self) -> Optional[F32]: ...
    @property
    def attributes(self) -> dict[str, F32]: ...
    @property
    def uv(self) -> Optional[F64]: ...
    @property
    def origin(self) -> F64: ...
    @property
    def warnings(self) -> list[str]: ...
    def __len__(self) -> int: ...

def load_points(path: PathLike) -> Points: ...
def media() -> list[str]: ...

class Object:
    """A translucent object (TransCut). Tets may come in either
    orientation: an inverted one (negative signed volume,
    det[p1 - p0, p2 - p0, p3 - p0] < 0) is re-oriented by swapping its
    first two nodes, so `mesh` returns every tet with positive volume; a
    tet of zero volume, a repeated, unused or NaN node raises InputError.
    `solve` warns (UserWarning, one per colour channel) when the mesh is
    too coarse to resolve a medium's diffusion length; `render`, `radiance` and `fluence` warn when the object was
    not solved since it was made or changed."""

    def __init__(
        self,
        nodes: ArrayLike,
        tets: ArrayLike,
        *,
        medium: Optional[MediumLike] = None,
        unit_mm: float = 1.0,
        eta: float = 1.3,
    ) -> None: ...
    def add_light(
        self,
        direction: Optional[Sequence[float]] = None,
        *,
        irradiance: Tuple[float, float, float] = (1.0, 1.0, 1.0),
        position: Optional[Sequence[float]] = None,
        intensity: Tuple[float, float, float] = (1.0, 1.0, 1.0),
        envmap: Optional[ArrayLike] = None,
        envmap_samples: int = 256,
    ) -> int: ...
    def solve(self, solver: Literal["auto", "jacobi", "vcycle"] = "auto") -> dict[str, Any]: ...
    def radiance(self, toward: Optional[Sequence[float]] = None) -> F64: ...
    @property
    def fluence(self) -> F64: ...
    def cut(
        self,
        point: Sequence[float],
        normal: Sequence[float],
        *,
        method: Literal["exact", "relax"] = "exact",
        relax_sweeps: int = 20,
    ) -> dict[str, float]: ...
    def paint(
        self, center: Sequence[float], radius: float, medium: MediumLike, *, strength: float = 1.0
    ) -> int: ...
    def fracture(
        self, point: Sequence[float], normal: Sequence[float], *, offset: float = 0.0
    ) -> Tuple[Object, Object]: ...
    @staticmethod
    def recombine(a: Object, b: Object) -> Object: ...
    def render(
        self,
        *,
        view: Optional[Sequence[float]] = None,
        size: int = 512,
        exposure: Optional[Literal["auto"]] = "auto",
    ) -> F32: ...
    @property
    def mesh(self) -> Tuple[F64, I64]: ...
    @property
    def boundary(self) -> I64: ...
    @property
    def boundary_vertices(self) -> I64: ...

def render(
    objects: Sequence[Object],
    *,
    view: Optional[Sequence[float]] = None,
    size: int = 512,
    exposure: Optional[Literal["auto"]] = "auto",
) -> F32: ...
