//! Bad and extreme arguments: every public constructor and sampler of the
//! crate is called with 0, subnormals, huge counts and values, NaN,
//! infinities and out-of-range indices, and must answer (an `Err`, or a
//! documented value), never panic or abort. Plus the regression inputs of
//! `tests/regressions/`.

use glam::{DVec2, Vec2, Vec3};
use mesh_sampling::{
    Channel, Density, DensitySampler, DensityTexture, Depth, Error, Filter, Layout, MAX_POINTS,
    MeshRef, Mode, MultiDensitySampler, MultiMeshSampler, NaiveSampler, Options, RejectionSampler,
    SurfacePoint, SurfaceSampler, UniformSampler, Wrap, spherical_uvs, uniform_barycentric,
};
use rand::SeedableRng;

/// `sampling-huge-density/square.obj`: a unit square; asking for 10^15
/// points per unit area is an error that says the count is too large, not
/// a process aborted by a 36 PB allocation.
#[test]
fn regression_sampling_huge_density() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/regressions/sampling-huge-density/square.obj"
    );
    let square = trilux_io::mesh::TriMesh::read(path).unwrap();
    let mesh = MeshRef::new(&square.positions, &square.indices);
    let uniform = UniformSampler::new(mesh).unwrap();
    assert!((uniform.total_area() - 1.0).abs() < 1e-9);
    let err = uniform.sample_stable(1, 1e15).unwrap_err();
    assert!(
        matches!(
            err,
            Error::TooManyPoints {
                budget: MAX_POINTS,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("too large"), "{err}");
    // A count f64 holds exactly is printed as the integer.
    let err = uniform.sample_n(1, usize::MAX).unwrap_err();
    assert!(
        err.to_string().starts_with("about 1.845e19 points")
            || err.to_string().starts_with("18446744073709551615 points"),
        "{err}"
    );
    let err = uniform.sample_n(1, MAX_POINTS + 1).unwrap_err();
    assert!(
        err.to_string()
            .starts_with(&format!("{} points", MAX_POINTS + 1)),
        "{err}"
    );
    // The same through a density, and the right count below the budget.
    let weights = vec![1.0f32; square.indices.len()];
    let density = DensitySampler::new(mesh, Density::PerFace(&weights)).unwrap();
    assert!(matches!(
        density.sample_stable(1, 1e15),
        Err(Error::TooManyPoints { .. })
    ));
    let points = uniform.sample_stable(1, 1000.0).unwrap();
    assert!((990..=1002).contains(&points.len()), "{}", points.len());
    // Counts asked of the batch APIs are checked the same way.
    for n in [MAX_POINTS + 1, usize::MAX] {
        assert!(matches!(
            uniform.sample_n(1, n),
            Err(Error::TooManyPoints { .. })
        ));
        assert!(matches!(
            uniform.sample_positions(1, n),
            Err(Error::TooManyPoints { .. })
        ));
        assert!(matches!(
            density.sample_n(1, n),
            Err(Error::TooManyPoints { .. })
        ));
    }
}

/// Floats that break naive code.
const EXTREME_F32: [f32; 10] = [
    0.0,
    -0.0,
    1e-45, // the smallest subnormal
    1.2e-38,
    1.0,
    -1.0,
    3.4e38,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::NAN,
];

const EXTREME_F64: [f64; 10] = [
    0.0,
    5e-324,
    1e-300,
    0.5,
    1.0,
    -1.0,
    1e300,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::NAN,
];

/// A valid mesh with UVs and normals, and variants with one extreme value
/// in one place.
/// Positions, UVs and triangles.
type Mesh = (Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>);

fn meshes() -> Vec<Mesh> {
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
    let uvs = vec![Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
    let indices = vec![[0, 1, 2], [1, 3, 2]];
    let mut out = vec![(positions.clone(), uvs.clone(), indices.clone())];
    for &x in &EXTREME_F32 {
        let mut p = positions.clone();
        p[1].x = x;
        out.push((p, uvs.clone(), indices.clone()));
        let mut t = uvs.clone();
        t[3] = Vec2::new(x, 2.0 * x);
        out.push((positions.clone(), t, indices.clone()));
        // Scaled: huge or tiny triangles, huge UV footprints.
        let s = if x.is_finite() && x != 0.0 {
            x.abs()
        } else {
            1.0
        };
        out.push((
            positions.iter().map(|&q| q * s).collect(),
            uvs.iter().map(|&q| q * s).collect(),
            indices.clone(),
        ));
    }
    out.push((positions.clone(), uvs.clone(), vec![]));
    out.push((positions.clone(), uvs.clone(), vec![[0, 1, u32::MAX]]));
    out.push((positions.clone(), uvs.clone(), vec![[0, 0, 0]]));
    out.push((vec![], vec![], vec![[0, 1, 2]]));
    out
}

fn textures() -> Vec<Result<DensityTexture, Error>> {
    let mut out = vec![
        DensityTexture::new(0, 0, vec![]),
        DensityTexture::new(0, 5, vec![]),
        DensityTexture::new(usize::MAX, 2, vec![1.0]),
        DensityTexture::new(usize::MAX, usize::MAX, vec![]),
        DensityTexture::new(2, 2, vec![1.0; 3]),
        DensityTexture::from_channels(2, 1, &[1.0; 8], 4, Channel::Index(usize::MAX)),
        DensityTexture::from_channels(2, 1, &[1.0; 8], 0, Channel::Luminance),
        DensityTexture::from_channels(2, 1, &[1.0; 8], 0, Channel::Index(0)),
        DensityTexture::from_channels(usize::MAX, 3, &[1.0; 9], 3, Channel::Luminance),
        DensityTexture::new(1, 1, vec![0.0]),
    ];
    for &x in &EXTREME_F32 {
        out.push(DensityTexture::new(2, 2, vec![1.0, x, 0.5, 1.0]));
        out.push(DensityTexture::new(1, 1, vec![x]));
        out.push(DensityTexture::from_channels(
            1,
            1,
            &[x, 1.0, x, 1.0],
            4,
            Channel::Luminance,
        ));
    }
    out
}

fn option_sets() -> Vec<Options> {
    let base = Options::default();
    let mut out = vec![base];
    for mode in [Mode::Approximate, Mode::Exact] {
        for layout in [Layout::Alias, Layout::Inversion] {
            for depth in [Depth::Nearest, Depth::AtMostOneTexel] {
                out.push(Options {
                    mode,
                    layout,
                    depth,
                    ..base
                });
            }
        }
    }
    for max_level in [0, 13, 14, 255] {
        out.push(Options { max_level, ..base });
    }
    for extra_levels in [1, 255] {
        out.push(Options {
            extra_levels,
            ..base
        });
    }
    for merge_tolerance in [-1.0, 0.5, 1.0, 2.0, f32::NAN, f32::INFINITY] {
        out.push(Options {
            merge_tolerance,
            ..base
        });
    }
    for max_pieces in [0, 1, 2, usize::MAX] {
        out.push(Options { max_pieces, ..base });
    }
    // Small budgets keep the far-out UV footprints quick to build (the
    // default budget is exercised by the first texture).
    for o in out.iter_mut().skip(1) {
        o.max_pieces = o.max_pieces.min(256);
    }
    out
}

/// Draws, pdfs and the stable modes of a built sampler, with extreme
/// seeds, counts, faces and barycentrics.
fn exercise<S: SurfaceSampler + std::fmt::Debug>(
    sampler: &S,
    pdf: impl Fn(usize, [f32; 3]) -> f32,
) {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
    for _ in 0..20 {
        let p = sampler.sample(&mut rng);
        assert!(!p.pdf.is_nan(), "a NaN pdf from {sampler:?}");
    }
    for seed in [0, u64::MAX] {
        for n in [0, 1, 100] {
            assert_eq!(sampler.sample_n(seed, n).unwrap().len(), n);
        }
    }
    assert!(sampler.sample_n(0, usize::MAX).is_err());
    sampler.sample_stream(0, 3, |_, chunk| assert!(chunk.len() <= 3));
    let mut out = [SurfacePoint::default(); 5];
    sampler.sample_into(&mut rng, &mut out);
    for face in [0, 1, 2, usize::MAX] {
        for &b in &EXTREME_F32 {
            let value = pdf(face, [b, 0.5, 0.5 - b]);
            assert!(!value.is_nan(), "pdf({face}, {b}) is NaN: {sampler:?}");
        }
    }
}

#[test]
fn no_public_function_panics_on_extreme_arguments() {
    let textures = textures();
    let valid: Vec<&DensityTexture> = textures.iter().filter_map(|t| t.as_ref().ok()).collect();
    assert!(valid.len() >= 5, "{} valid textures", valid.len());
    for (positions, uvs, indices) in meshes() {
        let with_attrs = MeshRef {
            uvs: Some(&uvs),
            normals: Some(&positions),
            ..MeshRef::new(&positions, &indices)
        };
        for mesh in [MeshRef::new(&positions, &indices), with_attrs] {
            let _ = mesh.validate();
            for face in [0, 1, usize::MAX] {
                let _ = mesh.corners(face);
                let _ = mesh.area(face);
                for &b in &EXTREME_F32 {
                    let _ = SurfacePoint::on(&mesh, face as u32, [b, b, 1.0], b);
                }
            }
            if let Ok(u) = UniformSampler::new(mesh) {
                exercise(&u, |f, _| u.pdf(f));
                for &x in &EXTREME_F64 {
                    let _ = u.sample_u([x, x]);
                    let _ = u.sample_u([0.5, x]);
                    let _ = u.sample_stable(1, x);
                }
            }
            if let Ok(n) = NaiveSampler::new(mesh) {
                exercise(&n, |f, _| n.pdf(f));
            }
            if let Ok(mut m) = MultiMeshSampler::new([mesh, mesh]) {
                for &x in &EXTREME_F64 {
                    let _ = m.sample_u([x, 1.0 - x]);
                }
                let _ = m.pdf(usize::MAX, usize::MAX);
                assert!(m.sample_n(1, usize::MAX).is_err());
                assert!(m.replace(usize::MAX, mesh).is_err());
                let _ = m.replace(1, MeshRef::new(&[], &[]));
            }
            let _ = MultiMeshSampler::new([]);
            let _ = spherical_uvs(&positions, &indices);
            for texture in &valid {
                for wrap in [Wrap::Repeat, Wrap::MirroredRepeat, Wrap::ClampToEdge] {
                    for filter in [Filter::Bilinear, Filter::Nearest] {
                        let t = (*texture).clone().with_wrap(wrap).with_filter(filter);
                        for &x in &EXTREME_F64 {
                            let _ = t.eval(DVec2::new(x, 0.5));
                            let _ = t.eval(DVec2::new(0.5, -x));
                            let _ = t.range_over_box(DVec2::splat(-x), DVec2::splat(x));
                            let _ = t.constant_over_box(DVec2::new(x, 0.0), DVec2::ONE);
                            if x.abs() < 1e6 || x.is_nan() {
                                let _ = t.max_over_box(DVec2::ZERO, DVec2::new(x, 1.0));
                                let tri = [DVec2::ZERO, DVec2::new(x, 0.0), DVec2::Y];
                                let _ = t.integral(tri);
                            }
                        }
                        if let Ok(r) = RejectionSampler::new(mesh, &t) {
                            exercise(&r, |f, b| r.pdf(f, b));
                        }
                        let all = option_sets();
                        let options_here = if std::ptr::eq(*texture, valid[0]) {
                            &all[..]
                        } else {
                            &all[1..3]
                        };
                        for options in options_here {
                            let d =
                                DensitySampler::with_options(mesh, Density::Texture(&t), options);
                            if let Ok(d) = d {
                                exercise(&d, |f, b| d.pdf(f, b));
                                let _ = d.sample_stable(1, 10.0);
                                let _ = d.sample_stable(1, f64::MAX);
                                let _ = d.level(usize::MAX);
                            }
                        }
                    }
                }
            }
            for &w in &EXTREME_F32 {
                let face_w = vec![w; indices.len()];
                let vertex_w = vec![w; positions.len()];
                for density in [
                    Density::PerFace(&face_w),
                    Density::PerVertex(&vertex_w),
                    Density::PerFace(&face_w[..face_w.len().saturating_sub(1)]),
                    Density::PerVertex(&[]),
                ] {
                    if let Ok(d) = DensitySampler::new(mesh, density) {
                        exercise(&d, |f, b| d.pdf(f, b));
                        if let Ok(multi) = MultiDensitySampler::new([d.clone(), d]) {
                            let _ = multi.pdf(usize::MAX, 0, [f32::NAN; 3]);
                            assert!(multi.sample_n(0, usize::MAX).is_err());
                        }
                    }
                }
            }
        }
    }
    let _ = MultiDensitySampler::new([]);
    for &x in &EXTREME_F64 {
        let b = uniform_barycentric(x, x);
        assert!(b.iter().all(|v| v.is_finite() && *v >= 0.0), "{x}: {b:?}");
    }
}

/// Scatter by rate with extreme rates, ceilings, densities and faces:
/// an `Err` or points, never a panic; an update with the same density
/// (or one that fails) leaves the points as they were.
#[test]
fn scatter_never_panics_on_extreme_arguments() {
    use mesh_sampling::{Scatter, ScatterDensity, ScatterOptions};
    let texture = DensityTexture::new(2, 2, vec![0.0, 1.0, 0.5, 0.25]).unwrap();
    for (positions, uvs, indices) in meshes() {
        let mesh = MeshRef {
            uvs: Some(&uvs),
            ..MeshRef::new(&positions, &indices)
        };
        for &w in &EXTREME_F32 {
            let face_w = vec![w; indices.len()];
            let vertex_w = vec![w; positions.len()];
            let function = move |_: usize, _: [f32; 3]| w;
            let densities = [
                ScatterDensity::Uniform,
                Density::PerFace(&face_w).into(),
                Density::PerVertex(&vertex_w).into(),
                Density::PerVertex(&[]).into(),
                Density::Texture(&texture).into(),
                ScatterDensity::Function(&function),
            ];
            for density in densities {
                for rate in [0.0, 1e-300, 1.0, 1e300, f64::INFINITY, f64::NAN, -1.0] {
                    for max_density in [None, Some(0.0), Some(1.0), Some(1e300), Some(f64::NAN)] {
                        for clamp in [false, true] {
                            let options = ScatterOptions {
                                max_density,
                                clamp,
                                seed: u64::MAX,
                                ..ScatterOptions::new(rate)
                            };
                            let Ok(mut s) = Scatter::new(mesh, density, &options) else {
                                continue;
                            };
                            let before = s.points().to_vec();
                            for faces in [&[][..], &[0, 1], &[1, 1, 0], &[u32::MAX]] {
                                // The same density: the same points, or an
                                // error that changed nothing.
                                let _ = s.update_faces(faces, density);
                                assert_eq!(s.points(), &before[..]);
                            }
                            let _ = s.face_points(usize::MAX);
                            assert_eq!(s.offsets().len(), indices.len() + 1);
                        }
                    }
                }
            }
        }
    }
}

/// Errors read as sentences that name the argument.
#[test]
fn errors_are_sentences() {
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let uvs = [Vec2::ZERO; 3];
    let errors = [
        UniformSampler::new(MeshRef::new(&positions, &[])).unwrap_err(),
        UniformSampler::new(MeshRef::new(&positions, &[[0, 1, 7]])).unwrap_err(),
        DensityTexture::new(0, 3, vec![]).unwrap_err(),
        DensityTexture::new(1, 1, vec![f32::NAN]).unwrap_err(),
        DensitySampler::new(
            MeshRef::new(&positions, &[[0, 1, 2]]),
            Density::PerFace(&[1.0, 2.0]),
        )
        .unwrap_err(),
        DensitySampler::with_options(
            MeshRef {
                uvs: Some(&uvs),
                ..MeshRef::new(&positions, &[[0, 1, 2]])
            },
            Density::Texture(&DensityTexture::new(1, 1, vec![1.0]).unwrap()),
            &Options {
                max_pieces: 0,
                ..Options::default()
            },
        )
        .unwrap_err(),
        SurfacePoint::on(
            &MeshRef::new(&positions, &[[0, 1, 2]]),
            5,
            [1.0, 0.0, 0.0],
            1.0,
        )
        .unwrap_err(),
    ];
    for e in errors {
        let text = e.to_string();
        assert!(text.len() > 20 && text.contains(' '), "{e:?}: {text}");
        assert!(!text.contains("Empty") && !text.contains("{"), "{text}");
    }
}
