//! GPU/CPU parity of `trilux paint`'s mesh-colour shader
//! (`cli/src/paint/page/meshcolors.js`, Mesh Colors Sec. 5.3) in a real
//! browser: headless Chromium (SwiftShader WebGL2) driven by
//! `tests/browser/meshcolors_parity.mjs`.
//!
//! A sphere of 320 faces at mixed resolutions (1 to 64, raised with
//! `set_face_resolutions`) carries five channels (two texels per value:
//! RGB with per-sample noise, so every texel shows, and a scalar); its
//! `GpuLayout` (1024 texels wide, so indices wrap rows) is drawn with a
//! fixed camera through every filter (nearest, linear, MIP levels 1 and 3,
//! trilinear, anisotropic, the scalar's heat map), and each canvas is read
//! back. A pick pass of the same program gives each pixel's face,
//! barycentrics and their screen derivatives, at which `GpuLayout::lookup`
//! (bit for bit the CPU filters) is evaluated, encoded to 8 bits as the
//! shader does (sRGB, or the heat map), and compared: at most 1/255 per
//! channel on every compared pixel. The shader's wrong twins (edge
//! direction bit ignored, sample rows one texel short) must fail the same
//! comparison. Then a stroke: `GpuLayout::update`'s rectangles go up with
//! `updateRects`, and the picture must equal the CPU's on the new layout.
//!
//! Pixels are skipped only where the canvas and the pick pass show
//! different faces (the canvas's alpha carries the face id mod 255 + 1):
//! both are the same program on the same geometry without antialiasing,
//! so that happens only if the browser rasterizes its canvas differently
//! from a framebuffer (none did here); counted, and bounded at 1%.
//!
//! Needs what `view_browser.rs` needs (node, Chromium as `TRILUX_BROWSER`,
//! playwright-core in `target/browser-e2e`, installed by `.ci/run`);
//! without them the test prints a notice and passes, unless `CI` is set.
//! `TRILUX_PAINT_BENCH=1` also measures the Table I ratios (mesh-colour
//! shader against the baked atlas as a plain 2D texture) and prints them;
//! its scene stays in `target/paint-shader/bench`, and `node
//! target/browser-e2e/meshcolors_parity.mjs cli/src/paint/page/meshcolors.js
//! target/paint-shader/bench --bench` (from the workspace root) times the
//! browser side again alone.

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::{Mat4, Vec3};
use mesh_colors::gpu::{Filter, GpuLayout};
use mesh_colors::{MeshColors, MipMap, Topology};
use serde_json::{Value, json};
use test_support::SplitMix64;
use trilux_io::image::linear_to_srgb;

/// Canvas size (even, so 2×2 derivative quads align however the browser
/// stores the canvas).
const SIZE: u32 = 256;
/// Anisotropic probes at most.
const MAX_SAMPLES: u32 = 8;
/// The heat map's channel and range.
const HEAT_CHANNEL: usize = 4;
const HEAT_RANGE: [f32; 2] = [0.2, 0.9];

fn missing(what: &str) {
    assert!(
        std::env::var_os("CI").is_none(),
        "CI must run the paint shader test, but {what}"
    );
    eprintln!("notice: the paint shader parity test is skipped: {what}");
}

/// The browser and the node script, or why not.
struct Harness {
    browser: String,
    script: PathBuf,
    module: PathBuf,
    root: PathBuf,
}

impl Harness {
    fn find() -> Result<Self, String> {
        let browser =
            std::env::var("TRILUX_BROWSER").unwrap_or_else(|_| "/usr/bin/chromium".into());
        if !Path::new(&browser).exists() {
            return Err(format!("no browser at {browser} (set TRILUX_BROWSER)"));
        }
        let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
        let modules = root.join("target/browser-e2e/node_modules/playwright-core");
        if !modules.exists() {
            return Err(
                "playwright-core is not installed in target/browser-e2e (see .ci/run)".into(),
            );
        }
        if Command::new("node").arg("--version").output().is_err() {
            return Err("no node".into());
        }
        let script = crate::common::browser_script("meshcolors_parity.mjs");
        Ok(Self {
            browser,
            script,
            module: root.join("cli/src/paint/page/meshcolors.js"),
            root,
        })
    }

    /// Runs the script on `dir` with `extra` arguments; its JSON answer.
    fn run(&self, dir: &Path, extra: &[&str]) -> Value {
        let out = Command::new("node")
            .arg(&self.script)
            .arg(&self.module)
            .arg(dir)
            .args(extra)
            .env("TRILUX_BROWSER", &self.browser)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        let v: Value = serde_json::from_str(text.trim())
            .unwrap_or_else(|e| panic!("{e}: {text}\n{}", String::from_utf8_lossy(&out.stderr)));
        assert!(v.get("error").is_none(), "{v:#}");
        v
    }
}

/// The model: a unit icosphere of 320 faces, at resolution 4 with a cap
/// facing the camera raised to 64 (texels smaller than pixels there, so
/// the MIP levels matter), a band at 16, and faces at 1 and 2 (coarser
/// than their neighbours' edges) — mixed resolutions on shared edges.
fn model() -> (Vec<Vec3>, MeshColors) {
    let sphere = trilux::shapes::icosphere(2);
    let positions = sphere.positions.clone();
    let topology = Topology::new(positions.len(), &sphere.indices).unwrap();
    let mut colors = MeshColors::uniform(topology, 4, 5).unwrap();
    let mut raise = Vec::new();
    for (f, t) in sphere.indices.iter().enumerate() {
        let c = t.iter().map(|&v| positions[v as usize]).sum::<Vec3>() / 3.0;
        let r = if c.z > 0.75 && c.x < 0.3 {
            64
        } else if c.z > 0.3 && c.x >= 0.3 {
            16
        } else if c.y < -0.45 {
            if f % 2 == 0 { 1 } else { 2 }
        } else if c.x < -0.5 {
            32
        } else {
            continue;
        };
        raise.push((f, r));
    }
    colors.set_face_resolutions(&raise).unwrap();
    let mut rng = SplitMix64(45);
    colors
        .fill(&positions, |p, out| {
            let base = [
                0.5 + 0.35 * (3.0 * p.x).sin(),
                0.5 + 0.35 * (2.0 * p.y + 1.0).sin(),
                0.5 + 0.35 * (4.0 * p.z).cos(),
            ];
            for (o, b) in out.iter_mut().zip(base) {
                *o = (b as f32 + 0.6 * (rng.f32() - 0.5)).clamp(0.0, 1.0);
            }
            out[3] = 1.0;
            out[4] = 0.5 + 0.4 * (5.0 * p.x * p.y).sin() as f32 + 0.1 * rng.f32();
        })
        .unwrap();
    (positions, colors)
}

/// The fixed camera: a 50° perspective (OpenGL clip space) from `eye`
/// towards a point near the centre, column-major for `uniformMatrix4fv`.
fn view_proj() -> Mat4 {
    let eye = Vec3::new(0.5, 0.6, 2.9);
    let forward = (Vec3::new(0.05, 0.0, 0.0) - eye).normalize();
    let side = forward.cross(Vec3::Y).normalize();
    let up = side.cross(forward);
    let view = Mat4::from_cols(
        side.extend(0.0),
        up.extend(0.0),
        (-forward).extend(0.0),
        Vec3::ZERO.extend(1.0),
    )
    .transpose()
        * Mat4::from_translation(-eye);
    let (near, far) = (0.1f32, 10.0f32);
    let f = 1.0 / (25f32.to_radians()).tan();
    let proj = Mat4::from_cols(
        glam::Vec4::new(f, 0.0, 0.0, 0.0),
        glam::Vec4::new(0.0, f, 0.0, 0.0),
        glam::Vec4::new(0.0, 0.0, (far + near) / (near - far), -1.0),
        glam::Vec4::new(0.0, 0.0, 2.0 * far * near / (near - far), 0.0),
    );
    proj * view
}

fn write_le<T: Copy, const N: usize>(path: PathBuf, values: &[T], bytes: fn(T) -> [u8; N]) {
    let data: Vec<u8> = values.iter().flat_map(|&x| bytes(x)).collect();
    std::fs::write(path, data).unwrap();
}

/// The passes the script draws: (name, filter, the script's options).
fn passes() -> Vec<(&'static str, Filter, Value)> {
    let d = [0.0; 3];
    // The derivative-driven filters' arguments are filled per pixel.
    let tri = Filter::Trilinear { footprint: 0.0 };
    let aniso = Filter::Anisotropic {
        db_dx: d,
        db_dy: d,
        max_samples: MAX_SAMPLES,
    };
    vec![
        ("nearest", Filter::Nearest, json!({"filter": "nearest"})),
        ("linear", Filter::Linear, json!({"filter": "linear"})),
        (
            "level1",
            Filter::Level(1),
            json!({"filter": "level", "level": 1}),
        ),
        (
            "level3",
            Filter::Level(3),
            json!({"filter": "level", "level": 3}),
        ),
        ("trilinear", tri, json!({"filter": "trilinear"})),
        (
            "anisotropic",
            aniso,
            json!({"filter": "anisotropic", "maxSamples": MAX_SAMPLES}),
        ),
        (
            "heat",
            Filter::Linear,
            json!({"filter": "linear", "display": "heat", "channel": HEAT_CHANNEL, "range": HEAT_RANGE}),
        ),
        (
            "twin_edge_direction",
            Filter::Linear,
            json!({"filter": "linear", "defines": ["TWIN_EDGE_DIRECTION"]}),
        ),
        (
            "twin_row_width",
            Filter::Linear,
            json!({"filter": "linear", "defines": ["TWIN_ROW_WIDTH"]}),
        ),
    ]
}

/// Writes the layout, the mesh, the camera and the passes for the script.
fn write_scene(dir: &Path, colors: &MeshColors, positions: &[Vec3], layout: &GpuLayout, size: u32) {
    let corners: Vec<f32> = colors
        .topology()
        .faces()
        .iter()
        .flat_map(|t| t.iter().flat_map(|&v| positions[v as usize].to_array()))
        .collect();
    write_le(
        dir.join("samples.f32"),
        layout.sample_texels(),
        f32::to_le_bytes,
    );
    write_le(
        dir.join("faces.u32"),
        layout.face_texels(),
        u32::to_le_bytes,
    );
    write_le(dir.join("corners.f32"), &corners, f32::to_le_bytes);
    let passes: Vec<Value> = passes()
        .into_iter()
        .map(|(name, _, mut o)| {
            o["name"] = json!(name);
            o
        })
        .collect();
    let meta = json!({
        "width": layout.width(),
        "channels": layout.channels(),
        "face_count": layout.face_count(),
        "size": [size, size],
        "view_proj": view_proj().to_cols_array(),
        "passes": passes,
    });
    std::fs::write(dir.join("meta.json"), meta.to_string()).unwrap();
}

/// A stroke's worth of change: every sample of the faces whose centre
/// lies in a small cap (its edges and corners too, shared with the
/// neighbours) set to one colour. Returns the faces.
fn stroke(colors: &mut MeshColors, positions: &[Vec3]) -> Vec<usize> {
    let faces: Vec<usize> = (0..colors.face_count())
        .filter(|&f| {
            let t = colors.topology().faces()[f];
            let c = t.iter().map(|&v| positions[v as usize]).sum::<Vec3>() / 3.0;
            (c - Vec3::new(0.55, 0.35, 0.7)).length() < 0.3
        })
        .collect();
    for &f in &faces {
        let r = colors.face_resolution(f).unwrap();
        for a in mesh_colors::lattice_points(r) {
            if let Some(i) = colors.lattice_index(f, a) {
                colors
                    .sample_mut(i)
                    .unwrap()
                    .copy_from_slice(&[0.9, 0.1, 0.6, 1.0, 0.3]);
            }
        }
    }
    faces
}

/// The layout after `stroke`, and the texel rectangles `GpuLayout::update`
/// reports, written for the script's update step (`update.json`,
/// `samples2.f32`, `faces2.u32`).
fn write_update(dir: &Path, layout: &GpuLayout, colors: &MeshColors) -> GpuLayout {
    let mut updated = layout.clone();
    let changes = updated.update(&colors.mip_map()).unwrap();
    assert!(
        !changes.resized && !changes.samples.is_empty(),
        "{changes:?}"
    );
    let changed: u32 = changes.samples.iter().map(|r| r.width * r.height).sum();
    let all = (layout.sample_texels().len() / 4) as u32;
    assert!(
        changed * 4 < all,
        "the stroke changed {changed} of {all} texels"
    );
    let rects = |rs: &[mesh_colors::gpu::TexelRect]| -> Vec<Value> {
        rs.iter()
            .map(|r| json!({"x": r.x, "y": r.y, "width": r.width, "height": r.height}))
            .collect()
    };
    let update = json!({
        "resized": changes.resized,
        "samples": rects(&changes.samples),
        "faces": rects(&changes.faces),
    });
    std::fs::write(dir.join("update.json"), update.to_string()).unwrap();
    write_le(
        dir.join("samples2.f32"),
        updated.sample_texels(),
        f32::to_le_bytes,
    );
    write_le(
        dir.join("faces2.u32"),
        updated.face_texels(),
        u32::to_le_bytes,
    );
    updated
}

/// One pixel of the pick pass.
struct Pick {
    face: f32,
    b: [f32; 3],
    dx: [f32; 3],
    dy: [f32; 3],
}

fn read_picks(path: &Path) -> Vec<Pick> {
    let bytes = std::fs::read(path).unwrap();
    let f: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    assert_eq!(f.len(), (SIZE * SIZE * 12) as usize);
    f.chunks_exact(12)
        .map(|p| Pick {
            face: p[0],
            b: [p[1], p[2], p[3]],
            dx: [p[4], p[5], p[6]],
            dy: [p[8], p[9], p[10]],
        })
        .collect()
}

/// A barycentric displacement's length on the equilateral triangle (as
/// `MipMap::anisotropic` and the shader measure it).
fn metric(d: [f32; 3]) -> f32 {
    let (x, y) = (d[0] + 0.5 * d[1], d[1] * 0.866_025_4);
    (x * x + y * y).sqrt()
}

/// The CPU's filter for a pixel: the derivative-driven ones take the pick
/// pass's derivatives (the trilinear footprint is the longer axis).
fn at_pixel(filter: Filter, p: &Pick) -> Filter {
    match filter {
        Filter::Trilinear { .. } => Filter::Trilinear {
            footprint: metric(p.dx).max(metric(p.dy)),
        },
        Filter::Anisotropic { max_samples, .. } => Filter::Anisotropic {
            db_dx: p.dx,
            db_dy: p.dy,
            max_samples,
        },
        f => f,
    }
}

/// The shader's heat map (five sRGB stops, linear between them).
fn heat(v: f32) -> [f32; 3] {
    const STOPS: [[f32; 3]; 5] = [
        [0.05, 0.03, 0.2],
        [0.45, 0.1, 0.55],
        [0.85, 0.2, 0.3],
        [0.98, 0.6, 0.1],
        [0.99, 0.97, 0.65],
    ];
    let s = ((v - HEAT_RANGE[0]) / (HEAT_RANGE[1] - HEAT_RANGE[0])).clamp(0.0, 1.0) * 4.0;
    let i = (s as usize).min(3);
    let t = s - i as f32;
    [0, 1, 2].map(|c| STOPS[i][c] + (STOPS[i + 1][c] - STOPS[i][c]) * t)
}

/// What one pass's comparison found.
#[derive(Debug, Default)]
struct Tally {
    covered: usize,
    compared: usize,
    skipped: usize,
    /// The largest difference, in 8-bit units.
    max_diff: u8,
    /// Pixels off by more than one unit.
    over: usize,
}

/// Compares the canvas of one pass with the CPU lookup at every covered
/// pixel of the pick pass.
fn compare(layout: &GpuLayout, picks: &[Pick], canvas: &[u8], name: &str, filter: Filter) -> Tally {
    let mut t = Tally::default();
    let mut value = vec![0.0f32; layout.channels()];
    for (p, px) in picks.iter().zip(canvas.chunks_exact(4)) {
        if p.face < 0.0 {
            continue;
        }
        t.covered += 1;
        let face = p.face as usize;
        // The canvas shows another face here (or none): its alpha tag
        // differs from the pick pass's face.
        if u32::from(px[3]) != face as u32 % 255 + 1 {
            t.skipped += 1;
            continue;
        }
        t.compared += 1;
        layout
            .lookup(face, p.b, at_pixel(filter, p), &mut value)
            .unwrap();
        let rgb = if name == "heat" {
            heat(value[HEAT_CHANNEL])
        } else {
            [0, 1, 2].map(|c| linear_to_srgb(value[c]))
        };
        for (c, x) in rgb.iter().enumerate() {
            let want = (x * 255.0).round() as i32;
            let diff = (want - i32::from(px[c])).unsigned_abs() as u8;
            t.max_diff = t.max_diff.max(diff);
            if diff > 1 {
                t.over += 1;
                break;
            }
        }
    }
    t
}

#[test]
fn the_mesh_colour_shader_matches_the_cpu_filters_in_chromium() {
    let h = match Harness::find() {
        Ok(h) => h,
        Err(why) => return missing(&why),
    };
    let (positions, colors) = model();
    let mip: MipMap = colors.mip_map();
    let layout = GpuLayout::new(&mip, 1024).unwrap();
    assert!(layout.sample_height() > 10, "indices must wrap rows");
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    write_scene(dir, &colors, &positions, &layout, SIZE);
    let mut stroked = colors.clone();
    let painted = stroke(&mut stroked, &positions);
    assert!(painted.len() >= 3, "{painted:?}");
    let updated = write_update(dir, &layout, &stroked);
    let shots = h.root.join("target/paint-shader");
    std::fs::create_dir_all(&shots).unwrap();
    let v = h.run(dir, &["--shots", shots.to_str().unwrap()]);
    assert_eq!(v["errors"], 0, "{v:#}");
    let picks = read_picks(&dir.join("pick.f32"));
    let mut canvases: std::collections::HashMap<&str, Vec<u8>> = std::collections::HashMap::new();
    for (name, filter, _) in passes() {
        let canvas = std::fs::read(dir.join(format!("{name}.rgba8"))).unwrap();
        let t = compare(&layout, &picks, &canvas, name, filter);
        eprintln!(
            "paint shader parity: {name:>20}: {} pixels compared, {} skipped, max difference {}/255, {} over 1/255",
            t.compared, t.skipped, t.max_diff, t.over
        );
        assert!(t.covered > 20_000, "{name}: {t:?}");
        // Skipped pixels: where the canvas and the pick pass disagree on
        // the face (the same program and geometry: rasterization is the
        // same, so at most a few edge pixels).
        assert!(t.skipped * 100 <= t.covered, "{name}: {t:?}");
        if name.starts_with("twin_") {
            assert!(
                t.over * 20 > t.compared,
                "the wrong twin {name} passed: {t:?}"
            );
        } else {
            assert!(t.max_diff <= 1, "{name}: {t:?}");
        }
        canvases.insert(name, canvas);
    }
    // After the stroke: only the changed rectangles went up
    // (texSubImage2D), and the picture equals the CPU's on the new layout
    // everywhere, painted or not.
    for (name, filter) in [
        ("after_linear", Filter::Linear),
        ("after_trilinear", passes()[4].1),
    ] {
        let canvas = std::fs::read(dir.join(format!("{name}.rgba8"))).unwrap();
        let t = compare(&updated, &picks, &canvas, name, filter);
        eprintln!(
            "paint shader parity: {name:>20}: {} pixels compared, {} skipped, max difference {}/255, {} over 1/255",
            t.compared, t.skipped, t.max_diff, t.over
        );
        assert!(
            t.max_diff <= 1 && t.skipped * 100 <= t.covered,
            "{name}: {t:?}"
        );
        canvases.insert(name, canvas);
    }
    assert!(differ_from(&canvases["after_linear"], &canvases["linear"]) > 500);
    // The scene exercises what it claims: texel detail (nearest differs
    // from linear), MIP levels coarser than the finest (trilinear differs
    // from linear), anisotropy (anisotropic differs from trilinear).
    let differ = |a: &str, b: &str| differ_from(&canvases[a], &canvases[b]);
    assert!(differ("nearest", "linear") > 5_000);
    assert!(differ("trilinear", "linear") > 5_000);
    assert!(differ("anisotropic", "trilinear") > 1_000);
    if std::env::var_os("TRILUX_PAINT_BENCH").is_some() {
        // The bench's scene stays in target/paint-shader/bench, so that
        // the browser side can be timed again alone (cli/README.md).
        let kept = h.root.join("target/paint-shader/bench");
        std::fs::create_dir_all(&kept).unwrap();
        bench(&h, &kept, "the parity sphere", &colors, &positions, &layout);
        bench_spot(&h, &h.root.join("target/paint-shader/bench-spot"));
    }
}

/// Table I on a real model, as the paper measures it: Spot with its
/// texture converted at the default resolution (what `trilux paint
/// spot.obj` shows), fitted into the sphere's view. Its faces are finely
/// sampled, so most fragments take the shader's interior path, where the
/// parity sphere's resolution-4 faces mostly take the boundary path.
fn bench_spot(h: &Harness, dir: &Path) {
    let Some(data) = test_support::data::data_dir() else {
        return eprintln!("paint shader bench: TRILUX_DATA is not set, no Spot row");
    };
    let mesh = trilux_io::mesh::TriMesh::read(data.join("meshes/spot.obj")).unwrap();
    let image = trilux_io::image::read(data.join("textures/spot_texture.png")).unwrap();
    let (surface, colors) =
        trilux::to_mesh_colors(&mesh, Some(&image), &Default::default()).unwrap();
    let (lo, hi) = surface.positions.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let (centre, radius) = ((lo + hi) / 2.0, (hi - lo).length() / 2.0);
    let positions: Vec<Vec3> = surface
        .positions
        .iter()
        .map(|&p| (p - centre) / radius)
        .collect();
    let layout = GpuLayout::new(&colors.mip_map(), 2048).unwrap();
    std::fs::create_dir_all(dir).unwrap();
    bench(h, dir, "Spot converted", &colors, &positions, &layout);
}

/// Pixels where two canvases differ by more than 2/255 in some channel.
fn differ_from(a: &[u8], b: &[u8]) -> usize {
    a.chunks_exact(4)
        .zip(b.chunks_exact(4))
        .filter(|(x, y)| x[..3].iter().zip(&y[..3]).any(|(p, q)| p.abs_diff(*q) > 2))
        .count()
}

/// Table I: the shader's frame time against the baked atlas drawn as a
/// plain 2D texture, same view, at 1024² (report only).
fn bench(
    h: &Harness,
    dir: &Path,
    scene: &str,
    colors: &MeshColors,
    positions: &[Vec3],
    layout: &GpuLayout,
) {
    let atlas = mesh_colors::atlas::bake(colors, &Default::default()).unwrap();
    let tex = &atlas.texture;
    let c = tex.channels();
    let texels: Vec<u8> = tex
        .data()
        .chunks_exact(c)
        .flat_map(|t| {
            let e = |x: f32| (linear_to_srgb(x) * 255.0).round() as u8;
            [e(t[0]), e(t[1]), e(t[2]), 255]
        })
        .collect();
    std::fs::write(dir.join("atlas.rgba8"), texels).unwrap();
    let uvs: Vec<f32> = atlas
        .corner_uvs
        .iter()
        .flat_map(|t| t.iter().flat_map(|uv| uv.to_array()))
        .collect();
    write_le(dir.join("uvs.f32"), &uvs, f32::to_le_bytes);
    write_scene(dir, colors, positions, layout, 1024);
    let meta_path = dir.join("meta.json");
    let mut meta: Value = serde_json::from_slice(&std::fs::read(&meta_path).unwrap()).unwrap();
    meta["atlas"] = json!([tex.width(), tex.height()]);
    std::fs::write(&meta_path, meta.to_string()).unwrap();
    let v = h.run(dir, &["--bench"]);
    eprintln!(
        "paint shader bench, {scene} (SwiftShader, load {}): {:#}; mesh-colour texels {} (all levels), atlas texels {}",
        std::fs::read_to_string("/proc/loadavg")
            .unwrap_or_default()
            .trim(),
        v["bench"],
        layout.sample_texels().len() / 4,
        tex.width() * tex.height()
    );
}
