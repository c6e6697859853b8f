//! Rec. 709 luminance: one channel from an RGB texture (a density, a
//! grey-scale bake).

/// The Rec. 709 (sRGB primaries) luminance of linear RGB:
/// `0.2126 R + 0.7152 G + 0.0722 B`. The same function, with the same
/// values, as in the other trilux crates.
///
/// ```
/// let y = mesh_colors::luminance([1.0, 1.0, 1.0]);
/// assert!((y - 1.0).abs() < 1e-6);
/// ```
#[inline]
pub fn luminance(rgb: [f32; 3]) -> f32 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

#[cfg(test)]
mod tests {
    use super::luminance;

    #[test]
    fn rec_709_weights() {
        for (rgb, want) in [
            ([1.0, 0.0, 0.0], 0.2126),
            ([0.0, 1.0, 0.0], 0.7152),
            ([0.0, 0.0, 1.0], 0.0722),
            // 0.1063 + 0.1788 + 0.1444.
            ([0.5, 0.25, 2.0], 0.4295),
        ] {
            assert!((luminance(rgb) - want).abs() < 1e-6, "{rgb:?}");
        }
    }
}
