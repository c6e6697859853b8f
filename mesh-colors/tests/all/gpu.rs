//! The packed GPU layout (Sec. 5.3): its CPU reference lookup equals every
//! CPU filter bit for bit, a wrong twin of the layout fails the same
//! check, and updates name exactly the texels that changed.

use crate::filtering::edge_points;
use crate::support;

use mesh_colors::gpu::{FACE_WORDS, Filter, GpuLayout, GpuParts};
use mesh_colors::{Error, MeshColors, MipMap, Topology};
use support::Rng;

/// A bumpy grid with levels 0..=5 and random values in `channels`.
fn mixed(seed: u64, channels: usize) -> MeshColors {
    let (positions, faces) = support::grid(6, 0.4);
    let mut rng = Rng(seed);
    let levels: Vec<u32> = (0..faces.len()).map(|_| 1 << rng.below(6)).collect();
    let topology = Topology::new(positions.len(), &faces).unwrap();
    let mut mc = MeshColors::new(topology, &levels, channels).unwrap();
    for x in mc.samples_mut() {
        *x = rng.f32();
    }
    mc
}

/// Lookup points: random interiors, dyadic lattice-like points, points on
/// every interior edge from both faces, and the corners.
fn points(mc: &MeshColors, rng: &mut Rng) -> Vec<(usize, [f32; 3])> {
    let mut out = Vec::new();
    for f in 0..mc.face_count() {
        for _ in 0..40 {
            out.push((f, rng.barycentric()));
        }
        for _ in 0..20 {
            let (i, j) = (rng.below(65) as u32, rng.below(65) as u32);
            let (i, j) = if i + j > 64 { (64 - i, 64 - j) } else { (i, j) };
            out.push((
                f,
                [i as f32 / 64.0, j as f32 / 64.0, (64 - i - j) as f32 / 64.0],
            ));
        }
        for k in 0..3 {
            let mut b = [0.0; 3];
            b[k] = 1.0;
            out.push((f, b));
        }
    }
    for (f0, b0, f1, b1) in edge_points(mc, rng).into_iter().step_by(3) {
        out.push((f0, b0));
        out.push((f1, b1));
    }
    out
}

/// Every filter, with the parameters the tests use.
fn filters(rng: &mut Rng) -> Vec<Filter> {
    let mut out = vec![Filter::Nearest, Filter::Linear];
    out.extend((0..=6).map(Filter::Level));
    out.push(Filter::Level(255));
    for footprint in [1.0, 0.7, 0.3, 0.2, 0.09, 0.04, 0.011, 0.0] {
        out.push(Filter::Trilinear { footprint });
    }
    for _ in 0..6 {
        let scale = 0.3 * rng.f32();
        let d = |rng: &mut Rng| {
            let (x, y) = (rng.f32() - 0.5, rng.f32() - 0.5);
            [scale * x, scale * y, -scale * (x + y)]
        };
        out.push(Filter::Anisotropic {
            db_dx: d(rng),
            db_dy: d(rng),
            max_samples: 1 + rng.below(16) as u32,
        });
    }
    out
}

/// The CPU filter a [`Filter`] names.
fn cpu(mc: &MeshColors, mip: &MipMap, f: usize, b: [f32; 3], filter: Filter, out: &mut [f32]) {
    match filter {
        Filter::Nearest => mc.nearest(f, b, out),
        Filter::Linear => mc.linear(f, b, out),
        Filter::Level(l) => mip.at_level(f, b, l, out),
        Filter::Trilinear { footprint } => mip.trilinear(f, b, footprint, out),
        Filter::Anisotropic {
            db_dx,
            db_dy,
            max_samples,
        } => mip.anisotropic(f, b, db_dx, db_dy, max_samples, out),
    }
    .unwrap();
}

/// Lookups whose bits differ from the CPU filter's, out of all made.
fn mismatches(layout: &GpuLayout, mc: &MeshColors, seed: u64) -> (usize, usize) {
    let mip = mc.mip_map();
    let mut rng = Rng(seed);
    let c = mc.channels();
    let (mut want, mut got) = (vec![0.0f32; c], vec![0.0f32; c]);
    let (mut bad, mut all) = (0, 0);
    let pts = points(mc, &mut rng);
    for filter in filters(&mut rng) {
        for &(f, b) in &pts {
            cpu(mc, &mip, f, b, filter, &mut want);
            layout.lookup(f, b, filter, &mut got).unwrap();
            all += 1;
            let same = want
                .iter()
                .zip(&got)
                .all(|(x, y)| x.to_bits() == y.to_bits());
            if !same {
                bad += 1;
            }
        }
    }
    (bad, all)
}

#[test]
fn the_packed_lookup_equals_every_cpu_filter_bit_for_bit() {
    for (seed, channels, width) in [
        (1, 3, 4096),
        (2, 3, 131),
        (3, 1, 250),
        (4, 6, 1000),
        (5, 4, 200),
    ] {
        let mc = mixed(seed, channels);
        let layout = GpuLayout::new(&mc.mip_map(), width).unwrap();
        assert!(layout.width() <= width && layout.sample_height() <= width);
        let (bad, all) = mismatches(&layout, &mc, seed + 10);
        assert!(all > 50_000, "{all} lookups");
        assert_eq!(
            bad, 0,
            "{bad} of {all} lookups differ ({channels} channels, width {width})"
        );
    }
}

#[test]
fn a_wrong_twin_of_the_layout_fails_the_same_check() {
    let mc = mixed(6, 3);
    let layout = GpuLayout::new(&mc.mip_map(), 150).unwrap();
    let parts = layout.clone().into_parts();
    // The same image with rows one texel wider than the width the
    // indices were packed for (a page that allocates the texture at
    // W + 1): texel t is then read from (t % (W+1), t / (W+1)), which
    // holds packed texel y·W + x.
    let restride = |flat: &[f32], w: usize| -> Vec<f32> {
        flat.chunks(4 * w)
            .flat_map(|row| row.iter().copied().chain([0.0; 4]))
            .collect()
    };
    let restride_u32 = |flat: &[u32], w: usize| -> Vec<u32> {
        flat.chunks(4 * w)
            .flat_map(|row| row.iter().copied().chain([0; 4]))
            .collect()
    };
    let mut wide = parts.clone();
    let w = parts.width as usize;
    wide.width += 1;
    wide.samples = restride(&parts.samples, w);
    wide.faces = restride_u32(&parts.faces, w);
    let (bad, all) = mismatches(&GpuLayout::from_parts(wide).unwrap(), &mc, 1);
    assert!(
        bad > all / 2,
        "off-by-one row width: only {bad} of {all} differ"
    );
    // Edge samples read from the wrong end: the direction bits flipped.
    let mut flipped = parts.clone();
    for f in 0..flipped.face_count {
        flipped.faces[f * FACE_WORDS + 7] ^= 0b111 << 28;
    }
    let (bad, all) = mismatches(&GpuLayout::from_parts(flipped).unwrap(), &mc, 2);
    assert!(bad > all / 10, "edges reversed: only {bad} of {all} differ");
    // One vertex level off (a vertex read one MIP level too coarse).
    let mut coarse = parts;
    for f in 0..coarse.face_count {
        let w = &mut coarse.faces[f * FACE_WORDS + 7];
        let vl = (*w >> 4) & 0xF;
        if vl > 0 {
            *w = (*w & !(0xF << 4)) | ((vl - 1) << 4);
        }
    }
    let (bad, _) = mismatches(&GpuLayout::from_parts(coarse).unwrap(), &mc, 3);
    assert!(bad > 100, "vertex levels off by one: only {bad} differ");
}

/// Applies `changes` of `new` onto `old` the way `texSubImage2D` does.
fn upload(old: &mut [f32], new: &[f32], w: usize, rects: &[mesh_colors::gpu::TexelRect]) {
    for r in rects {
        for y in r.y as usize..(r.y + r.height) as usize {
            let from = (y * w + r.x as usize) * 4;
            let to = from + r.width as usize * 4;
            old[from..to].copy_from_slice(&new[from..to]);
        }
    }
}

#[test]
fn updates_name_exactly_the_texels_that_changed() {
    let mut mc = mixed(8, 3);
    let mut layout = GpuLayout::new(&mc.mip_map(), 128).unwrap();
    assert!(layout.update(&mc.mip_map()).unwrap().is_empty());
    let mut rng = Rng(9);
    for round in 0..6 {
        let before = layout.clone();
        // A few changed samples (a small stroke) …
        for _ in 0..1 + rng.below(20) {
            let i = rng.below(mc.sample_count() as u64) as usize;
            mc.sample_mut(i).unwrap()[rng.below(3) as usize] = rng.f32();
        }
        let changes = layout.update(&mc.mip_map()).unwrap();
        assert!(!changes.resized);
        let w = layout.width() as usize;
        let mut texels = before.sample_texels().to_vec();
        upload(&mut texels, layout.sample_texels(), w, &changes.samples);
        assert_eq!(texels, layout.sample_texels(), "round {round}");
        let uploaded: u32 = changes.samples.iter().map(|r| r.width * r.height).sum();
        assert!(
            (uploaded as usize) < layout.sample_texels().len() / 8,
            "round {round}: {uploaded} texels uploaded for a small stroke"
        );
        assert!(changes.faces.is_empty());
        for r in &changes.samples {
            assert!(r.x + r.width <= layout.width() && r.y + r.height <= layout.sample_height());
            assert!(r.height == 1 || (r.x == 0 && r.width == layout.width()));
        }
        let lookups_agree = mismatches(&layout, &mc, round);
        assert_eq!(lookups_agree.0, 0);
    }
    // A resolution change moves the layout: everything is new.
    mc.set_face_resolutions(&[(0, 32), (5, 1)]).unwrap();
    let changes = layout.update(&mc.mip_map()).unwrap();
    assert!(changes.resized);
    let covered: u32 = changes.samples.iter().map(|r| r.width * r.height).sum();
    assert_eq!(covered as usize * 4, layout.sample_texels().len());
    assert_eq!(mismatches(&layout, &mc, 99).0, 0);
}

#[test]
fn bad_arguments_name_what_is_wrong() {
    let mc = mixed(10, 3);
    let mip = mc.mip_map();
    assert_eq!(
        GpuLayout::new(&mip, 0),
        Err(Error::InvalidArgument {
            argument: "max_width",
            reason: "must be at least 1 texel"
        })
    );
    assert!(matches!(
        GpuLayout::new(&mip, 8),
        Err(Error::TooLarge { unit: "rows", .. })
    ));
    let layout = GpuLayout::new(&mip, 256).unwrap();
    let mut out = [0.0f32; 3];
    assert!(matches!(
        layout.lookup(mc.face_count(), [0.3; 3], Filter::Linear, &mut out),
        Err(Error::MissingFace { .. })
    ));
    assert!(matches!(
        layout.lookup(0, [0.3; 3], Filter::Linear, &mut [0.0; 2]),
        Err(Error::ChannelMismatch { .. })
    ));
    // NaN and huge inputs give a value, not a panic.
    for b in [
        [f32::NAN; 3],
        [f32::INFINITY, 0.0, 1.0],
        [-1.0, -2.0, -3.0],
        [1e30, 1.0, 0.0],
    ] {
        for filter in [
            Filter::Nearest,
            Filter::Linear,
            Filter::Trilinear {
                footprint: f32::NAN,
            },
            Filter::Anisotropic {
                db_dx: [f32::NAN; 3],
                db_dy: [1e30, 0.0, 0.0],
                max_samples: u32::MAX,
            },
        ] {
            layout.lookup(0, b, filter, &mut out).unwrap();
        }
    }
    let parts = GpuParts {
        width: 4,
        channels: 3,
        face_count: 2,
        samples: vec![0.0; 15],
        faces: vec![0; 16],
    };
    let e = GpuLayout::from_parts(parts).unwrap_err();
    assert!(e.to_string().contains("`samples`"), "{e}");
    // Garbage parts read as zeros, never panic.
    let garbage = GpuParts {
        width: 3,
        channels: 3,
        face_count: 2,
        samples: vec![1.0; 12],
        faces: vec![u32::MAX; 24],
    };
    let g = GpuLayout::from_parts(garbage).unwrap();
    for filter in filters(&mut Rng(1)) {
        g.lookup(1, [0.2, 0.3, 0.5], filter, &mut out).unwrap();
        g.lookup(0, [0.0, 0.3, 0.7], filter, &mut out).unwrap();
    }
}

#[test]
fn a_stroke_refreshes_the_pyramid_and_texels_near_it_as_a_rebuild_would() {
    use glam::Vec3;
    use mesh_colors::undo::Recorder;
    use mesh_colors::{Blend, Brush, Painter};
    let (positions, faces) = support::grid(30, 0.1);
    let mut rng = Rng(21);
    let levels: Vec<u32> = (0..faces.len()).map(|_| 1 << rng.below(5)).collect();
    let mut mc =
        MeshColors::new(Topology::new(positions.len(), &faces).unwrap(), &levels, 3).unwrap();
    for x in mc.samples_mut() {
        *x = rng.f32();
    }
    let painter = Painter::new(&mc, &positions, 0.03).unwrap();
    let mut mip = mc.mip_map();
    let mut layout = GpuLayout::new(&mip, 512).unwrap();
    let values = mip.data().len() / 3;
    for round in 0..8 {
        let mut recorder = Recorder::new(&mc);
        let start = Vec3::new(rng.f32(), rng.f32(), 0.0);
        for k in 0..5 {
            let brush = Brush {
                center: start + Vec3::new(0.01 * k as f32, 0.005 * k as f32, 0.05),
                radius: 0.03 + 0.05 * rng.f32(),
                color: &[rng.f32(), rng.f32(), rng.f32()],
                strength: 0.8,
                blend: Blend::Mix,
            };
            painter
                .paint_recorded(&mut mc, &brush, &mut recorder)
                .unwrap();
        }
        let mut delta = recorder.finish();
        for undo in [false, true] {
            if undo {
                delta.undo(&mut mc).unwrap();
            }
            let spans = mip.refresh(&mc, delta.runs()).unwrap();
            assert_eq!(mip, mc.mip_map(), "round {round} (undo: {undo})");
            let rewritten: usize = spans.iter().map(|s| s.1 - s.0).sum();
            assert!(
                rewritten < values / 3,
                "round {round}: {rewritten} of {values} values rewritten"
            );
            let before = layout.clone();
            let changes = layout.refresh(&mip, &spans).unwrap();
            assert_eq!(layout, GpuLayout::new(&mip, 512).unwrap(), "round {round}");
            let mut texels = before.sample_texels().to_vec();
            upload(
                &mut texels,
                layout.sample_texels(),
                layout.width() as usize,
                &changes.samples,
            );
            assert_eq!(texels, layout.sample_texels());
        }
    }
    // Another layout is refused, naming the argument.
    let other = mc.set_face_resolution(0, 32).unwrap();
    let e = mip.refresh(&other, &[(0, 1)]).unwrap_err();
    assert!(e.to_string().contains("`colors`"), "{e}");
    let e = mip.refresh(&mc, &[(u32::MAX, 2)]).unwrap_err();
    assert!(e.to_string().contains("`changed`"), "{e}");
    let e = layout.refresh(&other.mip_map(), &[]).unwrap_err();
    assert!(e.to_string().contains("`mip`"), "{e}");
    let e = layout.refresh(&mip, &[(0, values + 1)]).unwrap_err();
    assert!(e.to_string().contains("`spans`"), "{e}");
}

#[test]
fn the_documented_addresses_find_the_values() {
    // The module documentation's formulas, applied by hand to the packed
    // arrays: a face's level-l interior sample, an edge's sample and a
    // corner's level, against the MIP map's own lookups at lattice points.
    let mc = mixed(30, 3);
    let mip = mc.mip_map();
    let layout = GpuLayout::new(&mip, 127).unwrap();
    let (w, tex, table) = (
        layout.width() as usize,
        layout.sample_texels(),
        layout.face_texels(),
    );
    let fetch = |i: usize| {
        let (x, y) = (i % w, i / w);
        let at = (y * w + x) * 4;
        [tex[at], tex[at + 1], tex[at + 2]]
    };
    let o = |l: u32| -> usize {
        (0..l)
            .map(|m| mesh_colors::samples_per_face(1 << m) as usize)
            .sum()
    };
    assert_eq!((0..6).map(o).collect::<Vec<_>>(), [0, 0, 0, 3, 24, 129]);
    let mut checked = 0;
    let mut out = [0.0f32; 3];
    for f in 0..mc.face_count() {
        let words = &table[f * FACE_WORDS..(f + 1) * FACE_WORDS];
        let n = words[7] & 0xF;
        assert_eq!(1 << n, mc.face_resolution(f).unwrap());
        for l in 0..=n {
            let r = 1u32 << l;
            for i in 1..r {
                for j in 1..r - i {
                    let idx = ((i - 1) * (r - 1) - (i - 1) * i / 2 + (j - 1)) as usize;
                    let got = fetch(words[0] as usize + o(l) + idx);
                    let b = [
                        i as f32 / r as f32,
                        j as f32 / r as f32,
                        (r - i - j) as f32 / r as f32,
                    ];
                    mip.at_level(f, b, l as u8, &mut out).unwrap();
                    assert_eq!(got, out, "face {f} level {l} sample ({i}, {j})");
                    checked += 1;
                }
            }
        }
        for k in 0..3 {
            let vl = (words[7] >> (4 + 4 * k)) & 0xF;
            let mut b = [0.0; 3];
            b[k] = 1.0;
            for l in 0..=vl {
                mip.at_level(f, b, l as u8, &mut out).unwrap();
                assert_eq!(
                    fetch(words[1 + k] as usize + l as usize),
                    out,
                    "corner {k} of face {f}"
                );
            }
            let el = (words[7] >> (16 + 4 * k)) & 0xF;
            let forward = words[7] & (1 << (28 + k)) != 0;
            let r = 1u32 << el;
            for s in 1..r {
                // Sample s from the edge's smaller vertex.
                let t = s as f32 / r as f32;
                let mut b = [0.0; 3];
                let (start, end) = if forward {
                    (k, (k + 1) % 3)
                } else {
                    ((k + 1) % 3, k)
                };
                b[start] = 1.0 - t;
                b[end] = t;
                mip.at_level(f, b, el as u8, &mut out).unwrap();
                let at =
                    words[4 + k] as usize + ((1usize << el) - 1 - el as usize) + s as usize - 1;
                assert_eq!(fetch(at), out, "edge {k} of face {f}, sample {s}");
                checked += 1;
            }
        }
    }
    assert!(checked > 1000, "{checked}");
}

/// A page's copy of the textures after `changes`: allocated again from
/// the whole arrays when `resized`, else the rectangles of both textures
/// written (`texSubImage2D`).
fn apply_on_page(page: &mut GpuParts, layout: &GpuLayout, changes: &mesh_colors::gpu::Changes) {
    if changes.resized {
        *page = layout.clone().into_parts();
        return;
    }
    let w = layout.width() as usize;
    upload(
        &mut page.samples,
        layout.sample_texels(),
        w,
        &changes.samples,
    );
    for r in &changes.faces {
        for y in r.y as usize..(r.y + r.height) as usize {
            let from = (y * w + r.x as usize) * 4;
            let to = from + r.width as usize * 4;
            page.faces[from..to].copy_from_slice(&layout.face_texels()[from..to]);
        }
    }
}

/// A wider bumpy grid than [`mixed`], levels 0..=2: a change of a few
/// faces reaches a small part of it.
fn wide(seed: u64) -> MeshColors {
    let (positions, faces) = support::grid(16, 0.4);
    let mut rng = Rng(seed);
    let levels: Vec<u32> = (0..faces.len()).map(|_| 1 << rng.below(3)).collect();
    let topology = Topology::new(positions.len(), &faces).unwrap();
    let mut mc = MeshColors::new(topology, &levels, 3).unwrap();
    for x in mc.samples_mut() {
        *x = rng.f32();
    }
    mc
}

#[test]
fn resolution_changes_send_only_the_runs_that_changed() {
    let mut mc = wide(11);
    let mut mip = mc.mip_map();
    let mut layout = GpuLayout::new(&mip, 256).unwrap();
    let mut page = layout.clone().into_parts();
    let mut rng = Rng(12);
    let mut undo = Vec::new();
    let (mut partial, mut grown) = (0, 0);
    for round in 0..12u64 {
        // Raise or lower a few faces, or undo an earlier change.
        let change = if round % 3 == 2 {
            let change: mesh_colors::edit::ResolutionChange = undo.pop().unwrap();
            mc.revert_resolutions(&change).unwrap();
            change
        } else {
            let requests: Vec<(usize, u32)> = (0..1 + rng.below(4))
                .map(|_| {
                    let f = rng.below(mc.face_count() as u64) as usize;
                    let level = mc.face_level(f).unwrap();
                    let to = if rng.below(3) == 0 {
                        level.saturating_sub(1)
                    } else {
                        (level + 1).min(4)
                    };
                    (f, 1u32 << to)
                })
                .collect();
            let change = mc.set_face_resolutions(&requests).unwrap();
            undo.push(change.clone());
            change
        };
        let faces: Vec<usize> = change.faces().map(|f| f.0).collect();
        let before = layout.clone();
        let spans = mip.refresh_resolutions(&mc, &faces).unwrap();
        let changes = layout.refresh_resolutions(&mip, &spans).unwrap();
        apply_on_page(&mut page, &layout, &changes);
        // The page's copy is the server's, bit for bit.
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&page.samples),
            bits(layout.sample_texels()),
            "round {round}"
        );
        assert_eq!(page.faces, layout.face_texels(), "round {round}");
        // And it filters as the CPU does (as a new layout would).
        let on_page = GpuLayout::from_parts(page.clone()).unwrap();
        assert_eq!(mismatches(&on_page, &mc, round).0, 0, "round {round}");
        if changes.resized {
            continue;
        }
        partial += 1;
        let uploaded: u32 = changes.samples.iter().map(|r| r.width * r.height).sum();
        assert!(
            (uploaded as usize) < layout.sample_texels().len() / 4,
            "round {round}: {uploaded} texels of {} for a few faces {:?}",
            layout.sample_texels().len() / 4,
            change.faces().collect::<Vec<_>>()
        );
        // A face that grew moved to a new block: its table entry is new,
        // and a page without the table's rectangles filters wrongly.
        let grew = change.faces().any(|(f, from, to)| {
            to > from && before.face_texels()[8 * f] != layout.face_texels()[8 * f]
        });
        if grew {
            grown += 1;
            assert!(!changes.faces.is_empty());
            let mut stale = page.clone();
            stale.faces.copy_from_slice(before.face_texels());
            let stale = GpuLayout::from_parts(stale).unwrap();
            assert!(mismatches(&stale, &mc, round).0 > 0, "round {round}");
        }
    }
    assert!(
        partial >= 6 && grown >= 2,
        "{partial} partial, {grown} grown"
    );
    // Without the spans the pyramid rewrote, the rings around the change
    // keep their old MIP levels: wrong (the spans are needed).
    let requests: Vec<(usize, u32)> = (0..2)
        .map(|f| (f, 2 * mc.face_resolution(f).unwrap()))
        .collect();
    let change = mc.set_face_resolutions(&requests).unwrap();
    let faces: Vec<usize> = change.faces().map(|f| f.0).collect();
    mip.refresh_resolutions(&mc, &faces).unwrap();
    let mut wrong = layout.clone();
    let changes = wrong.refresh_resolutions(&mip, &[]).unwrap();
    assert!(!changes.resized);
    assert!(mismatches(&wrong, &mc, 77).0 > 0);
}

#[test]
fn spare_rows_hold_the_first_raise_and_stay_zeros_past_the_used_rows() {
    let mut mc = wide(21);
    let mut mip = mc.mip_map();
    let mut plain = GpuLayout::new(&mip, 256).unwrap();
    let mut spare = GpuLayout::with_spare_rows(&mip, 256).unwrap();
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    // The same packing, with zero rows after it.
    assert!(spare.sample_height() > plain.sample_height());
    assert_eq!(spare.used_sample_rows(), plain.sample_height());
    assert_eq!(plain.used_sample_rows(), plain.sample_height());
    let n = plain.sample_texels().len();
    assert_eq!(
        bits(&spare.sample_texels()[..n]),
        bits(plain.sample_texels())
    );
    assert!(spare.sample_texels()[n..].iter().all(|&x| x.to_bits() == 0));
    assert_eq!(mismatches(&spare, &mc, 1).0, 0);
    // The first raise: the plain layout packs everything again, the one
    // with spare rows writes the raised faces into them.
    let requests: Vec<(usize, u32)> = (0..8)
        .map(|f| (f, 2 * mc.face_resolution(f).unwrap()))
        .collect();
    let change = mc.set_face_resolutions(&requests).unwrap();
    let faces: Vec<usize> = change.faces().map(|f| f.0).collect();
    let spans = mip.refresh_resolutions(&mc, &faces).unwrap();
    assert!(plain.refresh_resolutions(&mip, &spans).unwrap().resized);
    let changes = spare.refresh_resolutions(&mip, &spans).unwrap();
    assert!(!changes.resized);
    assert_eq!(mismatches(&spare, &mc, 2).0, 0);
    let used = spare.used_sample_rows() as usize * 4 * spare.width() as usize;
    assert!(used > n && used < spare.sample_texels().len());
    assert!(
        spare.sample_texels()[used..]
            .iter()
            .all(|&x| x.to_bits() == 0)
    );
}

#[test]
fn the_texels_a_uniform_resolution_needs_are_those_a_layout_has() {
    let (positions, faces) = support::grid(5, 0.2);
    let topology = Topology::new(positions.len(), &faces).unwrap();
    for (r, channels) in [(1, 3), (2, 3), (4, 4), (16, 3), (8, 5), (32, 8)] {
        let mip = MeshColors::uniform(topology.clone(), r, channels)
            .unwrap()
            .mip_map();
        let values = (mip.data().len() / channels) as u64;
        let texels = mesh_colors::gpu::uniform_sample_texels(&topology, r, channels);
        assert_eq!(
            texels,
            values * channels.div_ceil(4) as u64,
            "R = {r}, {channels} channels"
        );
        // The rows a layout has at its width.
        let layout = GpuLayout::new(&mip, 1024).unwrap();
        let w = u64::from(layout.width());
        assert_eq!(
            u64::from(layout.used_sample_rows()),
            texels.div_ceil(w),
            "R = {r}"
        );
    }
}
