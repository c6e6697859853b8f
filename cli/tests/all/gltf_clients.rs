//! glTF files written by trilux-io, checked by real clients: the Khronos
//! glTF-Validator (no error, no warning) and three.js's GLTFLoader in
//! headless Chromium (`tests/browser/three_gltf.mjs`), whose unlit render
//! must show the baked texture's colours and the vertex colours.
//!
//! Needs `node`, Chromium (`TRILUX_BROWSER`; default `/usr/bin/chromium`)
//! and the npm packages of `tests/browser/package.json` installed under
//! `target/browser-e2e` (`.ci/run` installs all of them). Without them a
//! check prints a notice and passes, unless `CI` is set.
//! `TRILUX_SCREENSHOTS=DIR` keeps the written files and their renders
//! there.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use serde_json::Value;
use trilux_io::glam::{Vec2, Vec3};
use trilux_io::image::Image;
use trilux_io::mesh::gltf::{self, Attribute, AttributeValues, Points, VertexData};
use trilux_io::mesh::{Material, Object, TriMesh, Wrap};

/// Within this many 8-bit units of the prediction: SwiftShader's sRGB
/// decode and encode round within one unit each.
const TOLERANCE: i32 = 3;

/// The render's background, 8-bit sRGB (`--background`).
const BACKGROUND: [u8; 3] = [0x40, 0x40, 0x40];

fn missing(what: &str) {
    assert!(
        std::env::var_os("CI").is_none(),
        "CI must run the three.js check of the glTF writer, but {what}"
    );
    eprintln!("notice: the three.js check of the glTF writer is skipped: {what}");
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The 8-bit sRGB encoding of a linear value, as three.js's output does.
fn srgb8(linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

/// The linear value of an 8-bit sRGB one.
fn linear(srgb: u8) -> f32 {
    let s = f32::from(srgb) / 255.0;
    if s <= 0.040_45 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

/// Where the three.js script is: copied once into `target/browser-e2e`,
/// whose `node_modules` it imports from; `None` (after a notice) when
/// something it needs is not installed.
fn three_script() -> Option<(PathBuf, String)> {
    static SCRIPT: OnceLock<Result<(PathBuf, String), String>> = OnceLock::new();
    let found = SCRIPT.get_or_init(|| {
        let browser =
            std::env::var("TRILUX_BROWSER").unwrap_or_else(|_| "/usr/bin/chromium".into());
        if !Path::new(&browser).exists() {
            return Err(format!("no browser at {browser} (set TRILUX_BROWSER)"));
        }
        let dir = root().join("target/browser-e2e");
        for package in ["playwright-core", "three"] {
            if !dir.join("node_modules").join(package).is_dir() {
                return Err(format!(
                    "{package} is not installed in target/browser-e2e (see .ci/run)"
                ));
            }
        }
        if Command::new("node").arg("--version").output().is_err() {
            return Err("no node".into());
        }
        let script = crate::common::browser_script("three_gltf.mjs");
        Ok((script, browser))
    });
    match found {
        Ok(s) => Some(s.clone()),
        Err(what) => {
            missing(what);
            None
        }
    }
}

/// Where the written files and screenshots go: `TRILUX_SCREENSHOTS`
/// (kept) or the test's temporary folder.
fn out_dir(temporary: &Path) -> PathBuf {
    match std::env::var_os("TRILUX_SCREENSHOTS") {
        Some(dir) => {
            std::fs::create_dir_all(&dir).unwrap();
            PathBuf::from(dir)
        }
        None => temporary.to_path_buf(),
    }
}

/// How to keep a render that showed a failure.
fn keep_hint() -> &'static str {
    if std::env::var_os("TRILUX_SCREENSHOTS").is_some() {
        ""
    } else {
        "; set TRILUX_SCREENSHOTS=DIR to keep it"
    }
}

/// Runs three_gltf.mjs on `model` with `args` and returns its JSON, or
/// `None` when it cannot run here.
fn three(model: &Path, screenshot: &Path, args: &[String]) -> Option<Value> {
    let (script, browser) = three_script()?;
    let out = Command::new("node")
        .arg(&script)
        .arg(model)
        .arg(screenshot)
        .args(args)
        .env("TRILUX_BROWSER", &browser)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    let v: Value = serde_json::from_str(text.trim()).unwrap_or_else(|e| {
        panic!(
            "three_gltf.mjs on {}: {e}: {text}\n{}",
            model.display(),
            String::from_utf8_lossy(&out.stderr)
        )
    });
    assert!(
        v.get("error").is_none(),
        "three.js on {}: {v:#}",
        model.display()
    );
    // Errors of the page (a failed request, a shader that did not
    // compile, GLTFLoader's own complaints); readPixels' GPU-stall
    // warnings are harmless.
    let bad: Vec<&Value> = v["console"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| {
            let m = m.as_str().unwrap();
            !m.starts_with("warning:") || m.contains("THREE.")
        })
        .collect();
    assert!(bad.is_empty(), "three.js on {}: {bad:#?}", model.display());
    eprintln!(
        "three.js r{} on {}: screenshot {}",
        v["three"].as_str().unwrap(),
        model.display(),
        screenshot.display()
    );
    Some(v)
}

/// Asserts that probe `i` of `v` reads `expected` (8-bit sRGB, opaque).
fn assert_pixel(v: &Value, i: usize, expected: [u8; 3], what: &str) {
    let probe = &v["probes"][i];
    let rgba: Vec<i32> = probe["rgba"]
        .as_array()
        .unwrap_or_else(|| panic!("no probe {i} in {v:#}"))
        .iter()
        .map(|c| c.as_i64().unwrap() as i32)
        .collect();
    let off = (0..3).any(|k| (rgba[k] - i32::from(expected[k])).abs() > TOLERANCE);
    assert!(
        !off && rgba[3] == 255,
        "{what}: three.js drew {rgba:?} at pixel {} (normalized {}), expected {expected:?} \
         ± {TOLERANCE}, alpha 255 (screenshot {}{})",
        probe["pixel"],
        probe["at"],
        v["screenshot"],
        keep_hint()
    );
}

fn world(p: Vec3) -> [String; 2] {
    ["--world".into(), format!("{},{},{}", p.x, p.y, p.z)]
}

/// The four quadrants of the texture, 8-bit sRGB as the PNG must hold
/// them: top-left, top-right, bottom-left, bottom-right of the image.
/// Mid-tones, not only 0 and 255, so a texture written without the sRGB
/// encoding (or decoded twice) shows.
const QUADRANTS: [[u8; 3]; 4] = [
    [200, 30, 40],   // red
    [40, 170, 60],   // green
    [30, 70, 210],   // blue
    [235, 235, 235], // white
];

/// A unit quad in the xy-plane facing +z, textured with [`QUADRANTS`]
/// (a 16 x 16 image, linear RGBA as trilux keeps it): image row 0 at the
/// top (y = 1), as glTF's v-down UVs put it.
fn textured_quad() -> TriMesh {
    let n = 16;
    let pixels = (0..n * n)
        .map(|i| {
            let (row, col) = (i / n, i % n);
            let q = QUADRANTS[usize::from(row >= n / 2) * 2 + usize::from(col >= n / 2)];
            [linear(q[0]), linear(q[1]), linear(q[2]), 1.0]
        })
        .collect();
    TriMesh {
        positions: vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        normals: Some(vec![Vec3::Z; 4]),
        uvs: Some(vec![
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 0.0),
        ]),
        objects: vec![Object {
            name: "quad".into(),
            triangles: 0..2,
            material: Some(0),
        }],
        materials: vec![Material {
            name: "quadrants".into(),
            diffuse: [1.0; 3],
            diffuse_texture: None,
            diffuse_image: Some(Image {
                width: n as u32,
                height: n as u32,
                pixels,
            }),
            wrap: [Wrap::ClampToEdge; 2],
            scalar_images: Vec::new(),
        }],
        ..TriMesh::default()
    }
}

/// Four separate triangles side by side in the xy-plane, each with one
/// linear colour on its three vertices (radiance-like values, not only
/// 0 and 1), plus a `_RADIANCE` attribute of the same values.
const TRIANGLE_COLOURS: [[f32; 3]; 4] = [
    [0.8, 0.05, 0.02],
    [0.1, 0.6, 0.15],
    [0.02, 0.1, 0.9],
    [0.25, 0.25, 0.25],
];

fn coloured_triangles() -> (TriMesh, VertexData, Vec<Vec3>) {
    let mut positions = Vec::new();
    let mut colours = Vec::new();
    let mut centres = Vec::new();
    for (i, c) in TRIANGLE_COLOURS.iter().enumerate() {
        let x = i as f32 * 1.1;
        let corners = [
            Vec3::new(x, 0.0, 0.0),
            Vec3::new(x + 1.0, 0.0, 0.0),
            Vec3::new(x + 0.5, 1.0, 0.0),
        ];
        centres.push((corners[0] + corners[1] + corners[2]) / 3.0);
        positions.extend(corners);
        colours.extend([[c[0], c[1], c[2], 1.0]; 3]);
    }
    let radiance = colours
        .iter()
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect();
    let mesh = TriMesh {
        positions,
        indices: (0..4).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
        ..TriMesh::default()
    };
    let data = VertexData {
        colors: Some(colours),
        attributes: vec![Attribute {
            name: "RADIANCE".into(),
            values: AttributeValues::Vec3(radiance),
        }],
    };
    (mesh, data, centres)
}

#[test]
fn a_textured_quad_validates_and_three_js_shows_its_quadrants() {
    let temporary = tempfile::tempdir().unwrap();
    let dir = out_dir(temporary.path());
    let mesh = textured_quad();
    for name in ["quad.glb", "quad.gltf"] {
        let path = dir.join(name);
        mesh.write(&path).unwrap();
        test_support::gltf::validate(&path);
        // The quadrant centres, in the order of QUADRANTS, then a corner
        // of the canvas outside the quad (the framing leaves 5%).
        let centres = [[0.25, 0.75], [0.75, 0.75], [0.25, 0.25], [0.75, 0.25]];
        let mut args: Vec<String> = centres
            .iter()
            .flat_map(|[x, y]| world(Vec3::new(*x, *y, 0.0)))
            .collect();
        args.extend(["--at".into(), "0.005,0.005".into()]);
        args.extend(["--background".into(), "404040".into()]);
        let shot = dir.join(format!("{name}.png"));
        let Some(v) = three(&path, &shot, &args) else {
            return;
        };
        assert_eq!(
            (v["meshes"].as_u64(), v["points"].as_u64()),
            (Some(1), Some(0)),
            "{v:#}"
        );
        let object = &v["objects"][0];
        assert_eq!(object["vertices"], 4, "{v:#}");
        assert_eq!(object["triangles"], 2, "{v:#}");
        let material = &object["material"];
        assert_eq!(material["map"], true, "no base-colour texture: {v:#}");
        assert_eq!(material["map_size"], serde_json::json!([16, 16]), "{v:#}");
        assert_eq!(material["map_color_space"], "srgb", "{v:#}");
        // The base-colour factor, linear: white, so the texture shows as it is.
        let factor: Vec<f64> = material["color"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_f64().unwrap())
            .collect();
        assert_eq!(factor, [1.0; 3], "{v:#}");
        for (i, q) in QUADRANTS.iter().enumerate() {
            assert_pixel(&v, i, *q, &format!("{name}: quadrant {i} of the texture"));
        }
        assert_pixel(&v, 4, BACKGROUND, &format!("{name}: the background"));
    }
}

#[test]
fn vertex_colours_validate_and_three_js_draws_them() {
    let temporary = tempfile::tempdir().unwrap();
    let dir = out_dir(temporary.path());
    let (mesh, data, centres) = coloured_triangles();
    let path = dir.join("colours.glb");
    gltf::write_with(&path, &mesh, &data).unwrap();
    test_support::gltf::validate(&path);
    let mut args: Vec<String> = centres.iter().flat_map(|c| world(*c)).collect();
    // Between the triangles' bases: the background.
    args.extend(world(Vec3::new(1.05, 0.05, 0.0)));
    let shot = dir.join("colours.glb.png");
    let Some(v) = three(&path, &shot, &args) else {
        return;
    };
    assert_eq!(
        (v["meshes"].as_u64(), v["vertices"].as_u64()),
        (Some(1), Some(12)),
        "{v:#}"
    );
    let object = &v["objects"][0];
    assert_eq!(object["triangles"], 4, "{v:#}");
    assert_eq!(
        object["gltf_attributes"],
        serde_json::json!(["COLOR_0", "POSITION", "_RADIANCE"]),
        "{v:#}"
    );
    // GLTFLoader keeps custom attributes under their lower-case names.
    assert!(
        object["attributes"]
            .as_array()
            .unwrap()
            .contains(&"_radiance".into()),
        "{v:#}"
    );
    let material = &object["material"];
    assert_eq!(material["vertex_colors"], true, "COLOR_0 unused: {v:#}");
    assert_eq!(material["map"], false, "{v:#}");
    for (i, c) in TRIANGLE_COLOURS.iter().enumerate() {
        let expected = c.map(srgb8);
        assert_pixel(
            &v,
            i,
            expected,
            &format!("triangle {i}'s linear colour {c:?}"),
        );
    }
    assert_pixel(&v, 4, BACKGROUND, "between the triangles");
}

#[test]
fn points_validate_and_three_js_draws_them_as_points() {
    let temporary = tempfile::tempdir().unwrap();
    let dir = out_dir(temporary.path());
    let positions: Vec<Vec3> = (0..3)
        .flat_map(|j| (0..3).map(move |i| Vec3::new(i as f32, j as f32, 0.0)))
        .collect();
    let colours: Vec<[f32; 4]> = (0..9)
        .map(|k| {
            let c = TRIANGLE_COLOURS[k % 4];
            [c[0], c[1], c[2], 1.0]
        })
        .collect();
    let points = Points {
        positions: positions.clone(),
        normals: Some(vec![Vec3::Z; 9]),
        faces: Some((0..9).collect()),
        vertex_data: VertexData {
            colors: Some(colours.clone()),
            attributes: Vec::new(),
        },
        ..Points::default()
    };
    let path = dir.join("points.glb");
    gltf::write_points(&path, &points).unwrap();
    test_support::gltf::validate(&path);
    let mut args: Vec<String> = positions.iter().flat_map(|p| world(*p)).collect();
    // Halfway between two points: the background.
    args.extend(world(Vec3::new(0.5, 0.5, 0.0)));
    args.extend(["--point-size".into(), "9".into()]);
    // The points span [0, 2]²: leave room for the outer points' squares.
    args.extend(["--ortho".into(), "1,1,1.5".into()]);
    let shot = dir.join("points.glb.png");
    let Some(v) = three(&path, &shot, &args) else {
        return;
    };
    assert_eq!(
        (v["meshes"].as_u64(), v["points"].as_u64()),
        (Some(0), Some(1)),
        "{v:#}"
    );
    let object = &v["objects"][0];
    assert_eq!(object["vertices"], 9, "{v:#}");
    assert_eq!(
        object["gltf_attributes"],
        serde_json::json!(["COLOR_0", "NORMAL", "POSITION", "_FACE"]),
        "{v:#}"
    );
    assert_eq!(object["material"]["vertex_colors"], true, "{v:#}");
    for (i, c) in colours.iter().enumerate() {
        let expected = [c[0], c[1], c[2]].map(srgb8);
        assert_pixel(&v, i, expected, &format!("point {i}'s linear colour {c:?}"));
    }
    assert_pixel(&v, 9, BACKGROUND, "between the points");
}

/// The rendered pixel of probe `i`, 8-bit sRGB, opaque.
fn pixel(v: &Value, i: usize) -> [u8; 3] {
    let rgba: Vec<u8> = v["probes"][i]["rgba"]
        .as_array()
        .unwrap_or_else(|| panic!("no probe {i} in {v:#}"))
        .iter()
        .map(|c| c.as_u64().unwrap() as u8)
        .collect();
    assert_eq!(rgba[3], 255, "probe {i}: {v:#}");
    [rgba[0], rgba[1], rgba[2]]
}

#[test]
fn a_diffuse_glb_lit_from_one_side_shows_its_lit_side_brighter_in_three_js() {
    let temporary = tempfile::tempdir().unwrap();
    let dir = out_dir(temporary.path());
    // A unit sphere, 10 mm across per unit, of marble, lit from +x only.
    let sphere = dir.join("sphere.obj");
    if sphere.exists() {
        std::fs::remove_file(&sphere).unwrap();
    }
    trilux::shapes::icosphere(3).write(&sphere).unwrap();
    let glb = dir.join("sphere_diffuse.glb");
    let out = Command::new(env!("CARGO_BIN_EXE_trilux"))
        .current_dir(&dir)
        .args(["--force", "diffuse", "sphere.obj", "--material", "marble"])
        .args(["--unit-mm", "10", "--light", "dir:1,0,0", "--size", "96"])
        .args(["-o", "sphere_diffuse.png", "--glb", "sphere_diffuse.glb"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    test_support::gltf::validate(&glb);
    let scene = gltf::read_scene(&glb).unwrap();
    let colours = scene.vertex_data.colors.as_ref().unwrap();
    assert!(colours.iter().flatten().all(|c| (0.0..=1.0).contains(c)));
    // Points on the sphere's front (+z, toward three.js's camera): the
    // lit side, the middle, the far side; then the background.
    let probes = [
        Vec3::new(0.6, 0.0, 0.8),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(-0.6, 0.0, 0.8),
    ];
    let mut args: Vec<String> = probes.iter().flat_map(|p| world(*p)).collect();
    args.extend(["--at".into(), "0.005,0.005".into()]);
    let shot = dir.join("sphere_diffuse.glb.png");
    let Some(v) = three(&glb, &shot, &args) else {
        return;
    };
    let object = &v["objects"][0];
    assert_eq!(
        object["gltf_attributes"],
        serde_json::json!(["COLOR_0", "NORMAL", "POSITION", "_PHI", "_RADIANCE"]),
        "{v:#}"
    );
    assert_eq!(object["material"]["vertex_colors"], true, "{v:#}");
    // The base colour is white: the vertex colours are the whole colour.
    let factor: Vec<f64> = object["material"]["color"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_f64().unwrap())
        .collect();
    assert_eq!(factor, [1.0; 3], "{v:#}");
    let lum = |p: [u8; 3]| 0.2126 * linear(p[0]) + 0.7152 * linear(p[1]) + 0.0722 * linear(p[2]);
    let [lit, middle, dark] = [0, 1, 2].map(|i| pixel(&v, i));
    let shown = format!(
        "lit {lit:?}, middle {middle:?}, far {dark:?} (screenshot {}{})",
        shot.display(),
        keep_hint()
    );
    eprintln!("diffuse --glb in three.js: {shown}");
    // Non-black where lit, and brighter toward the light.
    assert!(lit.iter().all(|&c| c >= 64), "{shown}");
    assert!(lum(lit) > 1.5 * lum(middle), "{shown}");
    assert!(lum(middle) > 1.5 * lum(dark), "{shown}");
    // Marble is translucent: light reaches the far side too.
    assert!(lum(dark) > 0.0, "{shown}");
    // Not a flat grey: marble's red scatters farthest.
    assert!(dark[0] > dark[2], "{shown}");
    assert_pixel(&v, 3, BACKGROUND, "beside the sphere");
}
