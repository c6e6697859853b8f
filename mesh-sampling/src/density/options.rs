//! What the density sampler is asked to do: the density source, the mode,
//! the depth rule and the build options.

use crate::{DensityTexture, Layout};

/// Where the density comes from.
#[derive(Debug, Clone, Copy)]
pub enum Density<'a> {
    /// A texture looked up at the mesh's UVs.
    Texture(&'a DensityTexture),
    /// One weight per triangle, constant over it.
    PerFace(&'a [f32]),
    /// One weight per vertex, linear over each triangle.
    PerVertex(&'a [f32]),
}

/// Which density a texture sampler draws from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mode {
    /// The paper's `p′` (Eq. 2): the density sampled at each
    /// sub-triangle's barycenter, constant over the sub-triangle. Fastest;
    /// a sub-triangle straddling a texel edge gets one value.
    #[default]
    Approximate,
    /// The filtered texture exactly: `p′`'s subdivision as the proposal,
    /// weighted by a bound of the density on each sub-triangle (its exact
    /// maximum over the sub-triangle's UV bounding box), and a rejection
    /// step. [`DensitySampler::acceptance`](crate::DensitySampler::acceptance) says how often it accepts.
    Exact,
}

/// How the subdivision depth of a triangle follows the texels it covers
/// (Šik & Křivánek 2013, Sec. 3.4: "each triangle is subdivided so that its
/// sub-triangles are smaller than a texel").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Depth {
    /// The level `L` with `4^L` nearest to the texel count `T` of the
    /// triangle (in log scale): sub-triangles of half a texel to two.
    Nearest,
    /// The paper's rule (the default): the smallest `L` with
    /// `T / 4^L ≤ 1`, so every sub-triangle covers at most one texel.
    /// Measured on the six data meshes with a noise and an HDR density
    /// (the `depth` example), it brings `p′` closer to the filtered
    /// density than [`Nearest`](Self::Nearest) in every case (total
    /// variation 1–7% lower) for 2–7% more pieces, since the edge rule
    /// already subdivides most triangles that far.
    #[default]
    AtMostOneTexel,
}

/// How finely a texture density is subdivided and merged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Approximate (the paper) or exact.
    pub mode: Mode,
    /// How a piece is drawn: the alias table whose columns are the
    /// records (default, one or two 16-byte columns a draw) or the
    /// order-preserving inversion method.
    pub layout: Layout,
    /// The depth rule by texel count (both rules also subdivide until no
    /// sub-triangle edge spans more than two texels).
    pub depth: Depth,
    /// The most sub-triangles the subdivision may make before merging,
    /// `Σ 4^L` over the triangles whose texture footprint is not constant
    /// (a constant one is one piece). Computed before anything is built;
    /// when the depths ask for more, the deepest triangles are capped at
    /// a common level until the sum fits (coarser where it must: each
    /// capped sub-triangle takes the density at its barycenter, and the
    /// exact mode stays exact, with a lower acceptance). Default
    /// `1 << 22` (4,194,304: about 200 MB of tables), four sub-triangles
    /// per texel of a 1024² texture; the error
    /// [`Error::TooManyPieces`](crate::Error::TooManyPieces) only when even one piece per triangle
    /// exceeds it.
    pub max_pieces: usize,
    /// The deepest subdivision level, at most 13 (`4^13` sub-triangles for
    /// one triangle). Default 11: a triangle spanning a 2048² texture.
    pub max_level: u8,
    /// Levels beyond the one that makes sub-triangles about a texel (and
    /// their edges no longer than two). Each one divides the approximation error of
    /// [`Mode::Approximate`] (or the rejection rate of [`Mode::Exact`])
    /// roughly by two, and costs four times the memory.
    pub extra_levels: u8,
    /// Relative tolerance for merging: 0 (default) merges only equal
    /// values, so `p′` is unchanged; `t > 0` merges four siblings when
    /// `max − min ≤ t · max` (approximate mode: their mean replaces the
    /// four values; exact mode: their maximum), and stops subdividing a
    /// sub-triangle (of 16 leaves or more) whose UV bounding box the
    /// texture's min/max pyramid bounds within the same tolerance, so its
    /// leaves are never made (approximate mode: it takes the density at its
    /// barycenter; exact mode: the pyramid's maximum). Trades accuracy
    /// (approximate mode: within `t` of `p′` in relative terms) or
    /// acceptance (exact mode) for memory and speed: fewer pieces, a
    /// smaller table. The `depth` example reports the total-variation
    /// distance to the filtered density for a few tolerances.
    pub merge_tolerance: f32,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            mode: Mode::Approximate,
            layout: Layout::Alias,
            depth: Depth::AtMostOneTexel,
            max_pieces: DEFAULT_MAX_PIECES,
            max_level: 11,
            extra_levels: 0,
            merge_tolerance: 0.0,
        }
    }
}

/// The default of [`Options::max_pieces`].
pub const DEFAULT_MAX_PIECES: usize = 1 << 22;
