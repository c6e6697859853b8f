//! 3D painting (Sec. 5.1): brush strokes on the samples themselves, with
//! no UV bookkeeping. A uniform grid over the samples' 3D positions finds
//! the samples near the brush, so a stroke costs the samples in the grid
//! cells it overlaps (a small multiple of the samples it touches when the
//! cell size is about the brush radius), not the size of the mesh.

use glam::Vec3;

use crate::grid::Grid;
use crate::structure::MeshColors;
use crate::undo::Recorder;
use crate::{Error, MAX_CHANNELS};

/// How a brush combines its colour with a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blend {
    /// Replace the colour inside the radius (no falloff).
    Set,
    /// Move towards the brush colour by the falloff weight.
    Mix,
    /// Add the brush colour times the falloff weight (densities, masks).
    Add,
}

/// A brush dab: a sphere with a smooth falloff `w = strength · (1 −
/// (d/r)²)²`, which is 1 at the centre and reaches 0 with zero slope at
/// the rim, so strokes leave no visible edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Brush<'a> {
    /// The centre, in the mesh's space.
    pub center: Vec3,
    /// The radius; samples farther away are untouched.
    pub radius: f32,
    /// The colour, one value per channel.
    pub color: &'a [f32],
    /// Scales the falloff weight (1: full strength).
    pub strength: f32,
    /// How the colour is applied.
    pub blend: Blend,
}

impl Brush<'_> {
    /// The falloff weight at distance `d`.
    pub fn weight(&self, d: f32) -> f32 {
        let x = d / self.radius;
        if x > 1.0 {
            0.0
        } else {
            let s = 1.0 - x * x;
            self.strength * s * s
        }
    }
}

/// What a stroke did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Stroke {
    /// Samples within the radius (changed, unless the weight was zero).
    pub touched: usize,
    /// Samples whose distance was computed (the cost).
    pub examined: usize,
}

/// A spatial index of the sample positions of one [`MeshColors`] on one
/// set of vertex positions. Rebuild it after a topology edit, a resolution
/// change or a vertex move.
#[derive(Debug, Clone)]
pub struct Painter {
    positions: Vec<Vec3>,
    grid: Grid,
    channels: usize,
}

impl Painter {
    /// Indexes the samples of `colors` on a mesh with vertex `positions`,
    /// in grid cells of size `cell` (about the usual brush radius).
    ///
    /// # Errors
    /// [`Error::ChannelMismatch`] if `positions` is shorter than the vertex
    /// count, [`Error::NonFinite`] for a non-finite position or cell size.
    pub fn new(colors: &MeshColors, positions: &[Vec3], cell: f32) -> Result<Self, Error> {
        let t = colors.topology();
        check_vertex_positions(t.vertex_count(), positions)?;
        if !(cell.is_finite() && cell > 0.0) {
            return Err(Error::NonFinite {
                what: "cell size",
                index: 0,
            });
        }
        let sample_positions: Vec<Vec3> = (colors.sites().iter().enumerate())
            .map(|(i, s)| {
                s.position(t, positions)
                    .map_or_else(|| positions[i], |p| p.as_vec3())
            })
            .collect();
        Ok(Self::from_positions(
            sample_positions,
            cell,
            colors.channels(),
        ))
    }

    /// The index of samples at `positions` (finite), in cells of `cell`.
    fn from_positions(positions: Vec<Vec3>, cell: f32, channels: usize) -> Self {
        Self {
            grid: Grid::of_points(&positions, cell),
            positions,
            channels,
        }
    }

    /// The 3D position of every sample.
    pub fn sample_positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Calls `f(sample, distance)` for every sample within `radius` of
    /// `center`; returns how many were examined.
    pub fn for_each_within(
        &self,
        center: Vec3,
        radius: f32,
        mut f: impl FnMut(usize, f32),
    ) -> usize {
        let mut examined = 0;
        self.grid.for_each_list_near(center, radius, |list| {
            for &i in list {
                examined += 1;
                let d = self.positions[i as usize].distance(center);
                if d <= radius {
                    f(i as usize, d);
                }
            }
        });
        examined
    }

    /// Applies one brush dab to `colors` (the ones this painter indexed).
    ///
    /// # Errors
    /// [`Error::ChannelMismatch`] if the brush colour or `colors` do not
    /// match this painter; [`Error::NonFinite`] for a bad radius.
    pub fn paint(&self, colors: &mut MeshColors, brush: &Brush<'_>) -> Result<Stroke, Error> {
        self.dab(colors, brush, None)
    }

    /// As [`Painter::paint`], recording into `recorder` the old value of
    /// every sample the dab changes (once per stroke: a sample already
    /// recorded by an earlier dab keeps its first value), for undo
    /// (Sec. 5.1; see [`crate::undo`]).
    ///
    /// # Errors
    /// As for [`Painter::paint`], and [`Error::StaleUndo`] if `recorder`
    /// was made for other colours; nothing changes then.
    pub fn paint_recorded(
        &self,
        colors: &mut MeshColors,
        brush: &Brush<'_>,
        recorder: &mut Recorder,
    ) -> Result<Stroke, Error> {
        recorder.fits(colors)?;
        self.dab(colors, brush, Some(recorder))
    }

    fn dab(
        &self,
        colors: &mut MeshColors,
        brush: &Brush<'_>,
        mut recorder: Option<&mut Recorder>,
    ) -> Result<Stroke, Error> {
        if brush.color.len() != self.channels || colors.channels() != self.channels {
            return Err(Error::ChannelMismatch {
                what: "brush colour",
                expected: self.channels,
                got: brush.color.len(),
            });
        }
        if colors.sample_count() != self.positions.len() {
            return Err(Error::ChannelMismatch {
                what: "samples indexed by this painter",
                expected: self.positions.len(),
                got: colors.sample_count(),
            });
        }
        if !(brush.radius.is_finite() && brush.radius > 0.0 && brush.center.is_finite()) {
            return Err(Error::NonFinite {
                what: "brush",
                index: 0,
            });
        }
        let mut touched = 0;
        let examined = self.for_each_within(brush.center, brush.radius, |i, d| {
            touched += 1;
            let w = brush.weight(d);
            let s = colors.sample_at_mut(i);
            let mut new = [0.0f32; MAX_CHANNELS];
            let new = &mut new[..s.len()];
            for ((n, &x), &c) in new.iter_mut().zip(s.iter()).zip(brush.color) {
                *n = match brush.blend {
                    Blend::Set => c,
                    Blend::Mix => x + w * (c - x),
                    Blend::Add => x + w * c,
                };
            }
            // Only samples whose bits change are recorded (the rim of a
            // dab, weight 0, changes nothing).
            if let Some(r) = recorder.as_deref_mut()
                && new
                    .iter()
                    .zip(s.iter())
                    .any(|(a, b)| a.to_bits() != b.to_bits())
            {
                r.note(i, s);
            }
            s.copy_from_slice(new);
        });
        Ok(Stroke { touched, examined })
    }
}

/// That a mesh of `vertex_count` vertices has a finite position for each.
///
/// # Errors
/// [`Error::ChannelMismatch`] for too few positions, [`Error::NonFinite`]
/// naming the first non-finite one.
pub(crate) fn check_vertex_positions(vertex_count: usize, positions: &[Vec3]) -> Result<(), Error> {
    if positions.len() < vertex_count {
        return Err(Error::ChannelMismatch {
            what: "vertex positions",
            expected: vertex_count,
            got: positions.len(),
        });
    }
    match positions.iter().position(|p| !p.is_finite()) {
        Some(i) => Err(Error::NonFinite {
            what: "position",
            index: i,
        }),
        None => Ok(()),
    }
}
