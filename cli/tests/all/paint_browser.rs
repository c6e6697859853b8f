//! `trilux paint`'s page in a real browser: headless Chromium (software
//! WebGL through SwiftShader) driven by `tests/browser/paint.mjs` — load,
//! first frame, a stroke that changes the pixels under it and nowhere
//! else, the eyedropper, the detail brush, undo and redo back to the same
//! pixels, save and a GLB export through the buttons, and the saved
//! colours reloaded into the same pixels.
//!
//! Needs what `view_browser.rs` needs (node, Chromium, playwright-core in
//! `target/browser-e2e`); without them it prints a notice and passes,
//! unless `CI` is set.
#![cfg(feature = "paint")]

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::{Value, json};
use trilux::ColorMesh;
use trilux::mesh_colors::MeshColors;
use trilux::paint::{Document, Options};

fn missing(what: &str) {
    assert!(
        std::env::var_os("CI").is_none(),
        "CI must run the browser test, but {what}"
    );
    eprintln!("notice: the browser test of trilux paint is skipped: {what}");
}

/// The built-in blob at resolution 8, grey (with a `density` channel, 0,
/// when `density`).
fn document_with(colors: Option<MeshColors>, density: bool) -> Document {
    let mut doc = document(colors);
    if density {
        let c = MeshColors::uniform(doc.surface.topology().unwrap(), 8, 4).unwrap();
        let mut c = c;
        for s in c.samples_mut().chunks_mut(4) {
            s.copy_from_slice(&[0.8, 0.8, 0.8, 0.0]);
        }
        doc.colors = c;
        doc.base = vec![0.8, 0.8, 0.8, 0.0];
        doc.scalars = vec!["density".into()];
    }
    doc
}

/// The built-in blob at resolution 8, grey.
fn document(colors: Option<MeshColors>) -> Document {
    let surface = ColorMesh::new(&trilux::shapes::blob(3)).unwrap();
    let colors = colors.unwrap_or_else(|| {
        let mut c = MeshColors::uniform(surface.topology().unwrap(), 8, 3).unwrap();
        c.samples_mut().fill(0.8);
        c
    });
    Document {
        surface,
        colors,
        base: vec![0.8; 3],
        scalars: Vec::new(),
        source: json!({"mesh": null}),
    }
}

/// Serves `doc` with exports into `exports` and runs the page script.
async fn run(
    script: &Path,
    browser: &str,
    shots: &Path,
    exports: &Path,
    doc: Document,
    mode: &str,
) -> Value {
    let options = Options {
        export_dir: exports.to_path_buf(),
        ..Options::default()
    };
    let running = trilux::paint::start(doc, None, options).await.unwrap();
    let out = tokio::task::spawn_blocking({
        let (script, browser, url, shots, mode) = (
            script.to_path_buf(),
            browser.to_string(),
            running.url(),
            shots.to_path_buf(),
            mode.to_string(),
        );
        move || {
            Command::new("node")
                .arg(&script)
                .arg(&url)
                .arg(&shots)
                .arg(&mode)
                .env("TRILUX_BROWSER", &browser)
                .current_dir(script.parent().unwrap())
                .output()
                .unwrap()
        }
    })
    .await
    .unwrap();
    running.stop().await.unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout.lines().last().unwrap_or_default();
    let v: Value = serde_json::from_str(line)
        .unwrap_or_else(|e| panic!("{e}: {stdout}\n{}", String::from_utf8_lossy(&out.stderr)));
    assert!(v.get("failure").is_none(), "{v:#}");
    v
}

/// Where screenshots go: `TRILUX_SCREENSHOTS` (to look at them), else
/// the test's own folder.
fn shots(tmp: &Path) -> PathBuf {
    std::env::var("TRILUX_SCREENSHOTS")
        .map(PathBuf::from)
        .unwrap_or_else(|_| tmp.to_path_buf())
}

/// The browser, the script's path and a screenshot folder, or `None`
/// (with the notice) when something is missing.
fn setup(script: &str) -> Option<(String, PathBuf)> {
    let browser = std::env::var("TRILUX_BROWSER").unwrap_or_else(|_| "/usr/bin/chromium".into());
    if !Path::new(&browser).exists() {
        missing(&format!("no browser at {browser} (set TRILUX_BROWSER)"));
        return None;
    }
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    if !root
        .join("target/browser-e2e/node_modules/playwright-core")
        .exists()
    {
        missing("playwright-core is not installed in target/browser-e2e (see .ci/run)");
        return None;
    }
    if Command::new("node").arg("--version").output().is_err() {
        missing("no node");
        return None;
    }
    Some((browser, crate::common::browser_script(script)))
}

/// The scatter panel in the page: rate mode shows nothing until the
/// density is painted, a stroke of density grows orange points under
/// it, strands appear, and both exports are written and valid.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_scatter_panel_follows_a_stroke_of_density_in_chromium() {
    let Some((browser, script)) = setup("scatter.mjs") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let (shots, exports) = (shots(tmp.path()), tmp.path());
    let doc = document_with(None, true);
    let v = run(&script, &browser, &shots, exports, doc, "test").await;
    assert_eq!(v["console_errors"], json!([]), "{v:#}");
    let step = |s: &str| &v["steps"][s];
    assert_eq!(step("legend"), true, "{v:#}");
    assert_eq!(step("rate")["points"], 0, "{v:#}");
    assert_eq!(step("rate")["orange"], 0, "{v:#}");
    let empty = step("empty_export");
    assert!(
        empty["message"].as_str().unwrap().contains("no points"),
        "{empty}"
    );
    assert_eq!(step("refused")["mode"], "rate", "{v:#}");
    let stroke = step("stroke");
    assert!(stroke["points"].as_u64().unwrap() > 50, "{stroke}");
    assert_eq!(stroke["points"], stroke["status"]["points"]);
    assert!(stroke["orange"].as_u64().unwrap() > 20, "{stroke}");
    assert!(
        stroke["hud"].as_str().unwrap().contains("points"),
        "{stroke}"
    );
    assert!(step("hair")["strands"].as_u64().unwrap() > 0, "{v:#}");
    let glb = exports.join("page-points.glb");
    let usda = exports.join("page-strands.usda");
    assert_eq!(
        step("export")["paths"],
        json!([glb.display().to_string(), usda.display().to_string()])
    );
    test_support::gltf::validate(&glb);
    let text = std::fs::read_to_string(&usda).unwrap();
    assert!(text.contains("BasisCurves"), "{text}");
    assert!(
        text.contains("widths"),
        "strands a renderer can draw: {text}"
    );
    let mismatch = step("mismatch");
    assert!(
        mismatch["states"].to_string().contains("reload the page"),
        "{mismatch}"
    );
    assert_eq!(
        mismatch["texts"],
        json!([]),
        "nothing read after a hello of another protocol"
    );
    let shot = step("screenshot");
    assert_eq!(shot["name"], "trilux-paint.png", "{shot}");
    assert_eq!(shot["png"], true, "{shot}");
    assert!(shot["bytes"].as_u64().unwrap() > 2000, "{shot}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_page_paints_picks_adds_detail_undoes_saves_and_exports_in_chromium() {
    let Some((browser, script)) = setup("paint.mjs") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let (shots, exports) = (shots(tmp.path()), tmp.path());
    let v = run(&script, &browser, &shots, exports, document(None), "all").await;
    let step = |s: &str| &v["steps"][s];
    eprintln!(
        "browser: paint: first frame {} ms after load; steps (ms) {}",
        v["first_frame_ms"], v["ms"]
    );
    assert_eq!(v["console_errors"], json!([]), "{v:#}");
    assert_eq!(v["errors"], json!([]), "{v:#}");

    // The hovering brush's ring lies on the surface: centred on the
    // cursor, and no wider than the radius in pixels (narrower across a
    // face seen at an angle, never below a quarter of it on this view).
    let ring = step("ring");
    assert_eq!(ring["shown"], true, "{ring}");
    assert_eq!(ring["points"], 65, "{ring}");
    let radius = ring["radius"].as_f64().unwrap();
    let centroid = ring["centroid"].as_array().unwrap();
    let off = (centroid[0].as_f64().unwrap() - 400.0).hypot(centroid[1].as_f64().unwrap() - 300.0);
    assert!(off < 0.2 * radius, "{ring}");
    let (lo, hi) = (
        ring["min_radius"].as_f64().unwrap(),
        ring["max_radius"].as_f64().unwrap(),
    );
    assert!(
        hi > 0.8 * radius && hi < 1.2 * radius && lo > 0.25 * radius,
        "{ring}"
    );

    // The stroke changed pixels, all within the brush's reach of its path
    // (y = 300, x from 330 to 470, radius in pixels), and nowhere else.
    let stroke = step("stroke");
    assert!(stroke["changed"].as_u64().unwrap() > 200, "{stroke}");
    let r = stroke["radius"].as_i64().unwrap() + 2;
    let b: Vec<i64> = stroke["box"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_i64().unwrap())
        .collect();
    assert!(
        b[0] >= 330 - r && b[2] <= 470 + r && b[1] >= 300 - r && b[3] <= 300 + r,
        "{stroke}"
    );
    assert_eq!(stroke["status"]["history"], json!(["paint"]));

    // The eyedropper on the stroke reads the brush colour back.
    assert_eq!(step("pick")["hex"], "#c0392b", "{}", step("pick"));

    // The detail brush raised the sample count; the colours were
    // resampled, so the picture barely moves.
    let detail = step("detail");
    assert!(
        detail["status"]["samples"].as_u64() > step("load")["status"]["samples"].as_u64(),
        "{detail}"
    );
    assert!(detail["changed"].as_u64().unwrap() < 2000, "{detail}");
    // And the page said so (the HUD's notice: samples before → after).
    let notice = detail["notice"].as_str().unwrap_or_default();
    assert!(
        notice.starts_with("samples ") && notice.contains(" → ") && notice.contains("(+"),
        "{detail}"
    );

    // Undo twice: the first picture again; redo: the stroke again.
    assert_eq!(step("undo")["changed"], 0, "{}", step("undo"));
    assert_eq!(step("undo")["hash"], step("load")["hash"]);
    assert_eq!(step("redo")["changed"], 0, "{}", step("redo"));

    // Save and export through the buttons.
    let saved = exports.join("page.meshcolors");
    let glb = exports.join("page.glb");
    assert_eq!(
        step("export")["paths"],
        json!([saved.display().to_string(), glb.display().to_string()])
    );
    test_support::gltf::validate(&glb);
    let help = v["help"].as_str().unwrap();
    assert!(help.contains("no seam"), "{help}");

    // The saved colours, loaded into a new server: the redone picture.
    let (colors, _) = trilux::mesh_colors::file::load(&saved).unwrap();
    let again = run(
        &script,
        &browser,
        &shots,
        exports,
        document(Some(colors)),
        "load-only",
    )
    .await;
    assert_eq!(again["steps"]["load"]["hash"], step("redo")["hash"]);
}
