//! The plain texture used as conversion source, bake target and
//! benchmark baseline: bilinear and trilinear lookups by hand.

use mesh_colors::{Texture, Wrap};

#[test]
fn bilinear_and_trilinear_by_hand() {
    // 2×2: 0 1 / 2 3.
    let t = Texture::new(2, 2, 1, vec![0.0, 1.0, 2.0, 3.0])
        .unwrap()
        .with_wrap(Wrap::Clamp);
    let mut out = [0.0f32];
    t.bilinear([0.25, 0.25], &mut out);
    assert_eq!(out[0], 0.0); // texel centre
    t.bilinear([0.75, 0.75], &mut out);
    assert_eq!(out[0], 3.0);
    t.bilinear([0.5, 0.5], &mut out);
    assert_eq!(out[0], 1.5); // the mean of four
    t.bilinear([0.5, 0.25], &mut out);
    assert_eq!(out[0], 0.5);
    t.bilinear([-3.0, 0.25], &mut out);
    assert_eq!(out[0], 0.0); // clamped
    let r = t.clone().with_wrap(Wrap::Repeat);
    r.bilinear([0.0, 0.25], &mut out);
    assert_eq!(out[0], 0.5); // halfway between texel 1 (wrapped) and 0
    let mut m = t.clone();
    m.build_mips();
    m.trilinear([0.3, 0.6], 1.0, &mut out);
    assert!((out[0] - 1.5).abs() < 1e-6); // the 1×1 level is the mean
    m.trilinear([0.25, 0.25], 0.5, &mut out);
    assert_eq!(out[0], 0.75); // halfway between 0 and 1.5
    m.trilinear([0.25, 0.25], f32::NAN, &mut out);
    assert_eq!(out[0], 0.0);
    assert!(Texture::new(0, 2, 1, vec![]).is_err());
    assert!(Texture::new(2, 2, 0, vec![]).is_err());
}
