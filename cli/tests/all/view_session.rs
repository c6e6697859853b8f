//! A session of `trilux view` saved from its page and replayed: by
//! `trilux view --replay` and by `trilux diffuse --session`, whose
//! picture, VTU and glTF surface are byte for byte the page's exports of
//! the live session (every file written listed in the summary and the
//! JSON); and a bad session file is an error naming the file and the
//! entry.
#![cfg(feature = "view")]

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use futures_util::StreamExt;
use serde_json::{Value, json};
use tokio_tungstenite::tungstenite::Message;

use crate::common::web::{Socket, connect, send};

fn trilux() -> Command {
    Command::new(env!("CARGO_BIN_EXE_trilux"))
}

/// The view server on `args`, exporting into `dir`; its address and token
/// from the JSON line it prints.
fn view(dir: &Path, args: &[&str]) -> (Child, String, String) {
    let mut child = trilux()
        .args(["--json", "view", "--export-dir"])
        .arg(dir)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let v: Value = serde_json::from_str(&line).unwrap_or_else(|e| panic!("{e}: {line:?}"));
    let url = v["url"]
        .as_str()
        .unwrap_or_else(|| panic!("no url in {line:?}"));
    let rest = url.strip_prefix("http://").unwrap();
    let (addr, token) = rest.split_once('/').unwrap();
    (
        child,
        addr.to_string(),
        token.trim_end_matches('/').to_string(),
    )
}

/// The next JSON message for which `pick` holds (binary frames and other
/// messages are skipped); an error message fails the test.
async fn until(s: &mut Socket, pick: impl Fn(&Value) -> bool) -> Value {
    loop {
        let m = tokio::time::timeout(Duration::from_secs(300), s.next())
            .await
            .expect("the server answers")
            .expect("the connection stays open")
            .expect("no protocol error");
        if let Message::Text(t) = m {
            let v: Value = serde_json::from_str(&t).unwrap();
            assert_ne!(v["type"], "error", "{v}");
            if pick(&v) {
                return v;
            }
        }
    }
}

fn status_of(seq: u64) -> impl Fn(&Value) -> bool {
    move |v| {
        v["type"] == "status"
            && v["seqs"]
                .as_array()
                .is_some_and(|s| s.contains(&json!(seq)))
    }
}

/// Exports the picture, VTU, GLB (and the session file, when `session`) of
/// the server's session once it is refined.
async fn export(s: &mut Socket, prefix: &str, session: bool) {
    let mut seq = 100;
    let mut kinds = vec![("png", "png"), ("vtu", "vtu"), ("glb", "glb")];
    if session {
        kinds.push(("session", "json"));
    }
    for (kind, ext) in kinds {
        seq += 1;
        send(
            s,
            json!({"seq": seq, "op": "export", "kind": kind, "name": format!("{prefix}.{ext}"),
                   "size": 96, "view": [0.5, 1.0, 2.0]}),
        )
        .await;
        until(s, |v| v["type"] == "export").await;
    }
}

#[test]
fn a_view_session_replays_in_diffuse_as_the_page_exports_it_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let runtime = tokio::runtime::Runtime::new().unwrap();
    let (mut live, addr, token) = view(d, &[]);
    runtime.block_on(async {
        let mut s = connect(&addr, &token).await;
        until(&mut s, |v| v["type"] == "hello").await;
        let r = 20.0; // the built-in ball's radius
        let edits = [
            json!({"seq": 1, "op": "paint", "material": "ketchup", "radius": 0.2 * r, "strength": 1.0,
                   "points": [[0.0, 0.0, r], [0.1 * r, 0.0, r]]}),
            json!({"seq": 2, "op": "lights", "lights": [{"kind": "dir", "dir": [-0.5, 1, 0.2]}]}),
            json!({"seq": 3, "op": "cut", "plane": {"point": [0, 0, 0.3 * r], "normal": [0.2, 0, 1]}}),
            json!({"seq": 4, "op": "paint", "material": "skin1", "radius": 0.15 * r, "strength": 0.7,
                   "points": [[0.0, 0.2 * r, 0.3 * r]]}),
        ];
        for (k, e) in edits.iter().enumerate() {
            send(&mut s, e.clone()).await;
            until(&mut s, status_of(k as u64 + 1)).await;
        }
        until(&mut s, |v| v["type"] == "status" && v["edit"] == "refine").await;
        export(&mut s, "live", true).await;
    });
    live.kill().unwrap();
    live.wait().unwrap();
    let session = d.join("live.json");
    let text = std::fs::read_to_string(&session).unwrap();
    assert!(text.contains("\"op\": \"cut\""), "{text}");

    // `trilux diffuse --session`: the same bytes as the page's exports.
    let out = trilux()
        .current_dir(d)
        .args(["diffuse", "--session", "live.json", "--view", "0.5,1,2"])
        .args(["--size", "96", "-o", "diffuse.png", "--vtu", "diffuse.vtu"])
        .args(["--glb", "diffuse.glb"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("replayed (4 edits)"), "{stdout}");
    assert!(
        stdout.ends_with("; written to diffuse.png, diffuse.vtu, diffuse.glb\n"),
        "{stdout}"
    );
    let read = |name: &str| std::fs::read(d.join(name)).unwrap();
    assert!(read("diffuse.png") == read("live.png"), "the PNGs differ");
    assert!(read("diffuse.vtu") == read("live.vtu"), "the VTUs differ");
    // The glTF surface too: the same surface, radiance and exposure.
    test_support::gltf::validate(&d.join("live.glb"));
    assert!(read("diffuse.glb") == read("live.glb"), "the GLBs differ");
    // The file keeps the page's camera; without --view, diffuse renders
    // from there.
    let saved: Value = serde_json::from_str(&text).unwrap();
    let camera = saved["source"]["view"].as_array().unwrap();
    let x = camera
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect::<Vec<_>>();
    assert!(
        (x[0] / x[2] - 0.25).abs() < 1e-12 && (x[1] / x[2] - 0.5).abs() < 1e-12,
        "{x:?}"
    );
    let out = trilux()
        .current_dir(d)
        .args([
            "diffuse",
            "--session",
            "live.json",
            "--size",
            "96",
            "-o",
            "saved_view.png",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    assert!(
        read("saved_view.png") == read("live.png"),
        "not the saved camera"
    );

    // `trilux view --replay`: the page's exports of the replayed session
    // are the same bytes again.
    let (mut replay, addr, token) = view(d, &["--replay", session.to_str().unwrap()]);
    runtime.block_on(async {
        let mut s = connect(&addr, &token).await;
        until(&mut s, |v| v["type"] == "hello").await;
        until(&mut s, |v| v["type"] == "status").await;
        export(&mut s, "replay", false).await;
    });
    replay.kill().unwrap();
    replay.wait().unwrap();
    assert!(read("replay.png") == read("live.png"), "the PNGs differ");
    assert!(read("replay.vtu") == read("live.vtu"), "the VTUs differ");
    assert!(read("replay.glb") == read("live.glb"), "the GLBs differ");
}

#[test]
fn diffuse_session_lists_every_file_it_writes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // The built-in ball, no edits.
    let session = json!({"format": "trilux-session", "version": 1, "refined_initially": false,
        "source": {"mesh": null, "material": null, "unit_mm": null}, "edits": []});
    std::fs::write(d.join("s.json"), session.to_string()).unwrap();
    let out = trilux()
        .current_dir(d)
        .args(["--json", "diffuse", "--session", "s.json", "--size", "32"])
        .args([
            "-o", "s.png", "--exr", "s.exr", "--vtu", "s.vtu", "--glb", "s.gltf",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    let written = ["s.png", "s.exr", "s.vtu", "s.bin", "s.gltf"];
    assert_eq!(report["files"], json!(written), "{report}");
    assert_eq!(report["output"], "s.png");
    for f in written {
        assert!(d.join(f).is_file(), "{f}");
    }
    test_support::gltf::validate(&d.join("s.gltf"));
    let out = trilux()
        .current_dir(d)
        .args(["diffuse", "--session", "s.json", "--size", "32"])
        .args(["-o", "t.png", "--glb", "t.glb"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.ends_with("replayed (0 edits); written to t.png, t.glb\n"),
        "{stdout}"
    );
}

#[test]
fn a_bad_session_file_is_an_error_naming_the_file_and_the_entry() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let source = json!({"mesh": null, "material": null, "unit_mm": null});
    let dab = |radius: Value| {
        json!({"op": "paint", "refined": true, "dabs": [{"points": [[0, 0, 1]], "radius": radius,
              "strength": 1, "medium": {"sigma_a": [0.1, 0.1, 0.1], "sigma_s_prime": [1, 1, 1]}}]})
    };
    let file = |edits: Vec<Value>| {
        json!({"format": "trilux-session", "version": 1, "source": source,
               "refined_initially": true, "edits": edits})
        .to_string()
    };
    let cases = [
        (
            file(vec![dab(json!(0.2)), dab(json!("wide"))]),
            "edits[1].dabs[0].radius: expected a number",
        ),
        (
            file(vec![json!({"op": "cut", "refined": true,
                "plane": {"point": [0, 0, -1000], "normal": [0, 0, 1]}})]),
            "edits[0] (cut)",
        ),
        (file(vec![dab(json!(-1.0))]), "edits[0] (paint)"),
        ("{\"format\": \"png\"}".to_string(), "format: expected"),
        (
            json!({"format": "trilux-session", "version": 1, "refined_initially": true,
                   "source": {"mesh": null, "view": [0, 0, 0]}, "edits": []})
            .to_string(),
            "source.view: expected three finite numbers",
        ),
        (
            json!({"format": "trilux-session", "version": 1, "refined_initially": true,
                   "source": {"mesh": null, "view": [1e300, 0, 0]}, "edits": []})
            .to_string(),
            "within f32's range",
        ),
        (
            json!({"format": "trilux-session", "version": 1, "refined_initially": true,
                   "source": {"mesh": null, "envelope": 2.0}, "edits": []})
            .to_string(),
            "envelope 2: a fraction of the bounding box's diagonal",
        ),
    ];
    for (k, (text, needle)) in cases.iter().enumerate() {
        let name = format!("bad{k}.json");
        std::fs::write(d.join(&name), text).unwrap();
        let out = trilux()
            .current_dir(d)
            .args(["diffuse", "--session", &name, "-o", "x.png", "--size", "32"])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{name}");
        assert!(stderr.contains(&name), "{name}: {stderr}");
        assert!(stderr.contains(needle), "{name}: {stderr}");
        assert!(!d.join("x.png").exists());
    }
    // --session takes the object from the file: no MESH beside it.
    let out = trilux()
        .current_dir(d)
        .args(["diffuse", "m.node", "--session", "bad0.json", "-o", "x.png"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}

// A port already taken (most often by a trilux view still running) is an
// error that names the address and says what to do, not the bare OS text.
#[test]
fn a_port_in_use_is_an_error_that_says_what_to_do() {
    let dir = tempfile::tempdir().unwrap();
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let out = trilux()
        .args(["view", "--export-dir"])
        .arg(dir.path())
        .args(["--port", &port])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains(&format!("error: 127.0.0.1:{port}: port {port} is in use")),
        "{stderr}"
    );
    assert!(stderr.contains("leave --port out"), "{stderr}");
}
