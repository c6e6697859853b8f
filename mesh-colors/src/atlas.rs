//! Mesh colours back to a UV texture: an atlas plus per-corner UVs that
//! any engine can draw with ordinary bilinear filtering.
//!
//! **Layout.** Face `f` of resolution `R` is stored as its own lattice:
//! sample `C_ij` (Eq. 4) at texel `(i, j)` of its block, a right triangle
//! of `(R+1)(R+2)/2` texels, and its corner UVs are the texel centres of
//! its three corner samples. Because UVs are affine in the barycentrics, a
//! point with barycentrics `b` lands at texel coordinates `R·(b0, b1)`,
//! exactly where the mesh-colour linear filter looks (Fig. 7): bilinear
//! filtering blends the same samples, plus a bounded twist term
//! `fx·fy·(C11 − C10 − C01 + C00)` (zero for any affine colour, and of the
//! order of the linear filter's own error otherwise). Along the
//! hypotenuse, the texels one step outside the triangle hold the
//! parallelogram extrapolation `C(i,j−1) + C(i−1,j) − C(i−1,j−1)`, so the
//! squares that straddle it are exact for affine colours too. Every face
//! stores its own copy of its vertex and edge samples (interpolated where
//! a finer face meets a coarser edge, the continuity rule), so both sides
//! of a mesh edge read identical values: no seam at level 0.
//!
//! **Packing.** By default two faces of the same resolution share an
//! `(R+3) × (R+2)` block, the second turned half a turn into the unused
//! half, so the atlas holds about one texel per sample plus a border, and
//! blocks get a gutter of `gutter` texels repeating their border: right
//! for bilinear filtering, while an engine's MIP levels would start to mix
//! the paired faces and neighbouring blocks.
//!
//! **MIP-safe packing** ([`Options::mip_levels`] = `k > 0`): one face per
//! block, blocks sized and placed on multiples of `2^k` with a gutter of at
//! least `2^k`, and every texel of the block outside the triangle holding
//! the linear extrapolation of the nearest lattice triangle. An engine's
//! 2×2 box-filtered levels 1..=k then average only texels of one face, and
//! for colours that are affine on the face every level is exact, so no
//! seam opens at those levels (tested); otherwise the error at level `j` is
//! the colour's variation over `2^j` texels, as for any texture. The
//! per-face gutters make it costly: 4× the texels of the default packing
//! for spot at `k = 2`, more for meshes of many small faces. (Mesh
//! colours' own [`crate::MipMap`] has no such limit.)

use glam::Vec2;

use crate::Error;
use crate::filter::{FINEST, lattice};
use crate::structure::MeshColors;
use crate::texture::Texture;

/// A baked texture and the per-corner UVs that map the mesh onto it.
#[derive(Debug, Clone, PartialEq)]
pub struct Atlas {
    /// The texture, `channels()` of the mesh colours.
    pub texture: Texture,
    /// `corner_uvs[f][k]`: the UV of corner `k` of face `f` ([`Texture`]
    /// convention: `v = 0` is row 0, as in `trilux-io`'s `TriMesh`).
    pub corner_uvs: Vec<[Vec2; 3]>,
}

/// How to bake an atlas.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Options {
    /// Texels of padding around each block.
    pub gutter: u32,
    /// MIP levels an engine may build without faces bleeding into each
    /// other (0: the compact paired packing; see the module docs).
    pub mip_levels: u32,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            gutter: 1,
            mip_levels: 0,
        }
    }
}

/// The largest atlas side, in texels (the common GPU texture limit).
pub const MAX_SIDE: u64 = 32_768;

/// The largest gutter, in texels: wider gutters only waste texels (a
/// MIP-safe gutter of `2^8` is the most [`Options::mip_levels`] asks for).
pub const MAX_GUTTER: u32 = 4_096;

struct Block {
    faces: [Option<usize>; 2],
    r: u32,
    x: u32,
    y: u32,
}

fn round_up(x: u64, to: u64) -> u64 {
    x.div_ceil(to) * to
}

/// Bakes mesh colours into an atlas (see the module docs for the layout).
///
/// # Errors
/// [`Error::TooLarge`], before allocating the atlas: a gutter above
/// [`MAX_GUTTER`], an atlas side above [`MAX_SIDE`], or texels × channels
/// above [`MAX_SAMPLE_VALUES`](crate::MAX_SAMPLE_VALUES).
pub fn bake(colors: &MeshColors, options: &Options) -> Result<Atlas, Error> {
    if options.gutter > MAX_GUTTER {
        return Err(Error::TooLarge {
            what: "the atlas gutter",
            requested: u64::from(options.gutter),
            budget: u64::from(MAX_GUTTER),
            unit: "texels",
        });
    }
    let k = options.mip_levels.min(8);
    let align = 1u64 << k;
    let paired = k == 0;
    let g = u64::from(if paired {
        options.gutter
    } else {
        options.gutter.max(1 << k)
    });
    let n = colors.face_count();
    let mut by_level: Vec<Vec<usize>> = vec![Vec::new(); crate::MAX_LEVEL as usize + 1];
    for f in 0..n {
        by_level[colors.level_at(f) as usize].push(f);
    }
    let mut blocks = Vec::new();
    for (l, faces) in by_level.iter().enumerate().rev() {
        let per = if paired { 2 } else { 1 };
        for group in faces.chunks(per) {
            blocks.push(Block {
                faces: [Some(group[0]), group.get(1).copied()],
                r: 1 << l,
                x: 0,
                y: 0,
            });
        }
    }
    // Sizes in u64: a block is at most 2^10 + 3 + 2 · 4096 texels wide, and
    // the sums below cannot overflow.
    // Inner block: the lattice (and, paired, the second face).
    let inner = |r: u32| {
        let r = u64::from(r);
        if paired {
            (r + 3, r + 2)
        } else {
            (r + 2, r + 2)
        }
    };
    let size = |b: &Block| {
        let (w, h) = inner(b.r);
        (round_up(w + 2 * g, align), round_up(h + 2 * g, align))
    };
    let area: u64 = blocks.iter().map(|b| size(b).0 * size(b).1).sum();
    let widest = blocks.iter().map(|b| size(b).0).max().unwrap_or(1);
    let width = round_up(
        ((area as f64 * 1.05).sqrt().ceil() as u64)
            .max(widest)
            .max(1),
        align,
    );
    // Shelf packing, tallest blocks first (they are sorted by level).
    let (mut x, mut y, mut shelf) = (0u64, 0u64, 0u64);
    let mut places = Vec::with_capacity(blocks.len());
    for b in &blocks {
        let (w, h) = size(b);
        if x + w > width {
            x = 0;
            y += shelf;
            shelf = 0;
        }
        places.push((x, y));
        x += w;
        shelf = shelf.max(h);
    }
    let height = round_up((y + shelf).max(1), align);
    let side = width.max(height);
    if side > MAX_SIDE {
        return Err(Error::TooLarge {
            what: "the atlas side",
            requested: side,
            budget: MAX_SIDE,
            unit: "texels",
        });
    }
    let values = width * height * colors.channels() as u64;
    if values > crate::MAX_SAMPLE_VALUES {
        return Err(Error::TooLarge {
            what: "the atlas",
            requested: values,
            budget: crate::MAX_SAMPLE_VALUES,
            unit: "f32 values",
        });
    }
    // Every coordinate is below MAX_SIDE now: u32 from here on.
    for (b, &(x, y)) in blocks.iter_mut().zip(&places) {
        (b.x, b.y) = (x as u32, y as u32);
    }
    let (width, height, g) = (width as u32, height as u32, g as u32);
    let size = |b: &Block| {
        let (w, h) = size(b);
        (w as u32, h as u32)
    };
    let inner = |r: u32| {
        let (w, h) = inner(r);
        (w as u32, h as u32)
    };
    let c = colors.channels();
    let (w, h) = (width as usize, height as usize);
    let mut data = vec![0.0f32; w * h * c];
    let mut corner_uvs = vec![[Vec2::ZERO; 3]; n];
    let uv = |x: u32, y: u32| {
        Vec2::new(
            (x as f32 + 0.5) / width as f32,
            (y as f32 + 0.5) / height as f32,
        )
    };
    let mut value = vec![0.0f32; c];
    for b in &blocks {
        let r = b.r;
        let (ox, oy) = (b.x + g, b.y + g);
        for (side, face) in b.faces.iter().enumerate() {
            let Some(f) = *face else { continue };
            // Texel of lattice point (i, j) for this side of the block.
            let at = |i: u32, j: u32| {
                if side == 0 {
                    (ox + i, oy + j)
                } else {
                    (ox + r + 2 - i, oy + r + 1 - j)
                }
            };
            let lf = colors.level_at(f);
            let mut lat = vec![0.0f32; ((r + 1) * (r + 2) / 2) as usize * c];
            let idx = |i: u32, j: u32| ((i * (2 * r + 3 - i) / 2 + j) as usize) * c;
            for i in 0..=r {
                for j in 0..=r - i {
                    value.fill(0.0);
                    lattice(
                        colors,
                        f,
                        FINEST,
                        lf,
                        [i, j, r - i - j],
                        1.0,
                        false,
                        &mut value,
                    );
                    lat[idx(i, j)..idx(i, j) + c].copy_from_slice(&value);
                }
            }
            // The value at block-local lattice coordinates (i, j): the
            // sample on the lattice, else the linear extrapolation of the
            // nearest lattice triangle (for texels just past the
            // hypotenuse, the triangle whose parallelogram they complete).
            let extrapolate = |i: i64, j: i64, out: &mut [f32]| {
                let ri = i64::from(r);
                if i >= 0 && j >= 0 && i + j <= ri {
                    let at = idx(i as u32, j as u32);
                    out.copy_from_slice(&lat[at..at + c]);
                    return;
                }
                let d = i64::from(i + j > ri);
                let i0 = (i - d).clamp(0, ri - 1);
                let j0 = (j - d).clamp(0, ri - 1 - i0);
                let (di, dj) = ((i - i0) as f32, (j - j0) as f32);
                let (b0, bi, bj) = (
                    idx(i0 as u32, j0 as u32),
                    idx(i0 as u32 + 1, j0 as u32),
                    idx(i0 as u32, j0 as u32 + 1),
                );
                for (ch, o) in out.iter_mut().enumerate() {
                    let base = lat[b0 + ch];
                    *o = base + di * (lat[bi + ch] - base) + dj * (lat[bj + ch] - base);
                }
            };
            let mut put = |x: u32, y: u32, v: &[f32]| {
                let i = (y as usize * w + x as usize) * c;
                data[i..i + c].copy_from_slice(v);
            };
            if paired {
                for i in 0..=r + 1 {
                    for j in 0..=r + 1 - i {
                        extrapolate(i64::from(i), i64::from(j), &mut value);
                        let (x, y) = at(i, j);
                        put(x, y, &value);
                    }
                }
            } else {
                let (bw, bh) = size(b);
                for yy in b.y..b.y + bh {
                    for xx in b.x..b.x + bw {
                        let (i, j) = (i64::from(xx) - i64::from(ox), i64::from(yy) - i64::from(oy));
                        extrapolate(i, j, &mut value);
                        put(xx, yy, &value);
                    }
                }
            }
            let (x0, y0) = at(r, 0);
            let (x1, y1) = at(0, r);
            let (x2, y2) = at(0, 0);
            corner_uvs[f] = [uv(x0, y0), uv(x1, y1), uv(x2, y2)];
        }
        if paired {
            // Gutter: repeat the block's border texels outwards.
            let (iw, ih) = inner(r);
            let (bw, bh) = size(b);
            for yy in b.y..b.y + bh {
                for xx in b.x..b.x + bw {
                    let cx = xx.clamp(ox, ox + iw - 1);
                    let cy = yy.clamp(oy, oy + ih - 1);
                    if (cx, cy) != (xx, yy) {
                        let from = (cy as usize * w + cx as usize) * c;
                        let to = (yy as usize * w + xx as usize) * c;
                        data.copy_within(from..from + c, to);
                    }
                }
            }
        }
    }
    let texture = Texture::new(w, h, c, data)?.with_wrap(crate::Wrap::ClampToEdge);
    Ok(Atlas {
        texture,
        corner_uvs,
    })
}
