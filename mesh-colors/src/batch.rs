//! Batch lookups: many points at once, on all threads with the `rayon`
//! feature. Each output depends only on its own point, so the result is
//! the same on any number of threads.

use crate::Error;
use crate::filter::{FINEST, eval};
use crate::mip::MipMap;
use crate::structure::MeshColors;

/// Points per parallel task: large enough to amortise scheduling.
#[cfg(feature = "rayon")]
const CHUNK: usize = 4096;

/// Checks every point's face and the output length.
fn check_batch(mc: &MeshColors, points: &[(u32, [f32; 3])], out: &[f32]) -> Result<(), Error> {
    if out.len() != points.len() * mc.channels {
        return Err(Error::ChannelMismatch {
            what: "batch output (points × channels)",
            expected: points.len() * mc.channels,
            got: out.len(),
        });
    }
    if let Some(&(f, _)) = points.iter().find(|p| p.0 as usize >= mc.face_level.len()) {
        return Err(Error::MissingFace {
            face: f as usize,
            count: mc.face_level.len(),
        });
    }
    Ok(())
}

/// Runs `one(point index, output)` over all points, in parallel chunks
/// with the `rayon` feature.
fn run(c: usize, n: usize, out: &mut [f32], one: impl Fn(usize, &mut [f32]) + Sync + Send) {
    #[cfg(feature = "rayon")]
    {
        use rayon::prelude::*;
        out.par_chunks_mut(CHUNK * c)
            .enumerate()
            .for_each(|(k, chunk)| {
                for (i, o) in chunk.chunks_mut(c).enumerate() {
                    one(k * CHUNK + i, o);
                }
            });
    }
    #[cfg(not(feature = "rayon"))]
    for (i, o) in out.chunks_mut(c).enumerate().take(n) {
        one(i, o);
    }
    let _ = n;
}

impl MeshColors {
    /// Linear lookups of many `(face, barycentrics)` points into `out`
    /// (`channels()` values per point), equal to [`MeshColors::linear`]
    /// point by point.
    ///
    /// # Errors
    /// [`Error::MissingFace`] for the first bad face, or
    /// [`Error::ChannelMismatch`] for a wrong output length; nothing is
    /// written then.
    pub fn linear_into(&self, points: &[(u32, [f32; 3])], out: &mut [f32]) -> Result<(), Error> {
        check_batch(self, points, out)?;
        run(self.channels, points.len(), out, |i, o| {
            let (f, b) = points[i];
            eval(self, f as usize, b, FINEST, false, o);
        });
        Ok(())
    }
}

impl MipMap {
    /// Trilinear lookups of many points with one footprint each, equal to
    /// [`MipMap::trilinear`] point by point.
    ///
    /// # Errors
    /// As for [`MeshColors::linear_into`], and [`Error::ChannelMismatch`]
    /// when `footprints` and `points` differ in length.
    pub fn trilinear_into(
        &self,
        points: &[(u32, [f32; 3])],
        footprints: &[f32],
        out: &mut [f32],
    ) -> Result<(), Error> {
        check_batch(&self.colors, points, out)?;
        if footprints.len() != points.len() {
            return Err(Error::ChannelMismatch {
                what: "footprints (one per point)",
                expected: points.len(),
                got: footprints.len(),
            });
        }
        run(self.colors.channels, points.len(), out, |i, o| {
            let (f, b) = points[i];
            // Faces and lengths were checked above, so this cannot fail.
            let _ = self.trilinear(f as usize, b, footprints[i], o);
        });
        Ok(())
    }
}
