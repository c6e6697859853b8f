//! A translucent object: a tet mesh, its materials and lights, TransCut's
//! three RGB systems, and their solution `φ`.

use std::ops::ControlFlow;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use glam::{DAffine3, DVec3};
use multires::{
    Block3, Cascade, CascadeOptions, Preconditioner, Progress, Report, SolveOptions, Stop, VCycle,
    VCycleOptions, Weights,
};
use rayon::prelude::*;
use sprs::CsMat;

use crate::assembly::{self, Coefficients, Geometry};
use crate::fem::{self, Integration, P1Matrices};
use crate::light::{LitLight, Shadows};
use crate::medium::ResolutionWarning;
use crate::{Error, Light, Medium, TetMesh, fresnel};

/// Which solver [`Object::solve`] uses (all from `multires`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// Chosen per solve, by the system: Jacobi-PCG runs first (the three
    /// channels as one block, [`multires::Block3`]), and every
    /// [`AUTO_PROBE`] iterations its own coefficients and residuals
    /// predict the iterations it still needs ([`Prediction`]). It switches
    /// to V-cycle-PCG — from the iterate it reached, nothing is lost —
    /// when the V-cycle is predicted to cost less (its hierarchy's build
    /// included, unless one is kept) and Jacobi-PCG has already spent half
    /// of what the V-cycle would cost: an early prediction is rough, and
    /// this bounds a wrong switch's loss (the ski-rental rule). The costs
    /// are [`SolverSettings::auto_costs`]. What ran and why is in
    /// [`SolveReport::choice`].
    #[default]
    Auto,
    /// CG preconditioned by an algebraic V-cycle on TransCut's hierarchy:
    /// 2–5 iterations to 1% error where Jacobi-PCG needs 1–116 on the
    /// data meshes, but each costs about 12 of the block Jacobi-PCG's,
    /// after a build of about 150 (2 cores): it pays only on badly
    /// conditioned systems (a long diffusion length against a finely
    /// meshed object).
    VCyclePcg,
    /// The paper's multi-resolution cascade (Sec. 4.2, Eq. 17).
    Cascade,
    /// The cascade with Galerkin coarse systems.
    CascadeGalerkin,
    /// Jacobi-preconditioned CG, the three channels as one block.
    JacobiPcg,
}

/// Jacobi-PCG iterations between [`Method::Auto`]'s predictions.
pub const AUTO_PROBE: usize = 5;

/// [`Method::Auto`]'s cost model, in units of one block Jacobi-PCG
/// iteration (three channels, one pass over the matrix). Counts, not
/// clocks, decide, so the choice is the same on every run and machine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AutoCosts {
    /// Building the V-cycle hierarchy of the three channels (one built,
    /// two refreshed).
    pub hierarchy: f64,
    /// One block V-cycle-PCG iteration.
    pub v_cycle_iteration: f64,
    /// The residual reduction per V-cycle-PCG iteration to expect.
    pub v_cycle_rate: f64,
}

impl AutoCosts {
    /// # Errors
    /// [`Error::BadArgument`] naming the cost that is out of its range:
    /// `hierarchy` finite and ≥ 0, `v_cycle_iteration` finite and > 0,
    /// `v_cycle_rate` in (0, 1) (a reduction per iteration).
    pub fn check(&self) -> Result<(), Error> {
        let bad = |what: &str, value: f64, need: &'static str| {
            Err(Error::BadArgument {
                what: format!("AutoCosts::{what}"),
                value,
                need,
            })
        };
        if !(self.hierarchy.is_finite() && self.hierarchy >= 0.0) {
            return bad(
                "hierarchy",
                self.hierarchy,
                "it must be finite and at least 0",
            );
        }
        if !(self.v_cycle_iteration.is_finite() && self.v_cycle_iteration > 0.0) {
            return bad(
                "v_cycle_iteration",
                self.v_cycle_iteration,
                "it must be finite and positive",
            );
        }
        if !(self.v_cycle_rate > 0.0 && self.v_cycle_rate < 1.0) {
            return bad(
                "v_cycle_rate",
                self.v_cycle_rate,
                "it is a residual reduction per iteration: above 0 and below 1",
            );
        }
        Ok(())
    }
}

impl Default for AutoCosts {
    /// `hierarchy` 150, `v_cycle_iteration` 12, `v_cycle_rate` 0.5:
    /// measured on the data meshes (bunny_500k, sphere_200k, bunny_50k;
    /// 2 cores), where the hierarchy costs 100–150 block Jacobi-PCG
    /// iterations, a V-cycle-PCG iteration 9–13, and V-cycle-PCG reduces
    /// the residual 0.2–0.3× per iteration to 1% error but only 0.5×
    /// towards 10⁻⁸ (the rate assumed, so as not to promise too much).
    /// A faster V-cycle (another machine, a GPU) lowers the first two;
    /// [`check`](Self::check) gives the ranges.
    fn default() -> Self {
        Self {
            hierarchy: 150.0,
            v_cycle_iteration: 12.0,
            v_cycle_rate: 0.5,
        }
    }
}

/// A solver that ran.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Solver {
    /// Jacobi-preconditioned CG.
    JacobiPcg,
    /// CG preconditioned by the V-cycle (after Jacobi-PCG's probe when
    /// [`Method::Auto`] switched).
    VCyclePcg,
    /// The cascade (Eq. 17).
    Cascade,
    /// The cascade with Galerkin coarse systems.
    CascadeGalerkin,
}

impl std::fmt::Display for Solver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::JacobiPcg => "Jacobi-PCG",
            Self::VCyclePcg => "V-cycle-PCG",
            Self::Cascade => "cascade",
            Self::CascadeGalerkin => "cascade (Galerkin)",
        })
    }
}

/// [`Method::Auto`]'s estimate, in block Jacobi-PCG iterations (see
/// [`AutoCosts`]). Jacobi-PCG's own coefficients give, at no extra
/// cost, a lower estimate `κ` of the condition number of the
/// Jacobi-preconditioned matrix ([`multires::Lanczos`]); CG then needs
/// about `ln(r / τ) / −ln ρ` more iterations to go from the relative
/// residual `r` to the tolerance `τ`, with `ρ = (√κ − 1)/(√κ + 1)` (the
/// classical bound, Saad Sec. 6.11.3), and V-cycle-PCG about
/// `ln(r / τ) / −ln` [`AutoCosts::v_cycle_rate`]. Where the residual has already
/// fallen faster than the bound allows (CG's superlinear convergence, a
/// few outlying eigenvalues) that observed rate is used instead.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// Jacobi-PCG iterations done when it was made.
    pub probe_iterations: usize,
    /// The estimated condition number (the worst channel).
    pub condition: f64,
    /// Jacobi-PCG iterations still needed (the slowest channel), also
    /// their cost.
    pub jacobi_cost: f64,
    /// V-cycle-PCG iterations needed.
    pub v_cycle_iterations: f64,
    /// Their cost plus the hierarchy's when none is kept.
    pub v_cycle_cost: f64,
    /// Whether a hierarchy was kept from an earlier solve.
    pub hierarchy_kept: bool,
}

impl Prediction {
    /// Whether the V-cycle is predicted to cost less.
    pub fn prefers_v_cycle(&self) -> bool {
        self.v_cycle_cost < self.jacobi_cost
    }

    /// Whether [`Method::Auto`] switches on it: the V-cycle predicted
    /// cheaper, and Jacobi-PCG's iterations so far at least half the
    /// V-cycle's cost.
    pub fn switches(&self) -> bool {
        self.prefers_v_cycle() && 2.0 * self.probe_iterations as f64 >= self.v_cycle_cost
    }
}

/// The running estimate of [`Method::Auto`]: per channel, one Lanczos
/// matrix fed by each iteration's CG coefficients, and the residual's
/// envelope (its smallest value so far).
struct Estimator {
    lanczos: [multires::Lanczos; 3],
    envelope: [Vec<f64>; 3],
    tolerance: f64,
    hierarchy_kept: bool,
    costs: AutoCosts,
}

impl Estimator {
    fn new(tolerance: f64, hierarchy_kept: bool, costs: AutoCosts) -> Self {
        Self {
            lanczos: Default::default(),
            envelope: Default::default(),
            tolerance,
            hierarchy_kept,
            costs,
        }
    }

    /// Takes in an iteration; every [`AUTO_PROBE`] iterations, the
    /// prediction from there.
    fn step(&mut self, p: &Progress<'_>) -> Option<Prediction> {
        let (alpha, beta) = p.coefficients();
        let running = p.running();
        for c in (0..3).filter(|&c| running[c]) {
            self.lanczos[c].push(alpha[c], beta[c]);
            let r = p.residual()[c];
            let least = self.envelope[c].last().map_or(r, |&e: &f64| e.min(r));
            self.envelope[c].push(least);
        }
        let k = p.iteration();
        if k == 0 || k % AUTO_PROBE != 0 {
            return None;
        }
        let (mut jacobi, mut v_cycle, mut worst) = (0.0f64, 0.0f64, 1.0f64);
        for c in (0..3).filter(|&c| running[c]) {
            let kappa = self.lanczos[c].condition().unwrap_or(1.0).max(1.0);
            worst = worst.max(kappa);
            let left = (p.residual()[c] / self.tolerance).ln();
            if left.is_nan() || left <= 0.0 {
                continue;
            }
            jacobi = jacobi.max(left / self.decay(c, kappa));
            v_cycle = v_cycle.max((left / -self.costs.v_cycle_rate.ln()).ceil().max(1.0));
        }
        let build = if self.hierarchy_kept {
            0.0
        } else {
            self.costs.hierarchy
        };
        Some(Prediction {
            probe_iterations: k,
            condition: worst,
            jacobi_cost: jacobi,
            v_cycle_iterations: v_cycle,
            v_cycle_cost: build + v_cycle * self.costs.v_cycle_iteration,
            hierarchy_kept: self.hierarchy_kept,
        })
    }

    /// Channel `c`'s expected `−ln` of the residual per iteration from
    /// here: the faster of the bound for the estimated `κ` and the rate
    /// the residual's envelope fell at over the second half of the
    /// iterations. Each alone overstates what is left — the bound where a
    /// few small eigenvalues (a nearly insulated object) inflate `κ` but
    /// cost CG only an iteration each, the observed rate because CG speeds
    /// up as it goes — so the faster is the closer.
    fn decay(&self, c: usize, kappa: f64) -> f64 {
        let root = kappa.sqrt();
        let bound = -((root - 1.0) / (root + 1.0)).ln();
        let e = &self.envelope[c];
        let k = e.len();
        let half = k / 2;
        let observed = if half >= 1 && e[half - 1] > 0.0 && e[k - 1] > 0.0 {
            (e[half - 1] / e[k - 1]).ln() / (k - half) as f64
        } else {
            0.0
        };
        bound.max(observed).max(f64::MIN_POSITIVE)
    }
}

/// Which solver a solve ran, and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Choice {
    /// What ran last (V-cycle-PCG when [`Method::Auto`] switched after its
    /// Jacobi-PCG probe).
    pub solver: Solver,
    /// The settings asked for it ([`SolverSettings::method`] not
    /// [`Method::Auto`]).
    pub forced: bool,
    /// [`Method::Auto`]'s estimate that came closest to a switch (the one
    /// that switched, if it did); `None` when the tolerance came before the
    /// first (or the solve was forced).
    pub prediction: Option<Prediction>,
}

impl std::fmt::Display for Choice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.forced {
            return write!(f, "{} (as set)", self.solver);
        }
        match &self.prediction {
            None => write!(f, "{} (auto: converged within the probe)", self.solver),
            Some(p) => write!(
                f,
                "{} (auto: after {} Jacobi-PCG iteration{}, condition ≥ {:.0}: Jacobi-PCG predicted {:.0} more, V-cycle-PCG {:.0} iteration{}{}: cost {:.0} vs {:.0})",
                self.solver,
                p.probe_iterations,
                plural(p.probe_iterations as f64),
                p.condition,
                p.jacobi_cost,
                p.v_cycle_iterations,
                plural(p.v_cycle_iterations),
                if p.hierarchy_kept {
                    " on the kept hierarchy"
                } else {
                    " and its hierarchy"
                },
                p.jacobi_cost,
                p.v_cycle_cost
            ),
        }
    }
}

/// How [`Object::solve`] solves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    /// The solver.
    pub method: Method,
    /// Relative residual `‖b − M φ‖ / ‖b‖` to reach.
    pub tolerance: f64,
    /// Iteration cap per channel.
    pub max_iterations: usize,
    /// Build one hierarchy (from the green channel's matrix) and use it for
    /// all three channels (each with its own Galerkin operators on it),
    /// instead of one per channel.
    pub share_hierarchy: bool,
    /// [`Method::Auto`]'s cost model.
    pub auto_costs: AutoCosts,
}

impl Default for SolverSettings {
    /// The solver chosen per solve ([`Method::Auto`]) to a relative
    /// residual of 10⁻⁶, one shared hierarchy when one is built.
    fn default() -> Self {
        Self {
            method: Method::Auto,
            tolerance: 1e-6,
            max_iterations: 5_000,
            share_hierarchy: true,
            auto_costs: AutoCosts::default(),
        }
    }
}

/// What a solve did.
#[derive(Debug, Clone, PartialEq)]
pub struct SolveReport {
    /// Per channel: the solver's report (iterations, true final residual).
    /// After [`Method::Auto`] switched, the iterations are Jacobi-PCG's
    /// and then V-cycle-PCG's, added.
    pub channels: [Report; 3],
    /// Levels of the hierarchy (1 for Jacobi-PCG).
    pub levels: usize,
    /// Time to build the hierarchy (and coarse operators), ms.
    pub hierarchy_ms: f64,
    /// Time of the iterations, ms.
    pub solve_ms: f64,
    /// Whether this solve built the hierarchy (the first solve after the
    /// mesh changed, or after a change of method).
    pub hierarchy_built: bool,
    /// Whether this solve refreshed the kept hierarchy's coarse operators
    /// (the matrix's diagonal had drifted past [`REFRESH_DRIFT`] from the
    /// one they were made for).
    pub hierarchy_refreshed: bool,
    /// Whether the [`Budget`]'s deadline or cancel flag stopped it.
    pub interrupted: bool,
    /// For a [`solve_preview`](Object::solve_preview) on a coarse level:
    /// that level of the hierarchy (the channels' reports are then of its
    /// systems); `None` for iterations on the original system.
    pub coarse_level: Option<usize>,
    /// Which solver ran and why.
    pub choice: Choice,
}

impl Budget<'_> {
    fn with_tolerance(self, tolerance: f64) -> Self {
        Self {
            tolerance: Some(tolerance),
            ..self
        }
    }
}

/// Damped Jacobi sweeps of a preview's correction on each intermediate
/// level and on the original one, on the way up
/// ([`multires::VCycle::coarse_correction`]): on bunny_500k (level 2,
/// under 2 000 unknowns), 2 and 2 take the boundary radiance's error
/// after a light change from 16 % (none) to 3 % (a solve to 10⁻² on the
/// original system: 0.3 %), for two fine mat-vecs per sweep and channel.
const PREVIEW_SWEEPS: [usize; 2] = [2, 2];

/// Limits of one [`Object::solve_monitored`].
#[derive(Debug, Clone, Copy, Default)]
pub struct Budget<'a> {
    /// Relative residual to reach instead of the settings' (a loose one,
    /// such as 10⁻², for a first look).
    pub tolerance: Option<f64>,
    /// Stop at this instant.
    pub deadline: Option<Instant>,
    /// Stop as soon as this is set (checked after every iteration).
    pub cancel: Option<&'a AtomicBool>,
}

/// The kept V-cycles' coarse operators are recomputed for the current
/// matrices (Galerkin products on the kept prolongations,
/// [`multires::VCycle::refreshed`]) before a solve when the matrices'
/// diagonal has moved this far from theirs
/// ([`multires::VCycle::diagonal_drift`]: the mean relative change per
/// row, capped at 1). Paint changes few rows, so a stroke rarely reaches
/// it; painting a third of the object with a very different medium does,
/// where the stale operators would triple the iterations.
pub const REFRESH_DRIFT: f64 = 0.1;

/// The solver state kept across solves while the mesh stays the same.
#[derive(Debug)]
pub(crate) struct Kept {
    method: Method,
    share_hierarchy: bool,
    solver: KeptSolver,
}

#[derive(Debug)]
enum KeptSolver {
    Jacobi,
    /// One shared (green channel's) V-cycle, or one per channel.
    VCycles(Vec<VCycle<'static>>),
    Cascade(Cascade),
}

impl KeptSolver {
    fn levels(&self) -> usize {
        match self {
            Self::Jacobi => 1,
            Self::VCycles(v) => v.first().map_or(1, |v| v.hierarchy().levels()),
            Self::Cascade(c) => c.hierarchy().levels(),
        }
    }
}

/// "s" unless `n` is 1.
fn plural(n: f64) -> &'static str {
    if n == 1.0 { "" } else { "s" }
}

/// A solve's monitor's answer to a budget: stop when it is spent.
fn budget_flow(spent: bool) -> ControlFlow<()> {
    if spent {
        ControlFlow::Break(())
    } else {
        ControlFlow::Continue(())
    }
}

/// Each channel's V-cycle: its own, or the one shared by all.
fn per_channel<'v>(v: &'v [VCycle<'static>]) -> [&'v VCycle<'static>; 3] {
    [0, 1, 2].map(|c| &v[if v.len() == 3 { c } else { 0 }])
}

/// Where a fractured piece came from, to recombine it exactly.
#[derive(Debug, Clone)]
pub(crate) struct Lineage {
    pub(crate) token: u64,
    pub(crate) parent_vertices: usize,
    pub(crate) parent_tets: usize,
    /// Piece vertex → parent vertex.
    pub(crate) vertex: Vec<u32>,
    /// Piece tet → parent tet.
    pub(crate) tet: Vec<u32>,
    /// The parent's own lineage (pieces can be split again).
    pub(crate) parent: Option<Box<Lineage>>,
    /// The parent's original tet ids.
    pub(crate) parent_original: Vec<u32>,
}

/// A translucent object ready to light, solve, shade, cut, paint and
/// fracture. `Clone` copies everything, the solution and the traced
/// shadows included (to try an edit and keep the original).
///
/// Lengths are in the mesh's unit; `length_unit_mm` says how many
/// millimetres one unit is (1000 for a mesh in metres), because the
/// materials are in mm⁻¹. `φ` is per vertex and per RGB channel.
#[derive(Debug, Clone)]
pub struct Object {
    pub(crate) mesh: TetMesh,
    pub(crate) length_unit_mm: f64,
    pub(crate) eta: f64,
    /// Indexed by original tet id.
    pub(crate) media: Vec<Medium>,
    pub(crate) geometry: Geometry,
    pub(crate) coefficients: Coefficients,
    pub(crate) matrices: [CsMat<f64>; 3],
    pub(crate) lights: Vec<LitLight>,
    pub(crate) shadows_enabled: bool,
    pub(crate) shadows: Option<Shadows>,
    pub(crate) incident: Option<Vec<[f64; 3]>>,
    pub(crate) q: Vec<[f64; 3]>,
    pub(crate) rhs: [Vec<f64>; 3],
    pub(crate) phi: [Vec<f64>; 3],
    /// Solver settings, used by [`solve`](Self::solve).
    pub settings: SolverSettings,
    pub(crate) transform: DAffine3,
    pub(crate) lineage: Option<Lineage>,
    pub(crate) assembly_ms: f64,
    /// The solver's hierarchy, kept until the mesh changes; shared by
    /// clones (it is only read).
    pub(crate) kept: Option<Arc<Kept>>,
    pub(crate) hierarchy_builds: usize,
    pub(crate) hierarchy_refreshes: usize,
    /// The tet centres binned in a uniform grid, for the paint brush;
    /// made on the first paint, dropped when the mesh changes.
    pub(crate) centres: std::sync::OnceLock<Arc<crate::paint::CentreGrid>>,
    /// Whether the matrices' values changed since the kept hierarchy's
    /// drift was last checked.
    pub(crate) values_changed: bool,
    /// The matrices as one block for the block solvers, and whether it
    /// holds their current values (a paint stroke or a material change
    /// refreshes its values; a new mesh drops it).
    pub(crate) block: Option<Arc<Block3>>,
    pub(crate) block_current: bool,
    /// Solves (fine or preview) since the mesh last changed.
    pub(crate) solves_on_mesh: usize,
}

impl Object {
    /// An object of one material.
    ///
    /// # Errors
    /// As [`new`](Self::new).
    ///
    /// # Example
    /// ```
    /// use tet_diffusion::{glam::DVec3, Light, Medium, Object, TetMesh};
    /// let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    /// let mesh = TetMesh::new(&p, &[[0, 1, 2, 3]])?;
    /// let mut marble = Object::homogeneous(mesh, 10.0, Medium::measured("marble")?, 1.3)?;
    /// marble.add_light(Light::Directional { to_light: DVec3::ONE, irradiance: [1.0; 3] })?;
    /// marble.solve()?;
    /// assert!(marble.radiance(None).iter().all(|l| l[0] >= 0.0));
    /// # Ok::<(), tet_diffusion::Error>(())
    /// ```
    pub fn homogeneous(
        mesh: TetMesh,
        length_unit_mm: f64,
        medium: Medium,
        eta: f64,
    ) -> Result<Self, Error> {
        let n = mesh
            .original_ids()
            .iter()
            .max()
            .map_or(0, |&m| m as usize + 1);
        Self::new(mesh, length_unit_mm, vec![medium; n], eta)
    }

    /// An object with one medium per tet (indexed by the mesh's
    /// [`original_ids`](TetMesh::original_ids), so by tet index for a mesh
    /// made by [`TetMesh::new`]); `eta` is the relative index of refraction
    /// of its boundary.
    ///
    /// # Errors
    /// [`Error::BadArgument`] for a unit or `eta` that is not positive and
    /// finite, or a bad coefficient (naming the tet and channel);
    /// [`Error::LengthMismatch`] when `media` is too short.
    pub fn new(
        mesh: TetMesh,
        length_unit_mm: f64,
        media: Vec<Medium>,
        eta: f64,
    ) -> Result<Self, Error> {
        if !(length_unit_mm.is_finite() && length_unit_mm > 0.0) {
            return Err(Error::BadArgument {
                what: "length_unit_mm".into(),
                value: length_unit_mm,
                need: "millimetres per mesh unit must be positive and finite",
            });
        }
        check_eta(eta)?;
        let needed = mesh
            .original_ids()
            .iter()
            .max()
            .map_or(0, |&m| m as usize + 1);
        if media.len() < needed {
            return Err(Error::LengthMismatch {
                what: "the media (one per tetrahedron)",
                expected: needed,
                found: media.len(),
            });
        }
        for &t in mesh.original_ids() {
            media[t as usize].check(&format!("tetrahedron {t}"))?;
        }
        let n = mesh.vertex_count();
        let nb = mesh.boundary_vertices().len();
        let mut object = Self {
            geometry: Geometry {
                volume: Vec::new(),
                weights: Vec::new(),
            },
            coefficients: Coefficients {
                kappa: Vec::new(),
                mu: Vec::new(),
            },
            matrices: std::array::from_fn(|_| CsMat::zero((0, 0))),
            mesh,
            length_unit_mm,
            eta,
            media,
            lights: Vec::new(),
            shadows_enabled: true,
            shadows: None,
            incident: None,
            q: vec![[0.0; 3]; nb],
            rhs: std::array::from_fn(|_| vec![0.0; n]),
            phi: std::array::from_fn(|_| vec![0.0; n]),
            settings: SolverSettings::default(),
            transform: DAffine3::IDENTITY,
            lineage: None,
            assembly_ms: 0.0,
            kept: None,
            hierarchy_builds: 0,
            hierarchy_refreshes: 0,
            centres: std::sync::OnceLock::new(),
            values_changed: false,
            block: None,
            block_current: false,
            solves_on_mesh: 0,
        };
        object.rebuild();
        Ok(object)
    }

    /// Recomputes everything that depends on the mesh: geometry, matrices,
    /// shadows, visibility, `q` and `b`.
    /// Returns the time (ms) of the matrices' assembly and of the lights'
    /// re-tracing with the right-hand sides, for the cut's report.
    pub(crate) fn rebuild(&mut self) -> [f64; 2] {
        self.kept = None;
        self.block = None;
        self.solves_on_mesh = 0;
        self.centres = std::sync::OnceLock::new();
        let assembly_ms = self.reassemble();
        let start = Instant::now();
        let lights: Vec<Light> = self.lights.drain(..).map(|l| l.light).collect();
        self.shadows = None;
        for light in lights {
            self.trace(light);
        }
        self.incident = None;
        self.update_rhs();
        [assembly_ms, start.elapsed().as_secs_f64() * 1e3]
    }

    /// Per-tet coefficients in mesh units.
    pub(crate) fn coefficients_of_media(&self) -> Coefficients {
        let (kappa, mu) = self
            .mesh
            .original_ids()
            .par_iter()
            .with_min_len(4096)
            .map(|&id| self.tet_coefficients(id))
            .unzip();
        Coefficients { kappa, mu }
    }

    /// `κ` (mesh units) and `μa` (per mesh unit) of original tet `id`.
    pub(crate) fn tet_coefficients(&self, id: u32) -> ([f64; 3], [f64; 3]) {
        let unit = self.length_unit_mm;
        let m = &self.media[id as usize];
        let k = m.kappa();
        ([0, 1, 2].map(|c| k[c] / unit), m.sigma_a.map(|a| a * unit))
    }

    fn trace(&mut self, light: Light) {
        if self.shadows_enabled && self.shadows.is_none() {
            self.shadows = Some(Shadows::new(&self.mesh));
        }
        let shadows = if self.shadows_enabled {
            self.shadows.as_ref()
        } else {
            None
        };
        self.lights.push(LitLight::trace(
            light,
            &self.mesh,
            shadows,
            self.length_unit_mm,
        ));
    }

    /// Recomputes `q` from the lights (and the extra incident light) and
    /// the right-hand sides; no ray is traced.
    pub(crate) fn update_rhs(&mut self) {
        let nb = self.mesh.boundary_vertices().len();
        let mut q = self.incident.clone().unwrap_or_else(|| vec![[0.0; 3]; nb]);
        for l in &self.lights {
            l.add_q(&self.mesh, self.eta, self.length_unit_mm, &mut q);
        }
        self.rhs = assembly::rhs(&self.mesh, &q, self.boundary_factor(), self.fdr());
        self.q = q;
    }

    /// Adds a light; its shadow rays are traced once, now. Returns its
    /// index.
    ///
    /// # Errors
    /// [`Error::BadArgument`] for a non-finite value or a zero direction.
    pub fn add_light(&mut self, light: Light) -> Result<usize, Error> {
        light.check()?;
        self.trace(light);
        self.update_rhs();
        Ok(self.lights.len() - 1)
    }

    /// Changes light `index`'s colour (irradiance or intensity; ignored for
    /// environment maps) without re-tracing its shadows.
    ///
    /// # Errors
    /// [`Error::BadArgument`] for a bad index or a non-finite value.
    pub fn set_light_color(&mut self, index: usize, rgb: [f64; 3]) -> Result<(), Error> {
        for (c, v) in rgb.into_iter().enumerate() {
            crate::error::finite(|| format!("colour[{c}] of light {index}"), v)?;
        }
        let n = self.lights.len();
        let light = self.lights.get_mut(index).ok_or(Error::BadArgument {
            what: "the light index".into(),
            value: index as f64,
            need: if n == 0 {
                "the object has no lights"
            } else {
                "it must be below the number of lights"
            },
        })?;
        light.set_color(rgb);
        self.update_rhs();
        Ok(())
    }

    /// The lights, in the order they were added.
    pub fn lights(&self) -> Vec<Light> {
        self.lights.iter().map(|l| l.light.clone()).collect()
    }

    /// Removes all lights (and the extra incident light).
    pub fn clear_lights(&mut self) {
        self.lights.clear();
        self.incident = None;
        self.update_rhs();
    }

    /// Whether lights cast shadows (on by default). Changing it re-traces
    /// the lights.
    pub fn set_shadows(&mut self, on: bool) {
        if on != self.shadows_enabled {
            self.shadows_enabled = on;
            let lights: Vec<Light> = self.lights.drain(..).map(|l| l.light).collect();
            for light in lights {
                self.trace(light);
            }
            self.update_rhs();
        }
    }

    /// Sets an extra diffused incoming light `q` (Eq. 2; W/mm², RGB) per
    /// boundary vertex, in the order of
    /// [`TetMesh::boundary_vertices`], added to the lights' (for tests,
    /// closed forms and lights computed elsewhere). It is cleared by a cut.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`], [`Error::BadArgument`] for a non-finite
    /// value.
    pub fn set_incident(&mut self, q: Vec<[f64; 3]>) -> Result<(), Error> {
        let nb = self.mesh.boundary_vertices().len();
        if q.len() != nb {
            return Err(Error::LengthMismatch {
                what: "the incident light (one per boundary vertex)",
                expected: nb,
                found: q.len(),
            });
        }
        for (k, v) in q.iter().enumerate() {
            for (c, &x) in v.iter().enumerate() {
                crate::error::finite(|| format!("q[{k}][{c}]"), x)?;
            }
        }
        self.incident = Some(q);
        self.update_rhs();
        Ok(())
    }

    /// The mesh.
    pub fn mesh(&self) -> &TetMesh {
        &self.mesh
    }

    /// Millimetres per mesh unit.
    pub fn length_unit_mm(&self) -> f64 {
        self.length_unit_mm
    }

    /// Relative index of refraction of the boundary.
    pub fn eta(&self) -> f64 {
        self.eta
    }

    /// `F_dr(η)`.
    pub fn fdr(&self) -> f64 {
        fresnel::diffuse_reflectance(self.eta)
    }

    /// `A = (1 + F_dr) / (1 − F_dr)`.
    pub fn boundary_factor(&self) -> f64 {
        fresnel::boundary_factor(self.eta)
    }

    /// The media, indexed by original tet id.
    pub fn media(&self) -> &[Medium] {
        &self.media
    }

    /// The medium of the mesh's tet `t`.
    pub fn medium(&self, t: usize) -> Option<&Medium> {
        let id = *self.mesh.original_ids().get(t)?;
        self.media.get(id as usize)
    }

    /// TransCut's matrix `M` of channel `c` (0 red, 1 green, 2 blue; larger
    /// values read blue), mesh units.
    pub fn matrix(&self, c: usize) -> &CsMat<f64> {
        &self.matrices[c.min(2)]
    }

    /// The right-hand side `b` (Eq. 12) of channel `c` (as for
    /// [`matrix`](Self::matrix)).
    pub fn rhs(&self, c: usize) -> &[f64] {
        &self.rhs[c.min(2)]
    }

    /// `q` (Eq. 2) per boundary vertex, RGB.
    pub fn incident(&self) -> &[[f64; 3]] {
        &self.q
    }

    /// The fluence `φ` of channel `c` (as for [`matrix`](Self::matrix)) per
    /// vertex: the last solution, and the warm start of the next solve.
    pub fn phi(&self, c: usize) -> &[f64] {
        &self.phi[c.min(2)]
    }

    /// `φ` per vertex, RGB.
    pub fn fluence(&self) -> Vec<[f64; 3]> {
        (0..self.mesh.vertex_count())
            .map(|i| [self.phi[0][i], self.phi[1][i], self.phi[2][i]])
            .collect()
    }

    /// Replaces `φ` (the warm start), e.g. with a solution computed
    /// elsewhere.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`].
    pub fn set_phi(&mut self, phi: [Vec<f64>; 3]) -> Result<(), Error> {
        for p in &phi {
            if p.len() != self.mesh.vertex_count() {
                return Err(Error::LengthMismatch {
                    what: "phi",
                    expected: self.mesh.vertex_count(),
                    found: p.len(),
                });
            }
        }
        self.phi = phi;
        Ok(())
    }

    /// Re-computes the cotangent weights and re-assembles the three
    /// matrices from the mesh and the media (what a cut does after
    /// rebuilding the mesh) and returns the time it took, ms.
    pub fn reassemble(&mut self) -> f64 {
        let start = Instant::now();
        self.values_changed = true;
        self.block_current = false;
        // Free the old arrays first: they are not read, and keeping them
        // while the new ones are built would double the peak memory.
        self.matrices = std::array::from_fn(|_| CsMat::zero((0, 0)));
        self.geometry = Geometry {
            volume: Vec::new(),
            weights: Vec::new(),
        };
        self.geometry = Geometry::new(&self.mesh);
        self.coefficients = self.coefficients_of_media();
        self.matrices = assembly::assemble(
            &self.mesh,
            &self.geometry,
            &self.coefficients,
            self.boundary_factor(),
        );
        self.assemble_block();
        self.assembly_ms = start.elapsed().as_secs_f64() * 1e3;
        self.assembly_ms
    }

    /// Bytes of the arrays this object holds (mesh, matrices and their
    /// block form, geometry,
    /// media, lights' visibility, `φ`, `q`, `b`; not the kept hierarchy,
    /// which clones share), to budget copies of it.
    pub fn memory_bytes(&self) -> usize {
        let n = self.mesh.vertex_count();
        let t = self.mesh.tets().len();
        let matrices: usize = self
            .matrices
            .iter()
            .map(|m| m.nnz() * 12 + (m.rows() + 1) * 8)
            .sum();
        let lights: usize = self.lights.iter().map(LitLight::bytes).sum();
        let block = self.block.as_deref().map_or(0, Block3::bytes);
        self.mesh.memory_bytes()
            + matrices
            + block
            + t * (8 + 48 + 48)
            + self.media.len() * std::mem::size_of::<Medium>()
            + lights
            + 3 * 2 * 8 * n
            + self.q.len() * 24
    }

    /// Replaces every medium by `medium`, re-assembles, and returns each
    /// tet (mesh index) with its previous medium.
    pub(crate) fn set_all_media(&mut self, medium: Medium) -> Vec<(u32, Medium)> {
        let previous: Vec<(u32, Medium)> = self
            .mesh
            .original_ids()
            .iter()
            .enumerate()
            .map(|(t, &id)| (t as u32, self.media[id as usize]))
            .collect();
        for &id in self.mesh.original_ids() {
            self.media[id as usize] = medium;
        }
        self.reassemble_values();
        previous
    }

    /// Puts back what [`set_all_media`](Self::set_all_media) returned.
    pub(crate) fn restore_all_media(&mut self, previous: &[(u32, Medium)]) {
        for &(t, m) in previous {
            let id = self.mesh.original_ids()[t as usize] as usize;
            self.media[id] = m;
        }
        self.reassemble_values();
    }

    /// Re-assembles the matrices from the media, keeping the geometry.
    fn reassemble_values(&mut self) {
        let start = Instant::now();
        self.values_changed = true;
        self.block_current = false;
        self.coefficients = self.coefficients_of_media();
        self.matrices = assembly::assemble(
            &self.mesh,
            &self.geometry,
            &self.coefficients,
            self.boundary_factor(),
        );
        self.assemble_block();
        self.assembly_ms = start.elapsed().as_secs_f64() * 1e3;
    }

    /// Time of the last full matrix assembly, ms.
    pub fn assembly_ms(&self) -> f64 {
        self.assembly_ms
    }

    /// Warnings for channels whose diffusion length `1/√(3 μa (μa + σs′))`
    /// is below the mesh's mean edge length (one per distinct medium and
    /// channel).
    pub fn warnings(&self) -> Vec<ResolutionWarning> {
        let edge_mm = self.mesh.mean_edge_length() * self.length_unit_mm;
        let mut seen: Vec<(usize, u32)> = Vec::new();
        let mut out = Vec::new();
        for (t, &id) in self.mesh.original_ids().iter().enumerate() {
            let l = self.media[id as usize].diffusion_length();
            for (c, &lc) in l.iter().enumerate() {
                if lc < edge_mm {
                    let key = (c, id);
                    let same = seen.iter().any(|&(sc, sid)| {
                        sc == c && self.media[sid as usize] == self.media[id as usize]
                    });
                    if !same {
                        seen.push(key);
                        out.push(ResolutionWarning {
                            tet: t,
                            channel: c,
                            diffusion_length_mm: lc,
                            edge_length_mm: edge_mm,
                        });
                    }
                }
            }
        }
        out
    }

    /// Solves the three systems `M φ = b` with [`settings`](Self::settings),
    /// starting from the current `φ` (warm start). The solver's hierarchy
    /// is built on the first solve after the mesh changed (creation, a
    /// cut) and kept across paint, light and material edits, which change
    /// only the values of `M` or `b` (see [`hierarchy_builds`](Self::hierarchy_builds)).
    ///
    /// # Errors
    /// [`Error::NotConverged`] with the true residual when a channel does
    /// not reach the tolerance (`φ` then holds the last iterate);
    /// [`Error::Solver`] for an error of `multires`.
    pub fn solve(&mut self) -> Result<SolveReport, Error> {
        self.solve_monitored(&Budget::default())
    }

    /// [`solve`](Self::solve) within a [`Budget`]: its own tolerance (a
    /// loose one gives a quick preview, which a later call refines from the
    /// same warm start), a deadline, and a cancel flag another thread sets
    /// when new input makes this solve moot. A solve stopped by the
    /// deadline or the flag is `Ok` with [`SolveReport::interrupted`] set,
    /// and `φ` holds the last iterate of each channel (channels after the
    /// one interrupted keep their previous `φ`).
    ///
    /// # Errors
    /// As [`solve`](Self::solve) (an interruption is not an error);
    /// [`Error::BadArgument`] for a tolerance that is not finite and ≥ 0.
    pub fn solve_monitored(&mut self, budget: &Budget<'_>) -> Result<SolveReport, Error> {
        let s = self.settings;
        let tolerance = budget.tolerance.unwrap_or(s.tolerance);
        if !(tolerance.is_finite() && tolerance >= 0.0) {
            return Err(Error::BadArgument {
                what: "the solve's tolerance".into(),
                value: tolerance,
                need: "it must be finite and at least 0",
            });
        }
        s.auto_costs.check()?;
        let prepared = self.prepare_kept()?;
        self.solves_on_mesh += 1;
        self.solve_prepared(budget, tolerance, prepared)
    }

    /// Builds or refreshes the kept solver state as a solve needs it;
    /// returns `[built, refreshed]` with their times (ms).
    fn prepare_kept(&mut self) -> Result<[Option<f64>; 2], Error> {
        let built = self.ensure_kept()?;
        let refreshed = if built.is_none() {
            self.refresh_kept()?
        } else {
            None
        };
        Ok([built, refreshed])
    }

    fn kept_now(&self) -> Result<Arc<Kept>, Error> {
        self.kept
            .clone()
            .ok_or(Error::Solver(multires::Error::InvalidOption(
                "the solver state was not built",
            )))
    }

    /// TransCut's interactive result (Sec. 4.2: the multi-resolution
    /// hierarchy's coarse level, interpolated to the fine vertices): the
    /// residual `b − M φ` of each channel restricted to the finest level
    /// of the kept V-cycle hierarchy with at most `max_rows` unknowns,
    /// that level's (Galerkin) system solved there to `tolerance`, and the
    /// correction prolonged back and added to `φ`
    /// ([`multires::VCycle::coarse_correction`]). A fraction of the cost
    /// of fine iterations, and a deterministic function of the object and
    /// `φ` (bit for bit on any number of threads), so a session can keep
    /// it as the state later edits warm-start from; a later
    /// [`solve`](Self::solve) refines it on the original system.
    ///
    /// When the original system has at most `max_rows` unknowns, or the
    /// solver is not [`Method::VCyclePcg`], this is
    /// [`solve_monitored`](Self::solve_monitored) with `tolerance` (fine
    /// iterations). [`SolveReport::coarse_level`] says which it was; the
    /// channels' reports are those of the coarse systems then.
    ///
    /// # Errors
    /// As [`solve_monitored`](Self::solve_monitored).
    pub fn solve_preview(&mut self, max_rows: usize, tolerance: f64) -> Result<SolveReport, Error> {
        if !(tolerance.is_finite() && tolerance >= 0.0) {
            return Err(Error::BadArgument {
                what: "the preview's tolerance".into(),
                value: tolerance,
                need: "it must be finite and at least 0",
            });
        }
        self.settings.auto_costs.check()?;
        let mut prepared = self.prepare_kept()?;
        // The coarse-level answer needs the hierarchy. Auto builds it for a
        // preview once this mesh has been solved before: an edit after an
        // edit, where later edits reuse it (TransCut's interactive loop);
        // the first solve after a cut answers from fine iterations, sooner.
        let large = self.phi[0].len() > max_rows;
        if self.settings.method == Method::Auto
            && large
            && self.solves_on_mesh > 0
            && matches!(self.kept_now()?.solver, KeptSolver::Jacobi)
        {
            prepared[0] = Some(self.keep_auto_v_cycles()?);
        }
        self.solves_on_mesh += 1;
        let kept = self.kept_now()?;
        let level = match &kept.solver {
            KeptSolver::VCycles(v) => {
                let rows = v[0].level_rows();
                rows.iter()
                    .position(|&r| r <= max_rows)
                    .unwrap_or(rows.len() - 1)
            }
            _ => 0,
        };
        let KeptSolver::VCycles(v) = &kept.solver else {
            return self.solve_prepared(
                &Budget::default().with_tolerance(tolerance),
                tolerance,
                prepared,
            );
        };
        if level == 0 || v.len() != 3 {
            return self.solve_prepared(
                &Budget::default().with_tolerance(tolerance),
                tolerance,
                prepared,
            );
        }
        let options =
            SolveOptions::new(tolerance, self.settings.max_iterations).allow_unconverged();
        let t = Instant::now();
        let n = self.phi[0].len();
        let (mut r, mut z) = (vec![0.0; n], vec![0.0; n]);
        let mut reports = Vec::with_capacity(3);
        for (c, v) in v.iter().enumerate() {
            multires::matrix::mul_vec(&self.matrices[c], &self.phi[c], &mut r);
            r.iter_mut()
                .zip(&self.rhs[c])
                .for_each(|(r, b)| *r = b - *r);
            let (report, _) =
                v.coarse_correction(level, &r, &mut z, PREVIEW_SWEEPS, &options, &mut |_, _| {
                    ControlFlow::Continue(())
                })?;
            self.phi[c].iter_mut().zip(&z).for_each(|(x, z)| *x += z);
            reports.push(report);
        }
        let [built, refreshed] = prepared;
        Ok(SolveReport {
            channels: [reports[0], reports[1], reports[2]],
            levels: kept.solver.levels(),
            hierarchy_ms: built.or(refreshed).unwrap_or(0.0),
            solve_ms: ms(t),
            hierarchy_built: built.is_some(),
            hierarchy_refreshed: refreshed.is_some(),
            interrupted: false,
            coarse_level: Some(level),
            choice: Choice {
                solver: Solver::VCyclePcg,
                forced: self.settings.method != Method::Auto,
                prediction: None,
            },
        })
    }

    /// The iterations of [`solve_monitored`](Self::solve_monitored) after
    /// [`prepare_kept`](Self::prepare_kept).
    fn solve_prepared(
        &mut self,
        budget: &Budget<'_>,
        tolerance: f64,
        [built, refreshed]: [Option<f64>; 2],
    ) -> Result<SolveReport, Error> {
        let s = self.settings;
        // Convergence is checked below, per channel, so that the error can
        // name the channel.
        let options = SolveOptions::new(tolerance, s.max_iterations).allow_unconverged();
        let mut hierarchy_ms = built.or(refreshed).unwrap_or(0.0);
        let mut built_here = false;
        let kept = self.kept_now()?;
        let stop_now = || {
            budget.cancel.is_some_and(|c| c.load(Ordering::Relaxed))
                || budget.deadline.is_some_and(|d| Instant::now() >= d)
        };
        let t = Instant::now();
        let forced = |solver| Choice {
            solver,
            forced: true,
            prediction: None,
        };
        let (channels, choice) = match (&kept.solver, s.method) {
            (KeptSolver::Cascade(cascade), method) => {
                let mut reports = Vec::with_capacity(3);
                for c in 0..3 {
                    let (m, b, x) = (&self.matrices[c], &self.rhs[c], &mut self.phi[c]);
                    let mut monitor = |_: usize, _: &[f64]| budget_flow(stop_now());
                    let r = cascade
                        .solve_monitored(m, b, x, &options, &mut monitor)?
                        .finest;
                    reports.push(r);
                    if r.stop == Stop::Interrupted {
                        break;
                    }
                }
                let skipped = Report {
                    stop: Stop::Interrupted,
                    iterations: 0,
                    residual: f64::NAN,
                };
                reports.resize(3, skipped);
                let solver = if method == Method::CascadeGalerkin {
                    Solver::CascadeGalerkin
                } else {
                    Solver::Cascade
                };
                ([reports[0], reports[1], reports[2]], forced(solver))
            }
            (KeptSolver::VCycles(v), Method::VCyclePcg) => {
                let v = per_channel(v);
                let reports =
                    self.block_pcg(Some(v), &options, &mut |_| budget_flow(stop_now()))?;
                (reports, forced(Solver::VCyclePcg))
            }
            (_, Method::Auto) => {
                let (reports, choice, built_ms) =
                    self.solve_auto(&kept, &options, tolerance, &stop_now)?;
                if let Some(built_ms) = built_ms {
                    hierarchy_ms += built_ms;
                    built_here = true;
                }
                (reports, choice)
            }
            _ => {
                let reports = self.block_pcg(None, &options, &mut |_| budget_flow(stop_now()))?;
                (reports, forced(Solver::JacobiPcg))
            }
        };
        let solve_ms = ms(t) - (hierarchy_ms - built.or(refreshed).unwrap_or(0.0));
        let hierarchy_built = built.is_some() || built_here;
        let interrupted = channels.iter().any(|r| r.stop == Stop::Interrupted);
        if !interrupted {
            for (c, r) in channels.iter().enumerate() {
                if !r.converged() {
                    return Err(Error::NotConverged {
                        channel: ["red", "green", "blue"][c],
                        residual: r.residual,
                        iterations: r.iterations,
                        stop: r.stop,
                        tolerance,
                    });
                }
            }
        }
        let kept = self.kept_now()?;
        Ok(SolveReport {
            channels,
            levels: kept.solver.levels(),
            hierarchy_ms,
            solve_ms,
            hierarchy_built,
            hierarchy_refreshed: refreshed.is_some(),
            interrupted,
            coarse_level: None,
            choice,
        })
    }

    /// [`Method::Auto`]: Jacobi-PCG's probe, the prediction, and V-cycle-PCG
    /// from the probe's iterate when it is predicted to cost less. Returns
    /// the reports (iterations of both), the choice and the time of a
    /// hierarchy built here (ms; `None` when none was).
    fn solve_auto(
        &mut self,
        kept: &Kept,
        options: &SolveOptions,
        tolerance: f64,
        stop_now: &dyn Fn() -> bool,
    ) -> Result<([Report; 3], Choice, Option<f64>), Error> {
        let hierarchy_kept = matches!(kept.solver, KeptSolver::VCycles(_));
        let mut estimator = Estimator::new(tolerance, hierarchy_kept, self.settings.auto_costs);
        let mut prediction = None;
        let mut switching = false;
        let probe = self.block_pcg(None, options, &mut |p: &Progress<'_>| {
            if stop_now() {
                return ControlFlow::Break(());
            }
            if let Some(guess) = estimator.step(p) {
                // Keep the estimate that came closest to a switch: the
                // report's reason for staying (or for switching).
                let margin = |p: &Prediction| p.v_cycle_cost - p.jacobi_cost;
                if prediction.is_none_or(|best: Prediction| margin(&guess) < margin(&best)) {
                    prediction = Some(guess);
                }
                if guess.switches() {
                    prediction = Some(guess);
                    switching = true;
                    return ControlFlow::Break(());
                }
            }
            ControlFlow::Continue(())
        })?;
        let jacobi = Choice {
            solver: Solver::JacobiPcg,
            forced: false,
            prediction,
        };
        if !switching {
            return Ok((probe, jacobi, None));
        }
        let built_ms = if hierarchy_kept {
            None
        } else {
            Some(self.keep_auto_v_cycles()?)
        };
        let kept = self.kept_now()?;
        let KeptSolver::VCycles(v) = &kept.solver else {
            return Ok((probe, jacobi, built_ms));
        };
        let v = per_channel(v);
        let done = probe.iter().map(|r| r.iterations).max().unwrap_or(0);
        let rest = SolveOptions::new(tolerance, self.settings.max_iterations.saturating_sub(done))
            .allow_unconverged();
        let reports = self.block_pcg(Some(v), &rest, &mut |_| budget_flow(stop_now()))?;
        let reports = std::array::from_fn(|c| Report {
            iterations: probe[c].iterations + reports[c].iterations,
            ..reports[c]
        });
        let choice = Choice {
            solver: Solver::VCyclePcg,
            ..jacobi
        };
        Ok((reports, choice, built_ms))
    }

    /// The three channels solved as one block from the current `φ`:
    /// preconditioned by `v` (a V-cycle per channel) or by Jacobi.
    fn block_pcg(
        &mut self,
        v: Option<[&VCycle<'static>; 3]>,
        options: &SolveOptions,
        monitor: &mut dyn FnMut(&Progress<'_>) -> ControlFlow<()>,
    ) -> Result<[Report; 3], Error> {
        let block = self.block()?;
        let b = [&self.rhs[0][..], &self.rhs[1][..], &self.rhs[2][..]];
        let [x0, x1, x2] = &mut self.phi;
        let x = [&mut x0[..], &mut x1[..], &mut x2[..]];
        let reports = match v {
            Some(v) => {
                let m: [&dyn Preconditioner; 3] = [v[0], v[1], v[2]];
                block.pcg(b, x, m, options, Some(monitor))?
            }
            None => block.cg(b, x, options, Some(monitor))?,
        };
        Ok(reports)
    }

    /// The block solvers' form of the matrices, made with them (part of
    /// the assembly, as TransCut assembles into its solver's format). A
    /// matrix the block refuses (which the assembly does not make) is
    /// reported by the next solve.
    fn assemble_block(&mut self) {
        if self.block().is_err() {
            self.block_current = false;
        }
    }

    /// The matrices as one block, made or refreshed as they changed.
    fn block(&mut self) -> Result<Arc<Block3>, Error> {
        if let (Some(block), true) = (&self.block, self.block_current) {
            return Ok(block.clone());
        }
        let m = [&self.matrices[0], &self.matrices[1], &self.matrices[2]];
        let block = match &self.block {
            Some(old) => match old.refreshed(m) {
                Ok(b) => b,
                Err(
                    multires::Error::PatternMismatch { .. } | multires::Error::BlockSize { .. },
                ) => Block3::new(m)?,
                Err(e) => return Err(e.into()),
            },
            None => Block3::new(m)?,
        };
        let block = Arc::new(block);
        self.block = Some(block.clone());
        self.block_current = true;
        Ok(block)
    }

    /// Builds the solver's hierarchy unless one of the current method is
    /// kept; returns the build time (ms) when it built one.
    fn ensure_kept(&mut self) -> Result<Option<f64>, Error> {
        let s = self.settings;
        if self
            .kept
            .as_ref()
            .is_some_and(|k| k.method == s.method && k.share_hierarchy == s.share_hierarchy)
        {
            return Ok(None);
        }
        // Free the old hierarchy before building the new one.
        self.kept = None;
        let t = Instant::now();
        let positions = self.mesh.positions();
        let weights = Weights::Points(&positions);
        let matrices = &self.matrices;
        let solver = match s.method {
            // Auto builds a hierarchy only when its probe says so.
            Method::JacobiPcg | Method::Auto => KeptSolver::Jacobi,
            Method::VCyclePcg => self.build_v_cycles()?,
            Method::Cascade | Method::CascadeGalerkin => {
                let copts = if s.method == Method::Cascade {
                    CascadeOptions::default()
                } else {
                    CascadeOptions::galerkin()
                };
                KeptSolver::Cascade(Cascade::new(&matrices[1], weights, &copts)?)
            }
        };
        // Jacobi builds nothing: neither a build to count nor its time.
        let hierarchy = !matches!(solver, KeptSolver::Jacobi);
        self.kept = Some(Arc::new(Kept {
            method: s.method,
            share_hierarchy: s.share_hierarchy,
            solver,
        }));
        self.values_changed = false;
        if !hierarchy {
            return Ok(None);
        }
        self.hierarchy_builds += 1;
        Ok(Some(ms(t)))
    }

    /// Builds the V-cycles for [`Method::Auto`] and keeps them; returns
    /// the build's time, ms.
    fn keep_auto_v_cycles(&mut self) -> Result<f64, Error> {
        let t = Instant::now();
        let solver = self.build_v_cycles()?;
        self.kept = Some(Arc::new(Kept {
            method: Method::Auto,
            share_hierarchy: self.settings.share_hierarchy,
            solver,
        }));
        self.hierarchy_builds += 1;
        self.values_changed = false;
        Ok(ms(t))
    }

    /// The V-cycles of the three channels: one hierarchy (the green
    /// channel's) with each channel's operators on it, or one each
    /// (see [`SolverSettings::share_hierarchy`]).
    fn build_v_cycles(&self) -> Result<KeptSolver, Error> {
        let positions = self.mesh.positions();
        let weights = Weights::Points(&positions);
        let matrices = &self.matrices;
        let vopts = VCycleOptions::default();
        let v = if self.settings.share_hierarchy {
            // A preview's coarse solve needs the channel's own coarse
            // system.
            let green = VCycle::new(&matrices[1], weights, &vopts)?.into_owned();
            let red = green.refreshed(&matrices[0])?;
            let blue = green.refreshed(&matrices[2])?;
            vec![red, green, blue]
        } else {
            let mut v = Vec::with_capacity(3);
            for m in matrices {
                v.push(VCycle::new(m, weights, &vopts)?.into_owned());
            }
            v
        };
        Ok(KeptSolver::VCycles(v))
    }

    /// Recomputes the kept V-cycles' operators for the current matrices
    /// when their diagonal drifted past [`REFRESH_DRIFT`]; returns the
    /// time (ms) when it did.
    fn refresh_kept(&mut self) -> Result<Option<f64>, Error> {
        if !std::mem::take(&mut self.values_changed) {
            return Ok(None);
        }
        let Some(kept) = &self.kept else {
            return Ok(None);
        };
        let KeptSolver::VCycles(v) = &kept.solver else {
            return Ok(None);
        };
        let channel = |k: usize| if v.len() == 3 { k } else { 1 };
        let drift = v
            .iter()
            .enumerate()
            .map(|(k, v)| v.diagonal_drift(&self.matrices[channel(k)]))
            .fold(0.0f64, f64::max);
        if drift <= REFRESH_DRIFT {
            return Ok(None);
        }
        let t = Instant::now();
        self.kept = self.kept_for_matrices()?;
        self.hierarchy_refreshes += 1;
        Ok(Some(ms(t)))
    }

    /// The kept V-cycles with their operators recomputed for the current
    /// matrices on the kept hierarchy ([`multires::VCycle::refreshed`]):
    /// bit for bit the V-cycles a build or refresh made when the matrices
    /// were these, so undo can re-derive a replaced hierarchy from the
    /// media of that time instead of storing it. `None` without a kept
    /// state; a kept state that is not refreshable (Jacobi, the cascade)
    /// is returned as it is.
    ///
    /// # Errors
    /// Those of [`multires::VCycle::refreshed`].
    pub(crate) fn kept_for_matrices(&self) -> Result<Option<Arc<Kept>>, Error> {
        let Some(kept) = &self.kept else {
            return Ok(None);
        };
        let KeptSolver::VCycles(v) = &kept.solver else {
            return Ok(Some(kept.clone()));
        };
        let channel = |k: usize| if v.len() == 3 { k } else { 1 };
        let mut fresh = Vec::with_capacity(v.len());
        for (k, v) in v.iter().enumerate() {
            fresh.push(v.refreshed(&self.matrices[channel(k)])?);
        }
        Ok(Some(Arc::new(Kept {
            method: kept.method,
            share_hierarchy: kept.share_hierarchy,
            solver: KeptSolver::VCycles(fresh),
        })))
    }

    /// How many times the kept hierarchy's coarse operators were
    /// recomputed for drifted matrices (see [`REFRESH_DRIFT`]).
    pub fn hierarchy_refreshes(&self) -> usize {
        self.hierarchy_refreshes
    }

    /// Bytes a kept solver state replaced by a refresh holds apart from
    /// what the refreshed one shares with it (see
    /// [`multires::VCycle::own_bytes`]; 0 for Jacobi and the cascade,
    /// which are not refreshed).
    pub(crate) fn kept_bytes(kept: &Option<Arc<Kept>>) -> usize {
        match kept.as_deref().map(|k| &k.solver) {
            Some(KeptSolver::VCycles(v)) => v.iter().map(VCycle::own_bytes).sum(),
            _ => 0,
        }
    }

    /// How many times this object (and the objects it was cloned from)
    /// built a solver hierarchy: once after creation and after each cut;
    /// paint, light and material edits keep it.
    pub fn hierarchy_builds(&self) -> usize {
        self.hierarchy_builds
    }

    /// Drops the kept hierarchy, so that the next solve builds a new one
    /// from the current matrices (worth it after painting most of the
    /// object with a very different medium: the kept one still converges,
    /// in more iterations).
    pub fn forget_hierarchy(&mut self) {
        self.kept = None;
    }

    /// The hemispherical flux `J⁺` (W/mm², RGB) that meets the boundary
    /// from inside at each boundary vertex, in the order of
    /// [`TetMesh::boundary_vertices`]:
    /// `J⁺ = [(1 + 1/A) φ − 4 q / (1 + F_dr)] / 4 = (φ − 2q) / (2 (1 + F_dr))`
    /// (Arbree et al.; the bracket of TransCut's Eq. 3), clamped at 0.
    /// `(1 − F_dr) J⁺` of it leaves the object. Radiance is this times
    /// [`fresnel::exit_radiance_factor`] (in air) or
    /// [`fresnel::inside_radiance_factor`] (Eq. 3 as printed), which a
    /// renderer evaluates per fragment from the direction to its eye.
    pub fn boundary_flux(&self) -> Vec<[f64; 3]> {
        let a = self.boundary_factor();
        let fdr = self.fdr();
        self.mesh
            .boundary_vertices()
            .iter()
            .enumerate()
            .map(|(k, &v)| {
                [0, 1, 2].map(|c| {
                    let j = ((1.0 + 1.0 / a) * self.phi[c][v as usize]
                        - 4.0 * self.q[k][c] / (1.0 + fdr))
                        / 4.0;
                    j.max(0.0)
                })
            })
            .collect()
    }

    /// Outgoing radiance in air (W/(mm² sr), RGB) at each boundary vertex,
    /// in the order of [`TetMesh::boundary_vertices`]:
    /// `L_o = F_t(ω_o) J⁺ / (π η²)` — TransCut's Eq. 3 divided by `η²`,
    /// because Eq. 3 as printed is the radiance just inside the boundary
    /// and `L/η²` is invariant across it (see
    /// [`fresnel::exit_radiance_factor`]; [`radiance_inside`](Self::radiance_inside)
    /// is the printed form). Integrated over the boundary and the outgoing
    /// hemisphere it equals the power that entered minus the power
    /// absorbed. `F_t` is at the angle between the vertex normal and
    /// `toward` (the unit direction to the viewer, in mesh coordinates), or
    /// at normal exitance when `None`. Never negative.
    pub fn radiance(&self, toward: Option<DVec3>) -> Vec<[f64; 3]> {
        self.radiance_with(toward, fresnel::exit_radiance_factor)
    }

    /// TransCut's Eq. 3 exactly as printed,
    /// `L = F_t(ω_o) / (4π) · [(1 + 1/A) φ − 4 q / (1 + F_dr)]`: the
    /// radiance just *inside* the boundary, `η²` times the radiance in air
    /// that [`radiance`](Self::radiance) gives (1.69× at η = 1.3). For
    /// comparison with the paper and with renders made before the
    /// correction; arguments and order as for [`radiance`](Self::radiance).
    pub fn radiance_inside(&self, toward: Option<DVec3>) -> Vec<[f64; 3]> {
        self.radiance_with(toward, fresnel::inside_radiance_factor)
    }

    /// [`boundary_flux`](Self::boundary_flux) times `factor(cos, η)` per
    /// boundary vertex.
    fn radiance_with(&self, toward: Option<DVec3>, factor: fn(f64, f64) -> f64) -> Vec<[f64; 3]> {
        let mesh = &self.mesh;
        let toward = toward.map(|d| d.normalize_or_zero());
        mesh.boundary_vertices()
            .iter()
            .zip(self.boundary_flux())
            .map(|(&v, j)| {
                let cos = toward.map_or(1.0, |d| mesh.vertex_normals()[v as usize].dot(d));
                let f = factor(cos, self.eta);
                j.map(|x| f * x)
            })
            .collect()
    }

    /// The P1 finite-element reference system of this object (Arbree et
    /// al.), assembled by `how`; see [`P1Matrices`].
    pub fn fem_reference(&self, how: Integration) -> P1Matrices {
        fem::assemble(&self.mesh, &self.coefficients, how)
    }

    /// The rigid transform used for display (fractured pieces moved
    /// apart); the physics stays in the mesh's own frame.
    pub fn transform(&self) -> DAffine3 {
        self.transform
    }

    /// Sets the display transform.
    pub fn set_transform(&mut self, transform: DAffine3) {
        self.transform = transform;
    }

    /// The vertex positions moved by the display transform.
    pub fn display_positions(&self) -> Vec<DVec3> {
        self.mesh
            .positions()
            .iter()
            .map(|&p| self.transform.transform_point3(p))
            .collect()
    }
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// `η` must be positive and finite.
pub(crate) fn check_eta(eta: f64) -> Result<(), Error> {
    if !(eta.is_finite() && eta > 0.0) {
        return Err(Error::BadArgument {
            what: "the index of refraction eta".into(),
            value: eta,
            need: "it must be positive and finite",
        });
    }
    Ok(())
}
