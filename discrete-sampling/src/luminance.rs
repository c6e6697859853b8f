//! Rec. 709 luminance: the usual weight of an RGB environment map texel.

/// The Rec. 709 (sRGB primaries) luminance of linear RGB:
/// `0.2126 R + 0.7152 G + 0.0722 B`. The same function, with the same
/// values, as in the other trilux crates.
///
/// ```
/// let y = discrete_sampling::luminance([0.5, 0.25, 2.0]);
/// assert!((y - 0.4295).abs() < 1e-6);
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
            // 0.1063 + 0.1788 + 0.1444 (the shared convention note says
            // 0.46295, which is not what these weights give).
            ([0.5, 0.25, 2.0], 0.4295),
        ] {
            assert!((luminance(rgb) - want).abs() < 1e-6, "{rgb:?}");
        }
    }
}
