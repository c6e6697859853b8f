//! Tetrahedral meshes from triangle surfaces: isosurface stuffing
//! (Labelle & Shewchuk 2007, "Isosurface Stuffing: Fast Tetrahedral Meshes
//! with Good Dihedral Angles", SIGGRAPH) of the 1/2 level set of the
//! generalized winding number (Jacobson, Kavan & Sorkine-Hornung 2013),
//! evaluated with the fast hierarchical approximation of Barill et al. 2018.
//!
//! Takes the surfaces people have — closed or with holes, several
//! overlapping parts, flipped patches — and returns a mesh whose dihedral
//! angles are bounded by the chosen [`Params`]: no slivers, so cotangent
//! weights stay bounded (TransCut Sec. 6).
//!
//! Steps ([`tetrahedralize`]):
//! 1. inside/outside at the vertices of a body-centred cubic (BCC) lattice
//!    of spacing `h` by the winding number `w > 1/2` ([`winding`]);
//! 2. cut points where lattice edges cross the 1/2 level set (on the input
//!    triangles where it runs along them, by bisection across holes);
//! 3. warping of lattice vertices too close to a cut point (the α
//!    thresholds of [`Params`]);
//! 4. stencils that fill each lattice tetrahedron with its inside part,
//!    splitting shared quadrilaterals by the paper's parity rule;
//! 5. optionally ([`Options::graded`]) coarser, octree-graded tetrahedra
//!    deep inside, with the fine BCC lattice kept near the surface;
//! 6. optionally ([`Options::envelope`]) boundary vertices moved onto the
//!    tips, creases and thin parts of the input the lattice cut across,
//!    and boundary edges split where no vertex could move far enough,
//!    each move and split kept only if the tetrahedra around it keep
//!    10°–165°.
//!
//! The crate depends on `glam`, `rayon`, `thiserror` and `std` only: a
//! user who wants tetrahedra from a surface gets no solver, sparse-matrix
//! or BVH crate (the winding-number tree of [`winding`] is its own, a few
//! hundred lines). Its output is plain data (`Vec<DVec3>`, `Vec<[u32; 4]>`)
//! that `tet-diffusion`, `trilux-io`'s writers or any FEM code take as is.
//!
//! # Example
//! ```
//! use tet_stuffing::{self as stuffing, Options};
//! use tet_stuffing::glam::DVec3;
//! // A cube of side 1 with outward (counter-clockwise) faces.
//! let p: Vec<DVec3> = (0..8)
//!     .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
//!     .collect();
//! let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
//! let tris: Vec<[u32; 3]> = quads
//!     .iter()
//!     .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
//!     .collect();
//! let mesh = stuffing::tetrahedralize(&p, &tris, &Options::new(0.2)).unwrap();
//! let (lo, hi) = stuffing::Params::Angles10_7.dihedral_bounds_deg();
//! assert!(mesh.report.min_dihedral_deg >= lo && mesh.report.max_dihedral_deg <= hi);
//! let volume: f64 = mesh.tets.iter().map(|t| {
//!     stuffing::signed_volume(t.map(|v| mesh.positions[v as usize]))
//! }).sum();
//! assert!((volume - 1.0).abs() < 0.05);
//! ```

mod bvh;
mod cuts;
mod distance;
mod envelope;
mod error;
mod graded;
mod lattice;
mod mesh;
mod quality;
mod refine;
mod stencils;
mod warp;
pub mod winding;

use std::time::{Duration, Instant};

use glam::{DVec3, Vec3};
use rayon::prelude::*;

pub use distance::{CAP_MIN_DISTANCE, CAP_WINDING, SurfaceDistance};
pub use error::Error;

pub use glam;
pub use quality::{EDGES, Quality, dihedral_angles, quality, signed_volume};

use cuts::{Cut, Sign};
use lattice::{Lattice, edge_key};
use stencils::{FaceRule, LatticeTet, Point};

/// The warping thresholds `(α_long, α_short)` of Labelle & Shewchuk 2007.
///
/// The paper's abstract gives two parameter choices, with dihedral angles
/// within 10.7°–164.8° or within 8.9°–158.8°, proved by a computer-assisted
/// search over its stencils. `α_long = 0.24999`, `α_short = 0.41189` is the
/// pair of the first bound as independent implementations of the paper
/// carry it; the second variant here uses `α_short = 0.42978`, the value
/// two of them (SOFA's `MeshTetraStuffing` defaults, a sound-synthesis
/// mesher's settings) pair with it. Only the abstract was available, so
/// the pairs could not be checked against the paper's table.
///
/// What this module guarantees is measured instead
/// ([`Params::dihedral_bounds_deg`]): the stencil test enumerates every
/// sign pattern and warp direction of a lattice tetrahedron on a grid of
/// warp distances and cut positions, plus 400,000 random ones, with the
/// paper's stencils and parity rule. It finds 9.32°–161.64° for the first
/// pair and 7.34°–164.58° for the second, so neither reproduces the
/// paper's numbers: either the pairs are not the paper's, or the paper's
/// analysis excludes configurations this test allows. The worst case of
/// the first pair is a pyramid stencil (two inside vertices, one warped,
/// one outside) whose two tetrahedra are fixed by the stencil, not a
/// choice of ours. On the data meshes the smallest angles measured are
/// 12°–18°.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Params {
    /// `α_long = 0.24999`, `α_short = 0.41189` (the paper's 10.7°–164.8°
    /// pair, see the type's docs). Measured: 9.32°–161.64°.
    #[default]
    Angles10_7,
    /// `α_long = 0.24999`, `α_short = 0.42978` (see the type's docs).
    /// Measured: 7.34°–164.58°: warps more, which here does not pay off.
    Angles8_9,
}

impl Params {
    /// `α_long`: the warping threshold on long (length `h`) lattice edges,
    /// as a fraction of the edge length.
    pub fn alpha_long(self) -> f64 {
        0.24999
    }

    /// `α_short`: the warping threshold on short (length `√3 h / 2`)
    /// lattice edges.
    pub fn alpha_short(self) -> f64 {
        match self {
            Params::Angles10_7 => 0.41189,
            Params::Angles8_9 => 0.42978,
        }
    }

    /// The `(smallest, largest)` dihedral angle, degrees, that every
    /// stencil output stays within (measured, rounded outward; see the
    /// type's docs).
    pub fn dihedral_bounds_deg(self) -> (f64, f64) {
        match self {
            Params::Angles10_7 => (9.0, 162.0),
            Params::Angles8_9 => (7.0, 165.0),
        }
    }

    /// The bounds the paper proves for its own stencils with this pair.
    pub fn paper_bounds_deg(self) -> (f64, f64) {
        match self {
            Params::Angles10_7 => (10.7, 164.8),
            Params::Angles8_9 => (8.9, 158.8),
        }
    }
}

/// Settings of [`tetrahedralize`].
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Lattice spacing `h`, in the surface's length unit: the edge length
    /// of the cubes; tetrahedra near the surface have edges of `h` and
    /// `√3 h / 2`.
    pub h: f64,
    /// The warping thresholds and the angle bounds they give.
    pub params: Params,
    /// Grade the mesh: keep tetrahedra of size `h` near the surface and use
    /// cubes of up to `2^graded_levels · h` deep inside: 32–43% of the
    /// uniform count on the data meshes at about 500k uniform tetrahedra
    /// (36% on the bunny; the `stuffing` example), with the same angle
    /// bounds.
    pub graded: bool,
    /// Coarsest level of the graded mesh (cells of `2^graded_levels · h`);
    /// 1 to 10.
    pub graded_levels: u32,
    /// Accuracy parameter β of the fast winding number (see
    /// [`winding::DEFAULT_BETA`]); at least 1.
    pub winding_beta: f64,
    /// Bound on memory and time before anything is computed: the most
    /// lattice vertices [`tetrahedralize`] may classify (about 2 bytes and
    /// one fast winding number each, a few microseconds). The default,
    /// 2^25, is a lattice of about 256³ cubes: about 20 s on 2 cores.
    pub max_lattice_vertices: usize,
    /// Bound on the output, checked once the lattice vertices are
    /// classified and before the tetrahedra are made: the most tetrahedra
    /// of the uniform mesh (6 per inside lattice vertex; a graded mesh is
    /// held to the same estimate). The pass that makes them holds about
    /// 150 bytes per tetrahedron; the default, 2^24 (16.8 million), about
    /// 2.5 GB.
    pub max_tets: usize,
    /// Points sampled on each surface (input and boundary) to measure
    /// [`Report::distance`], the symmetric Hausdorff and mean distance
    /// between them; the vertices are added when there are no more of them.
    /// 0 skips the measurement. It costs one winding number per input
    /// triangle (which ones enclose volume) and a nearest-point query per
    /// point: at the default 2^16 and 1/40 of the diagonal as spacing,
    /// 0.2–1.2× the stuffing's own time on the data meshes (the most on
    /// 100k-triangle inputs), less at finer spacings (the `stuffing`
    /// example's `--distance` table).
    pub distance_samples: usize,
    /// Fit the boundary to the input: the largest distance, as a fraction
    /// of the input's bounding-box diagonal, that an input point (where the
    /// input encloses volume) may lie from the boundary before the fit
    /// pulls the nearest boundary vertex onto it; between 0 and 1. `None`
    /// (the default) keeps the plain stuffing.
    ///
    /// Stuffing's boundary vertices lie on the input already; what it
    /// misses are tips, sharp creases (input edges between faces at less
    /// than 140°) and thin parts, which its triangles span across. The fit
    /// moves boundary vertices onto points of the input that lie farther
    /// than this from the boundary (vertices, points along creases and
    /// points spread over the area, farthest first), then projects the
    /// other boundary vertices onto the input; each move is kept only if
    /// every tetrahedron around the vertex keeps its dihedral angles within
    /// 10°–165° (or gets no worse), else a half or a quarter of it. Where
    /// no vertex can move far enough (a part 0.2–2 spacings thick, a tip),
    /// boundary edges near the far points, and near boundary points farther
    /// than this from the input, are split with the new vertex on the input
    /// (longest-edge bisection of the tetrahedra below where that is what
    /// the angle check refuses), each split kept only under the same check,
    /// up to three times the stuffed count ([`Report::split_edges`]). So
    /// the smallest angle can drop from the stuffing's to 10°, never below
    /// the lower of the two. Parts with no boundary vertex within a spacing
    /// can stay missing: it is not a guarantee, and [`Report::distance`]
    /// gives what was achieved. Costs a nearest-point query per input
    /// vertex and sample and a few rounds over the boundary (the
    /// `stuffing` example's `--envelope` table).
    pub envelope: Option<f64>,
}

impl Options {
    /// Uniform mesh of spacing `h` with the default parameters.
    pub fn new(h: f64) -> Options {
        Options {
            h,
            params: Params::default(),
            graded: false,
            graded_levels: 4,
            winding_beta: winding::DEFAULT_BETA,
            max_lattice_vertices: 1 << 25,
            max_tets: 1 << 24,
            distance_samples: 1 << 16,
            envelope: None,
        }
    }

    /// The `(smallest, largest)` dihedral angle, degrees, that every output
    /// of [`tetrahedralize`] with these options stays within, whatever the
    /// surface: the stencils' [`Params::dihedral_bounds_deg`], widened to
    /// 10°–165° by [`Options::envelope`]'s fit where it moves or splits
    /// (9°–165° with the default parameters).
    pub fn dihedral_bounds_deg(&self) -> (f64, f64) {
        let (lo, hi) = self.params.dihedral_bounds_deg();
        match self.envelope {
            Some(_) => (
                lo.min(envelope::MIN_DIHEDRAL_DEG),
                hi.max(envelope::MAX_DIHEDRAL_DEG),
            ),
            None => (lo, hi),
        }
    }
}

/// A tetrahedral mesh and how it was made.
#[derive(Debug, Clone, PartialEq)]
pub struct TetMesh {
    /// Vertex positions, in the surface's unit. Every vertex is used.
    pub positions: Vec<DVec3>,
    /// Tetrahedra, four 0-based vertex indices each, positively oriented:
    /// `(p1 - p0) · ((p2 - p0) × (p3 - p0)) > 0`.
    pub tets: Vec<[u32; 4]>,
    /// The boundary surface: faces of exactly one tetrahedron, oriented
    /// counter-clockwise seen from outside (outward normals).
    pub boundary: Vec<[u32; 3]>,
    /// Counts, quality and timing.
    pub report: Report,
}

/// What [`tetrahedralize`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// Number of tetrahedra.
    pub tets: usize,
    /// Number of vertices.
    pub vertices: usize,
    /// Number of boundary triangles.
    pub boundary_triangles: usize,
    /// Smallest dihedral angle, degrees.
    pub min_dihedral_deg: f64,
    /// Largest dihedral angle, degrees.
    pub max_dihedral_deg: f64,
    /// The `(smallest, largest)` dihedral angle, degrees, any surface gets
    /// with the options used ([`Options::dihedral_bounds_deg`]): what
    /// `min_dihedral_deg`/`max_dihedral_deg` are promised to stay within.
    pub dihedral_bounds_deg: (f64, f64),
    /// Smallest cotangent of a dihedral angle (see [`Quality::min_cot`]).
    pub min_cot: f64,
    /// Largest cotangent of a dihedral angle.
    pub max_cot: f64,
    /// Lattice vertices (the memory bound counts these).
    pub lattice_vertices: usize,
    /// Cut points computed on lattice edges.
    pub cut_points: usize,
    /// Lattice vertices warped onto the surface.
    pub warped_vertices: usize,
    /// Boundary vertices the envelope fit moved ([`Options::envelope`]; 0
    /// without it).
    pub fitted_vertices: usize,
    /// Sharp input edges (creases, faces at less than 140°) the envelope
    /// fit held the boundary to (0 without it).
    pub sharp_edges: usize,
    /// Boundary edges the envelope fit split where moving vertices could
    /// not bring the boundary within the envelope (each split adds a
    /// vertex on or towards the input and splits the tetrahedra around the
    /// edge; 0 without the envelope).
    pub split_edges: usize,
    /// How far the boundary lies from the input, both ways
    /// ([`Options::distance_samples`]; `None` when that is 0). Its time is
    /// part of [`elapsed`](Self::elapsed).
    pub distance: Option<SurfaceDistance>,
    /// Wall-clock time of the whole call.
    pub elapsed: Duration,
}

/// A position type [`tetrahedralize`] accepts.
pub trait Position: Copy {
    /// The position in double precision.
    fn to_dvec3(self) -> DVec3;
}

impl Position for DVec3 {
    fn to_dvec3(self) -> DVec3 {
        self
    }
}

impl Position for Vec3 {
    fn to_dvec3(self) -> DVec3 {
        self.as_dvec3()
    }
}

impl Position for [f32; 3] {
    fn to_dvec3(self) -> DVec3 {
        Vec3::from(self).as_dvec3()
    }
}

impl Position for [f64; 3] {
    fn to_dvec3(self) -> DVec3 {
        DVec3::from(self)
    }
}

/// Fills the inside of a triangle surface with tetrahedra.
///
/// `positions` and `triangles` (0-based, counter-clockwise seen from
/// outside) form any triangle soup: inside is where its generalized winding
/// number exceeds 1/2, so holes, separate or overlapping parts and flipped
/// patches are accepted. The result has every dihedral angle within
/// [`Params::dihedral_bounds_deg`], uniform or graded (the graded interior
/// adds tetrahedra of 45°–120°, kept within 20°–150° where vertices warped
/// onto the surface distort them, refined otherwise).
/// Same input, same output, on any number of threads.
///
/// # Performance
/// Linear in the number of lattice vertices (about `2 V / h³` over the
/// padded bounding box) times the cost of a fast winding number (about
/// `O(log n)` for `n` triangles), plus a few winding numbers per lattice
/// edge that crosses the surface; parallel over fixed chunks. On the
/// 43k-triangle closed bunny, 510k tetrahedra take 0.9 s on 2 cores, 10×
/// less than TetGen `-pq1.2` for a similar count in the same run (the
/// `stuffing` example).
///
/// # Errors
/// [`Error::NoTriangles`], [`Error::IndexOutOfRange`],
/// [`Error::NonFinitePosition`], [`Error::InvalidSpacing`] (h not a
/// positive finite length), [`Error::InvalidBeta`],
/// [`Error::InvalidGrading`], [`Error::LatticeTooLarge`] (beyond
/// [`Options::max_lattice_vertices`]), [`Error::TooManyTetrahedra`]
/// (beyond [`Options::max_tets`]), [`Error::OpenSurface`] (no triangle
/// bounds a volume: an open sheet, a single triangle),
/// [`Error::EmptyVolume`] (no lattice vertex inside a shape thinner than
/// the lattice), [`Error::InvalidEnvelope`].
pub fn tetrahedralize<P: Position>(
    positions: &[P],
    triangles: &[[u32; 3]],
    options: &Options,
) -> Result<TetMesh, Error> {
    run(positions, triangles, options, FaceRule::Parity)
}

/// [`tetrahedralize`] with a choice of quadrilateral rule (the tests run
/// the deliberately wrong one through the same pipeline).
fn run<P: Position>(
    positions: &[P],
    triangles: &[[u32; 3]],
    options: &Options,
    rule: FaceRule,
) -> Result<TetMesh, Error> {
    let start = Instant::now();
    let h = options.h;
    if !(h.is_finite() && h > 0.0) {
        return Err(Error::InvalidSpacing { h });
    }
    if options.graded && !(1..=10).contains(&options.graded_levels) {
        return Err(Error::InvalidGrading {
            what: "number of levels (1 to 10)",
            value: f64::from(options.graded_levels),
        });
    }
    if let Some(eps) = options.envelope
        && !(eps.is_finite() && eps > 0.0 && eps < 1.0)
    {
        return Err(Error::InvalidEnvelope { eps });
    }
    validate_soup(positions.len(), triangles)?;
    let pos: Vec<DVec3> = positions.iter().map(|p| p.to_dvec3()).collect();
    if let Some(v) = pos.iter().position(|p| !p.is_finite()) {
        return Err(Error::NonFinitePosition { vertex: v });
    }
    let wn = winding::WindingNumber::new(&pos, triangles, options.winding_beta)?;
    let lattice = lattice_for(&pos, triangles, options)?;
    // Which input triangles enclose volume: the fit and the measurement
    // both leave the others out. One winding number per triangle,
    // independent of the lattice, so it runs beside the stuffing and
    // fills the cores the stuffing's sequential steps leave idle.
    let needs_bounding = options.envelope.is_some() || options.distance_samples > 0;
    let (bounding, stuffed) = rayon::join(
        || {
            if needs_bounding {
                distance::bounding_triangles(&wn)
            } else {
                Vec::new()
            }
        },
        || stuff(&wn, &lattice, options, rule),
    );
    let Stuffed {
        mesh: mut m,
        cut_points,
        warped_vertices,
    } = stuffed?;
    let fitted = options.envelope.map(|eps| {
        let (lo, hi) = used_bounds(&pos, triangles);
        let diagonal = lo.distance(hi);
        // The refinement may triple the stuffed count (the issue's cost
        // bound), never beyond the caller's limit.
        let budget = m.tets.len().saturating_mul(3).min(options.max_tets);
        envelope::fit(&wn, &bounding, &mut m, h, eps * diagonal, budget)
    });
    let q = quality::quality(&m.positions, &m.tets);
    let distance = (options.distance_samples > 0).then(|| {
        distance::measure(
            &wn,
            &bounding,
            &m.positions,
            &m.boundary,
            options.distance_samples,
        )
    });
    let report = Report {
        tets: m.tets.len(),
        vertices: m.positions.len(),
        boundary_triangles: m.boundary.len(),
        min_dihedral_deg: q.min_dihedral_deg,
        max_dihedral_deg: q.max_dihedral_deg,
        dihedral_bounds_deg: options.dihedral_bounds_deg(),
        min_cot: q.min_cot,
        max_cot: q.max_cot,
        lattice_vertices: lattice.vertex_count(),
        cut_points,
        warped_vertices,
        fitted_vertices: fitted.map_or(0, |f| f.moved),
        sharp_edges: fitted.map_or(0, |f| f.sharp_edges),
        split_edges: fitted.map_or(0, |f| f.split_edges),
        distance,
        elapsed: start.elapsed(),
    };
    Ok(TetMesh {
        positions: m.positions,
        tets: m.tets,
        boundary: m.boundary,
        report,
    })
}

/// What the stuffing proper (steps 1–5 of the crate docs) made.
struct Stuffed {
    mesh: mesh::Assembled,
    cut_points: usize,
    warped_vertices: usize,
}

/// Steps 1–5 of the crate docs: classification, cut points, warping, the
/// stencils (and the graded interior), assembled into one mesh.
fn stuff(
    wn: &winding::WindingNumber,
    lattice: &Lattice,
    options: &Options,
    rule: FaceRule,
) -> Result<Stuffed, Error> {
    let h = options.h;
    let mut signs = cuts::classify(lattice, wn, |_| true);
    let inside = signs.iter().filter(|&&s| s == Sign::In).count();
    if inside == 0 {
        return Err(empty(wn, h));
    }
    // BCC has 6 tetrahedra per lattice vertex.
    let estimated = 6 * inside as u128;
    if estimated > options.max_tets as u128 {
        return Err(Error::TooManyTetrahedra {
            h,
            estimated,
            limit: options.max_tets,
        });
    }
    let mut cut_list = cuts::cut_points(lattice, wn, &signs);
    let warped = warp::warp(
        lattice,
        &mut signs,
        &mut cut_list,
        options.params.alpha_long(),
        options.params.alpha_short(),
    );
    let ctx = Context {
        lattice,
        signs: &signs,
        cuts: &cut_list,
        warped: &warped,
    };
    let background = options
        .graded
        .then(|| graded::background(lattice, &signs, options.graded_levels, |v| ctx.position(v)));
    let mut cells = ctx.stuff(background.as_ref().map(|b| &b.fine[..]), rule);
    if let Some(b) = &background {
        cells.extend(b.coarse.iter().map(|t| {
            t.map(|v| Point {
                id: v,
                pos: ctx.position(v),
            })
        }));
    }
    if cells.is_empty() {
        return Err(empty(wn, h));
    }
    Ok(Stuffed {
        mesh: mesh::assemble(cells),
        cut_points: cut_list.len(),
        warped_vertices: warped.len(),
    })
}

/// How far the surface `(boundary_positions, boundary)` — typically a
/// tetrahedral mesh's boundary, [`TetMesh::boundary`] or another mesher's —
/// lies from the input surface `(positions, triangles)`, and the input
/// from it, where the input encloses volume (by the winding number with
/// accuracy [`winding::DEFAULT_BETA`]): the symmetric Hausdorff and mean
/// distance from `samples` points on each surface plus their vertices when
/// there are no more of them (see [`SurfaceDistance`]). The same figures
/// [`Report::distance`] gives. Deterministic on any number of threads.
///
/// # Errors
/// For the input: [`Error::NoTriangles`], [`Error::IndexOutOfRange`],
/// [`Error::NonFinitePosition`]; the same inside [`Error::InBoundary`] for
/// the boundary.
pub fn surface_distance<P: Position, Q: Position>(
    positions: &[P],
    triangles: &[[u32; 3]],
    boundary_positions: &[Q],
    boundary: &[[u32; 3]],
    samples: usize,
) -> Result<SurfaceDistance, Error> {
    let input: Vec<DVec3> = positions.iter().map(|p| p.to_dvec3()).collect();
    let wn = winding::WindingNumber::new(&input, triangles, winding::DEFAULT_BETA)?;
    let output: Vec<DVec3> = boundary_positions.iter().map(|p| p.to_dvec3()).collect();
    let in_boundary = |e: Error| Error::InBoundary(Box::new(e));
    validate_soup(output.len(), boundary).map_err(in_boundary)?;
    for t in boundary {
        if let Some(&v) = t.iter().find(|&&v| !output[v as usize].is_finite()) {
            return Err(in_boundary(Error::NonFinitePosition { vertex: v as usize }));
        }
    }
    let bounding = distance::bounding_triangles(&wn);
    Ok(distance::measure(
        &wn, &bounding, &output, boundary, samples,
    ))
}

/// Why no tetrahedron came out at spacing `h`: no triangle bounds a volume
/// (no spacing helps), or the volume is thinner than `h`.
fn empty(wn: &winding::WindingNumber, h: f64) -> Error {
    let p = wn.positions();
    let bounds_some = wn
        .triangles()
        .par_iter()
        .any(|t| distance::encloses_volume(wn, t.map(|v| p[v as usize])));
    if bounds_some {
        Error::EmptyVolume { h }
    } else {
        Error::OpenSurface {
            triangles: wn.triangles().len(),
        }
    }
}

/// Checks that there are triangles and that their indices exist.
pub(crate) fn validate_soup(vertices: usize, triangles: &[[u32; 3]]) -> Result<(), Error> {
    if triangles.is_empty() {
        return Err(Error::NoTriangles);
    }
    for (t, tri) in triangles.iter().enumerate() {
        for &index in tri {
            if index as usize >= vertices {
                return Err(Error::IndexOutOfRange {
                    triangle: t,
                    index,
                    vertices,
                });
            }
        }
    }
    Ok(())
}

/// The lattice covering the used vertices' bounds with a margin of `2h`
/// (so that its outer layer is outside), checked against the memory bound
/// before anything is allocated.
fn lattice_for(pos: &[DVec3], triangles: &[[u32; 3]], options: &Options) -> Result<Lattice, Error> {
    let h = options.h;
    let (lo, hi) = used_bounds(pos, triangles);
    let cubes = ((hi - lo) / h).ceil() + 4.0;
    let too_large = |vertices: u128| Error::LatticeTooLarge {
        h,
        vertices,
        limit: options.max_lattice_vertices,
        limit_mib: options.max_lattice_vertices * 2 / (1 << 20),
    };
    // Beyond 10^12 cubes per axis the count itself is meaningless.
    if !cubes.is_finite() || cubes.max_element() > 1e12 {
        return Err(too_large(u128::MAX));
    }
    let n = [cubes.x as u128, cubes.y as u128, cubes.z as u128];
    let vertices = Lattice::vertex_count_for(n);
    // Point ids (lattice vertices, then cut points) must fit in u32.
    let limit = options.max_lattice_vertices.min(1 << 28) as u128;
    if vertices > limit {
        return Err(too_large(vertices));
    }
    let n = [n[0] as usize, n[1] as usize, n[2] as usize];
    let size = DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64) * h;
    Ok(Lattice {
        origin: 0.5 * (lo + hi) - 0.5 * size,
        h,
        n,
    })
}

/// The bounding box of the vertices the triangles use.
fn used_bounds(pos: &[DVec3], triangles: &[[u32; 3]]) -> (DVec3, DVec3) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for t in triangles {
        for &v in t {
            lo = lo.min(pos[v as usize]);
            hi = hi.max(pos[v as usize]);
        }
    }
    (lo, hi)
}

/// Red vertices per parallel work item (fixed: thread-count independent).
const RED_CHUNK: usize = 2048;

/// Everything the stencil pass reads.
struct Context<'a> {
    lattice: &'a Lattice,
    signs: &'a [Sign],
    cuts: &'a [Cut],
    warped: &'a [(u32, DVec3)],
}

impl Context<'_> {
    /// Current position of a lattice vertex (warped or not).
    fn position(&self, v: u32) -> DVec3 {
        match self.warped.binary_search_by_key(&v, |w| w.0) {
            Ok(i) => self.warped[i].1,
            Err(_) => self.lattice.position(v),
        }
    }

    /// Runs the stencils over the BCC tetrahedra (all of them, or, for a
    /// graded mesh, those between two fine cubes), in parallel chunks
    /// concatenated in order.
    fn stuff(&self, fine: Option<&[bool]>, rule: FaceRule) -> Vec<[Point; 4]> {
        let nb = self.lattice.black_count();
        let nv = self.lattice.vertex_count() as u32;
        let reds = self.lattice.red_count();
        let chunks: Vec<Vec<[Point; 4]>> = (0..reds.div_ceil(RED_CHUNK))
            .into_par_iter()
            .map(|chunk| {
                let mut out = Vec::new();
                let mut tets = Vec::with_capacity(12);
                for red in chunk * RED_CHUNK..((chunk + 1) * RED_CHUNK).min(reds) {
                    self.lattice.red_tets(red, &mut tets);
                    for t in &tets {
                        if let Some(f) = fine
                            && !(f[red] && f[t[1] as usize - nb])
                        {
                            continue;
                        }
                        if t.iter().all(|&v| self.signs[v as usize] != Sign::In) {
                            continue;
                        }
                        let lt = self.lattice_tet(*t, nv);
                        stencils::fill(&lt, rule, &mut out);
                    }
                }
                out
            })
            .collect();
        chunks.into_iter().flatten().collect()
    }

    fn lattice_tet(&self, t: [u32; 4], nv: u32) -> LatticeTet {
        let v = t.map(|id| Point {
            id,
            pos: self.position(id),
        });
        let sign = t.map(|id| self.signs[id as usize]);
        let coords = t.map(|id| self.lattice.coords(id));
        let mut cut = [[None; 4]; 4];
        for i in 0..4 {
            for j in i + 1..4 {
                if matches!(
                    (sign[i], sign[j]),
                    (Sign::In, Sign::Out) | (Sign::Out, Sign::In)
                ) && let Some(c) = cuts::find(self.cuts, edge_key(t[i], t[j]))
                {
                    let p = Point {
                        id: nv + c as u32,
                        pos: self.cuts[c].pos,
                    };
                    cut[i][j] = Some(p);
                    cut[j][i] = Some(p);
                }
            }
        }
        LatticeTet {
            v,
            sign,
            coords,
            cut,
        }
    }
}

#[cfg(test)]
mod tests;

/// The README's example, compiled as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctest;
