//! The plain texture used as conversion source, bake target and
//! benchmark baseline: bilinear and trilinear lookups by hand.

use mesh_colors::{Texture, Wrap};

#[test]
fn bilinear_and_trilinear_by_hand() {
    // 2×2: 0 1 / 2 3.
    let t = Texture::new(2, 2, 1, vec![0.0, 1.0, 2.0, 3.0])
        .unwrap()
        .with_wrap(Wrap::ClampToEdge);
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

#[test]
fn mirrored_repeat_reflects_every_other_copy() {
    // 4×1: 0 1 2 3, read at texel centres across three copies.
    let t = Texture::new(4, 1, 1, vec![0.0, 1.0, 2.0, 3.0])
        .unwrap()
        .with_wrap(Wrap::MirroredRepeat);
    let at = |x: i32| {
        let mut out = [0.0f32];
        t.bilinear([(x as f32 + 0.5) / 4.0, 0.5], &mut out);
        out[0]
    };
    // Texels -4..8: 3 2 1 0 | 0 1 2 3 | 3 2 1 0.
    let want = [3.0, 2.0, 1.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 2.0, 1.0, 0.0];
    for (k, &w) in want.iter().enumerate() {
        assert_eq!(at(k as i32 - 4), w, "texel {}", k as i32 - 4);
    }
    // Continuous across the mirror line at u = 1: the lookup halfway
    // between texel 3 and its mirror image is texel 3 itself.
    let mut out = [0.0f32];
    t.bilinear([1.0, 0.5], &mut out);
    assert_eq!(out[0], 3.0);
    // Repeat and ClampToEdge at the same points, for contrast.
    let r = t.clone().with_wrap(Wrap::Repeat);
    r.bilinear([(-1.0 + 0.5) / 4.0, 0.5], &mut out);
    assert_eq!(out[0], 3.0);
    r.bilinear([(4.0 + 0.5) / 4.0, 0.5], &mut out);
    assert_eq!(out[0], 0.0);
    let c = t.clone().with_wrap(Wrap::ClampToEdge);
    c.bilinear([(6.0 + 0.5) / 4.0, 0.5], &mut out);
    assert_eq!(out[0], 3.0);
    // And far away, with MIP levels: no panic, values in range.
    let mut m = t.clone();
    m.build_mips();
    for u in [-1e6f32, -12.3, 7.9, 1e6] {
        m.trilinear([u, u], 0.7, &mut out);
        assert!((0.0..=3.0).contains(&out[0]), "{u}: {}", out[0]);
    }
    assert_eq!(Wrap::default(), Wrap::Repeat);
    assert_eq!(t.texel(3, 0), Some(&[3.0f32][..]));
    assert_eq!(t.texel(4, 0), None);
}
