//! `trilux view`'s page in a real browser: headless Chromium (software
//! WebGL through SwiftShader) driven by `tests/browser/e2e.mjs` with
//! playwright-core — load, first frame with radiance, orbit, stroke cut,
//! paint, relight, undo, redo, an environment map, a GLB export,
//! screenshots — asserting on pixels, mesh counts, the written file and
//! the server's numbers.
//!
//! Needs `node`, Chromium (`TRILUX_BROWSER` names it; default
//! `/usr/bin/chromium`) and playwright-core installed under
//! `target/browser-e2e` (`.ci/run` installs all three). Without them the
//! test prints a notice and passes, unless `CI` is set.
#![cfg(feature = "view")]

use std::path::PathBuf;
use std::process::Command;

use serde_json::{Value, json};
use tet_diffusion::Light;
use tet_diffusion::glam::DVec3;

fn missing(what: &str) {
    assert!(
        std::env::var_os("CI").is_none(),
        "CI must run the browser test, but {what}"
    );
    eprintln!("notice: the browser test of trilux view is skipped: {what}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_page_cuts_paints_relights_undoes_and_redoes_in_chromium() {
    let browser = std::env::var("TRILUX_BROWSER").unwrap_or_else(|_| "/usr/bin/chromium".into());
    if !std::path::Path::new(&browser).exists() {
        return missing(&format!("no browser at {browser} (set TRILUX_BROWSER)"));
    }
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let modules = root.join("target/browser-e2e/node_modules/playwright-core");
    if !modules.exists() {
        return missing("playwright-core is not installed in target/browser-e2e (see .ci/run)");
    }
    if Command::new("node").arg("--version").output().is_err() {
        return missing("no node");
    }
    let script_dir = root.join("target/browser-e2e");
    crate::common::browser_script("e2e.mjs");
    let shots = tempfile::tempdir().unwrap();
    let dir = std::env::var("TRILUX_SCREENSHOTS")
        .map(PathBuf::from)
        .unwrap_or_else(|_| shots.path().to_path_buf());
    let mut object = trilux::view::builtin::object(10).unwrap();
    light(&mut object);
    let page = Page {
        script: script_dir.join("e2e.mjs"),
        browser,
        dir,
        exports: shots.path().to_path_buf(),
    };
    let v = page.run(object, false).await;
    // The figure: page load → first frame with radiance for
    // bunny_50k, recorded with the machine's load (when the data is here).
    if let Some(bunny) = bunny_50k() {
        let b = page.run(bunny, true).await;
        eprintln!(
            "browser: bunny_50k: first frame with radiance {} ms after load (load {})",
            b["first_frame_ms"],
            machine_load()
        );
    }
    let step = |s: &str| &v["steps"][s];
    // First frame: a surface of the ball, lit, with radiance.
    let load = step("load");
    assert_eq!(load["pieces"], 1);
    assert!(load["triangles"].as_u64().unwrap() > 500);
    assert!(load["lit"].as_f64().unwrap() > 0.05, "{load}");
    eprintln!(
        "browser: built-in ball: first frame with radiance {} ms after load (load {})",
        v["first_frame_ms"],
        machine_load()
    );
    // Orbit is local: no new radiance frames, but different pixels.
    let orbit = step("orbit");
    assert_eq!(orbit["radiance"], load["radiance"]);
    assert_ne!(orbit["mean"], orbit["before"]["mean"]);
    // The cut removed tets and sent a new surface.
    let cut = step("cut");
    assert!(cut["tets"][0].as_u64().unwrap() < 6000);
    assert!(cut["surfaces"].as_u64().unwrap() > load["surfaces"].as_u64().unwrap());
    assert_eq!(cut["history"]["done"], json!(["cut"]));
    // Paint and relight are in the history, one step each: a stroke or a
    // drag arrives as several edits of one gesture, undone as one.
    let done = |st: &str| -> Vec<String> {
        step(st)["history"]["done"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_str().unwrap().to_string())
            .collect()
    };
    // Keys pressed after picking the material switch modes, not the material.
    assert_eq!(step("paint")["material_after_keys"], "ketchup");
    assert_eq!(done("paint"), ["cut", "paint"]);
    assert_eq!(done("light"), ["cut", "paint", "lights"]);
    assert_ne!(step("light")["mean"], step("paint")["mean"]);
    // Undo twice (the drag, then the stroke), redo once (the stroke).
    assert_eq!(done("undo"), ["cut"]);
    assert_eq!(step("undo")["history"]["redo"], json!(["paint", "lights"]));
    assert_eq!(done("redo"), ["cut", "paint"]);
    assert_ne!(step("undo")["mean"], step("light")["mean"]);
    // Light mode shows where the light is; undoing the drag puts the
    // page's light (its specular term and that sun) back with the server's.
    assert_eq!(step("light")["sun"], true);
    assert_eq!(step("load")["sun"], false);
    assert_ne!(step("light")["light_dir"], load["light_dir"]);
    assert_eq!(step("undo")["light_dir"], load["light_dir"]);
    assert_eq!(
        v["modifier_keys"],
        json!({"mode": "light", "specular": true})
    );
    assert_eq!(v["help_visible"], true);
    // No console error (the favicon request was a 404 on every load).
    assert_eq!(v["console_errors"], json!([]), "{v:#}");
    // The HUD names the result in words, not the protocol's op names, and
    // the exposure slider shows its value.
    let hud = load["hud"].as_str().unwrap();
    assert!(
        ["loaded", "refined"].iter().any(|w| hud.starts_with(w)),
        "{hud}"
    );
    assert!(!hud.contains("hello") && !hud.contains("refine:"), "{hud}");
    assert_eq!(load["ev"], "+0.0 EV");
    // Exposure from the covered pixels (as the CLI's PNGs), not the
    // surface vertices: measured, with part of the drawing covered.
    assert_eq!(load["white_from"], "pixels", "{load}");
    assert!(load["covered"].as_u64().unwrap() > 100, "{load}");
    assert!(load["white"].as_f64().unwrap() > 0.0);
    // The environment map loaded from the page lights the object: in the
    // lights and the history, and the picture changed.
    let env = step("env");
    assert!(
        env["environment"]
            .as_str()
            .is_some_and(|f| f.starts_with("env-") && f.ends_with(".hdr")),
        "{env}"
    );
    assert_eq!(done("env").last().map(String::as_str), Some("lights"));
    assert_ne!(env["mean"], step("redo")["mean"]);
    // The panel's GLB button: the server wrote the surface (its name made
    // a file name), a valid glTF file with one object per piece.
    let export = step("export");
    let written = page.exports.join("page_surface.glb");
    assert_eq!(
        export["paths"],
        json!([written.display().to_string()]),
        "{export}"
    );
    assert!(
        export["hud"]
            .as_str()
            .is_some_and(|h| h.starts_with("written ")),
        "{export}"
    );
    test_support::gltf::validate(&written);
    let scene = trilux_io::mesh::gltf::read_scene(&written).unwrap();
    assert_eq!(scene.mesh.objects.len(), 1);
    assert!(scene.vertex_data.colors.is_some());
    let help = v["help_text"].as_str().unwrap();
    assert!(help.contains("GLB"), "{help}");
    for s in [
        "load", "cut", "paint", "light", "undo", "redo", "env", "export",
    ] {
        assert_eq!(step(s)["errors"], 0, "{s}: {v:#}");
    }
}

/// The machine's load averages (as `uptime` prints them).
fn machine_load() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .unwrap_or_default()
        .trim()
        .to_string()
}

fn light(object: &mut tet_diffusion::Object) {
    object
        .add_light(Light::Directional {
            to_light: DVec3::new(0.4, 1.0, 0.7),
            irradiance: [1.0; 3],
        })
        .unwrap();
}

/// `tets/bunny_50k.node` of `TRILUX_DATA` in marble, as `trilux view`
/// loads it (a mesh in metres), if the data is here.
fn bunny_50k() -> Option<tet_diffusion::Object> {
    let data = std::env::var_os("TRILUX_DATA")?;
    let path = PathBuf::from(data).join("tets/bunny_50k.node");
    let t = trilux_io::tet::TetMesh::read(&path).ok()?;
    let mesh = tet_diffusion::TetMesh::new(&t.positions, &t.tets).ok()?;
    let marble = tet_diffusion::Medium::measured("marble").ok()?;
    let mut o = tet_diffusion::Object::homogeneous(mesh, 1000.0, marble, 1.3).ok()?;
    light(&mut o);
    Some(o)
}

/// The page driven by the e2e script.
struct Page {
    script: PathBuf,
    browser: String,
    dir: PathBuf,
    exports: PathBuf,
}

impl Page {
    /// Serves `object`, runs the script on it (only up to the first frame
    /// with `first_frame`) and returns what it printed.
    async fn run(&self, object: tet_diffusion::Object, first_frame: bool) -> Value {
        let running = trilux::view::start(
            object,
            json!({"mesh": null}),
            None,
            trilux::view::Options {
                export_dir: self.exports.clone(),
                ..Default::default()
            },
            Box::new(NoExport),
        )
        .await
        .unwrap();
        let mut command = Command::new("node");
        command
            .arg(&self.script)
            .arg(running.url())
            .arg(&self.dir)
            .env("TRILUX_BROWSER", &self.browser);
        if first_frame {
            command.arg("first-frame");
        }
        let out = tokio::task::spawn_blocking(move || command.output().unwrap())
            .await
            .unwrap();
        running.stop().await.unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        let v: Value = serde_json::from_str(text.trim())
            .unwrap_or_else(|e| panic!("{e}: {text}\n{}", String::from_utf8_lossy(&out.stderr)));
        assert!(v.get("error").is_none(), "{v:#}");
        v
    }
}

struct NoExport;

impl trilux::view::Exporter for NoExport {
    fn export(
        &self,
        _: &tet_diffusion::Session,
        _: trilux::view::protocol::ExportKind,
        _: &std::path::Path,
        _: u32,
        _: Option<DVec3>,
        _: bool,
    ) -> Result<(), String> {
        Err("not in this test".into())
    }
}
