//! `trilux view`'s server driven through its protocol by a WebSocket
//! client: every edit, undo/redo, probes, exports (atomic, no silent
//! overwrite), bad messages (random JSON, huge arrays, non-finite numbers,
//! unknown ops), the token, Host and Origin checks, rate limits, and
//! dropped connections that keep the session.
#![cfg(feature = "view")]

use std::time::Duration;

use futures_util::{SinkExt, StreamExt};
use serde_json::{Value, json};
use tet_diffusion::glam::DVec3;
use tet_diffusion::{Light, Session};
use tokio_tungstenite::tungstenite::{self, Message};
use trilux::view::protocol::{self, ExportKind};
use trilux::view::session_file;
use trilux::view::{Exporter, Options, Running, builtin};

use crate::common::web::{self, Socket, send, send_raw};

/// Writes a small text file for pictures (the real renderer is the
/// binary's), atomically, refusing to overwrite.
struct Plain;

impl Exporter for Plain {
    fn export(
        &self,
        session: &Session,
        kind: ExportKind,
        path: &std::path::Path,
        size: u32,
        _view: Option<DVec3>,
        overwrite: bool,
    ) -> Result<(), String> {
        trilux::output::write_atomic(path, overwrite, |tmp| {
            std::fs::write(tmp, format!("{kind:?} {size} {}", session.pieces().len())).map_err(
                |source| trilux::Error::File {
                    path: tmp.to_path_buf(),
                    source,
                },
            )
        })
        .map_err(|e| e.to_string())
    }
}

async fn server(dir: &std::path::Path) -> Running {
    server_on(dir, Options::default().host).await
}

async fn server_on(dir: &std::path::Path, host: std::net::IpAddr) -> Running {
    let mut object = builtin::object(6).unwrap();
    object
        .add_light(Light::Directional {
            to_light: DVec3::new(0.3, 1.0, 0.5),
            irradiance: [1.0; 3],
        })
        .unwrap();
    let options = Options {
        host,
        export_dir: dir.to_path_buf(),
        ..Options::default()
    };
    trilux::view::start(
        object,
        json!({"mesh": null, "material": null, "unit_mm": null}),
        None,
        options,
        Box::new(Plain),
    )
    .await
    .unwrap()
}

async fn connect_with(
    r: &Running,
    token: &str,
    origin: Option<&str>,
) -> Result<Socket, tungstenite::Error> {
    web::connect_with(&r.addr.to_string(), token, origin).await
}

async fn connect(r: &Running) -> Socket {
    web::connect(&r.addr.to_string(), &r.token).await
}

/// Reads messages until a JSON one of type `kind` (others are kept in
/// `seen`); binary frames are counted.
async fn until(s: &mut Socket, kind: &str, seen: &mut Seen) -> Value {
    loop {
        let m = tokio::time::timeout(Duration::from_secs(120), s.next())
            .await
            .expect("the server answers within 2 minutes")
            .expect("the connection stays open")
            .expect("no protocol error");
        match m {
            Message::Text(t) => {
                let v: Value = serde_json::from_str(&t).unwrap();
                let ty = v["type"].as_str().unwrap_or_default().to_string();
                seen.texts.push(v.clone());
                if ty == kind {
                    return v;
                }
            }
            Message::Binary(b) => {
                assert_eq!(&b[..4], protocol::MAGIC);
                assert_eq!(b[4], protocol::VERSION);
                let a = u32::from_le_bytes(b[8..12].try_into().unwrap()) as usize;
                match b[5] {
                    protocol::SURFACE => {
                        let t = u32::from_le_bytes(b[12..16].try_into().unwrap()) as usize;
                        assert_eq!(b.len(), 16 + a * 24 + t * 12);
                        seen.surfaces += 1;
                        seen.frames.push(Frame::Surface);
                    }
                    protocol::RADIANCE => {
                        assert_eq!(b.len(), 16 + a * 12);
                        let finite = b[16..]
                            .chunks(4)
                            .all(|c| f32::from_le_bytes(c.try_into().unwrap()).is_finite());
                        assert!(finite);
                        seen.radiance += 1;
                        let tag = u32::from_le_bytes(b[12..16].try_into().unwrap());
                        seen.frames.push(Frame::Radiance(tag as u64));
                        if b[6] & protocol::FINAL != 0 {
                            seen.finals += 1;
                        }
                    }
                    k => panic!("unknown frame kind {k}"),
                }
            }
            _ => {}
        }
    }
}

#[derive(Default)]
struct Seen {
    texts: Vec<Value>,
    surfaces: usize,
    radiance: usize,
    finals: usize,
    /// The binary frames in arrival order.
    frames: Vec<Frame>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Frame {
    Surface,
    /// Radiance, with the edit's sequence number it answers (0: a
    /// refinement or a reconnection).
    Radiance(u64),
}

async fn get(r: &Running, path: &str, host: &str, origin: Option<&str>) -> (u16, String) {
    web::get(r.addr, path, host, origin).await
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn http_needs_the_token_and_this_servers_host_and_origin() {
    let dir = tempfile::tempdir().unwrap();
    let r = server(dir.path()).await;
    let host = r.addr.to_string();
    let t = r.token.clone();
    let (code, body) = get(&r, &format!("/{t}/"), &host, None).await;
    assert_eq!(code, 200);
    assert!(body.contains("trilux view"));
    for f in ["app.js", "gl.js", "camera.js", "net.js", "style.css"] {
        assert_eq!(
            get(&r, &format!("/{t}/{f}"), &host, None).await.0,
            200,
            "{f}"
        );
    }
    // No token, a wrong one: 404 (the token stays secret), with a body
    // that says what to do instead of a bare "not found".
    let wrong = "0".repeat(t.len());
    for path in [
        "/".to_string(),
        "/app.js".into(),
        "/favicon.ico".into(),
        format!("/{wrong}/"),
        format!("/{wrong}/app.js"),
        format!("/{wrong}"),
    ] {
        let (code, body) = get(&r, &path, &host, None).await;
        assert_eq!(code, 404, "{path}");
        assert!(
            body.contains("needs the full URL trilux printed when it started"),
            "{path}: {body}"
        );
        assert!(!body.contains(&t), "{path}: the body reveals the token");
    }
    // A path outside the binary's files.
    assert_eq!(
        get(&r, &format!("/{t}/../Cargo.toml"), &host, None).await.0,
        404
    );
    assert_eq!(
        get(&r, &format!("/{t}/%2e%2e%2fCargo.toml"), &host, None)
            .await
            .0,
        404
    );
    // DNS rebinding: a foreign Host; a foreign Origin.
    assert_eq!(
        get(&r, &format!("/{t}/"), "evil.example:80", None).await.0,
        403
    );
    let (code, _) = get(&r, &format!("/{t}/"), &host, Some("http://evil.example")).await;
    assert_eq!(code, 403);
    let port = r.addr.port();
    assert_eq!(
        get(&r, &format!("/{t}/"), &format!("localhost:{port}"), None)
            .await
            .0,
        200
    );
    r.stop().await.unwrap();
}

// `--host 0.0.0.0` is for opening the page from another machine, by one
// of this machine's addresses (which the server does not know): every
// IP-literal Host with the server's port passes, a host name does not.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn on_every_interface_any_address_of_this_machine_may_open_the_page() {
    let dir = tempfile::tempdir().unwrap();
    let r = server_on(dir.path(), std::net::Ipv4Addr::UNSPECIFIED.into()).await;
    let (t, port) = (r.token.clone(), r.addr.port());
    for host in [
        format!("0.0.0.0:{port}"),
        format!("127.0.0.1:{port}"),
        format!("localhost:{port}"),
        format!("192.0.2.7:{port}"),
        format!("[2001:db8::7]:{port}"),
    ] {
        let origin = format!("http://{host}");
        let (code, _) = get(&r, &format!("/{t}/"), &host, Some(&origin)).await;
        assert_eq!(code, 200, "{host}");
    }
    for host in [
        format!("evil.example:{port}"),
        format!("192.0.2.7:{}", port.wrapping_add(1)),
    ] {
        let (code, body) = get(&r, &format!("/{t}/"), &host, None).await;
        assert_eq!(code, 403, "{host}");
        assert!(body.contains("wrong Host header"), "{host}: {body}");
    }
    let (code, _) = get(
        &r,
        &format!("/{t}/"),
        &format!("192.0.2.7:{port}"),
        Some("http://evil.example"),
    )
    .await;
    assert_eq!(code, 403);
    r.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn websockets_need_the_token_and_a_matching_origin() {
    let dir = tempfile::tempdir().unwrap();
    let r = server(dir.path()).await;
    let origin = format!("http://{}", r.addr);
    let wrong = "f".repeat(r.token.len());
    assert!(connect_with(&r, &wrong, Some(&origin)).await.is_err());
    assert!(
        connect_with(&r, &r.token, Some("http://evil.example"))
            .await
            .is_err()
    );
    assert!(connect_with(&r, &r.token, None).await.is_err());
    assert!(connect_with(&r, &r.token, Some(&origin)).await.is_ok());
    r.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_edit_through_the_protocol() {
    let dir = tempfile::tempdir().unwrap();
    let r = server(dir.path()).await;
    let mut s = connect(&r).await;
    let mut seen = Seen::default();
    let hello = until(&mut s, "hello", &mut seen).await;
    assert_eq!(hello["materials"].as_array().unwrap().len(), 12);
    let status = until(&mut s, "status", &mut seen).await;
    assert!(seen.surfaces >= 1 && seen.radiance >= 1);
    let tets0 = status["tets"][0].as_u64().unwrap();
    assert_eq!(tets0, 6 * 6 * 6 * 6);
    let r0 = builtin::RADIUS;
    // Each edit, and the status it gets: (message, edit name, pieces after).
    let edits = [
        (
            json!({"seq": 1, "op": "paint", "material": "ketchup", "radius": 0.2 * r0, "strength": 1.0,
                 "points": [[0.0, 0.0, r0], [0.1 * r0, 0.0, r0]], "gesture": 42}),
            "paint",
            1,
        ),
        (
            json!({"seq": 2, "op": "lights", "lights": [{"kind": "dir", "dir": [-0.5, 1, 0.2]},
                 {"kind": "point", "pos": [0, 3.0 * r0, 0], "rgb": [400, 400, 400]}]}),
            "lights",
            1,
        ),
        (
            json!({"seq": 3, "op": "material", "material": "apple"}),
            "material",
            1,
        ),
        (
            json!({"seq": 4, "op": "cut", "stroke": {"points": [[-2.0 * r0, -2.0 * r0, 0], [2.0 * r0, 1.0 * r0, 0]],
                 "view": [0, 0, -1]}}),
            "cut",
            1,
        ),
        (
            json!({"seq": 5, "op": "cut", "plane": {"point": [0, 0, 0.6 * r0], "normal": [0, 0, 1]}}),
            "cut",
            1,
        ),
        (
            json!({"seq": 6, "op": "fracture", "piece": 0, "point": [0, 0, 0], "normal": [1, 0.1, 0]}),
            "fracture",
            2,
        ),
        (
            json!({"seq": 7, "op": "move", "piece": 1, "offset": [0.5 * r0, 0, 0]}),
            "move",
            2,
        ),
        (
            json!({"seq": 8, "op": "recombine", "a": 0, "b": 1}),
            "recombine",
            1,
        ),
    ];
    for (m, name, pieces) in &edits {
        let surfaces = seen.surfaces;
        let frames = seen.frames.len();
        send(&mut s, m.clone()).await;
        let st = loop {
            let st = until(&mut s, "status", &mut seen).await;
            if st["seqs"].as_array().unwrap().contains(&m["seq"]) {
                break st;
            }
        };
        assert_eq!(st["edit"], *name, "{m}");
        assert_eq!(st["pieces"], *pieces, "{m}");
        assert!(st["wall_ms"].as_f64().unwrap() >= 0.0);
        let solves = st["solves"].as_array().unwrap();
        assert!(!solves.is_empty(), "{m}");
        for sv in solves {
            assert!(sv["levels"].as_u64().unwrap() >= 1);
            let solver = sv["solver"].as_str().unwrap();
            assert!(solver == "Jacobi-PCG" || solver == "V-cycle-PCG", "{m}");
            assert!(
                sv["residual"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .all(|x| x.as_f64().unwrap() <= 1e-2)
            );
        }
        let topology = ["cut", "fracture", "recombine"].contains(name);
        assert_eq!(seen.surfaces > surfaces, topology, "{m}");
        // A new surface goes out before the solve, with the radiance of
        // the φ carried over; the solved radiance follows. Other edits
        // send the solved radiance alone.
        let seq = m["seq"].as_u64().unwrap();
        let ours: Vec<Frame> = seen.frames[frames..]
            .iter()
            .copied()
            .filter(|&f| f == Frame::Surface || f == Frame::Radiance(seq))
            .collect();
        let p = *pieces;
        let mut expected = Vec::new();
        if topology {
            expected.extend(vec![Frame::Surface; p]);
            expected.extend(vec![Frame::Radiance(seq); p]);
        }
        expected.extend(vec![Frame::Radiance(seq); p]);
        assert_eq!(ours, expected, "{m}");
    }
    // The cuts removed tets; recombining gave back the cut object.
    let after_recombine = until(&mut s, "status", &mut seen).await;
    let _ = after_recombine;
    // Undo walks back through recombine, move, fracture, the cuts …
    for (k, expected) in ["recombine", "move", "fracture", "cut"].iter().enumerate() {
        send(&mut s, json!({"seq": 20 + k, "op": "undo"})).await;
        let st = until(&mut s, "status", &mut seen).await;
        assert_eq!(st["edit"], "undo");
        let redo = st["history"]["redo"].as_array().unwrap();
        assert_eq!(redo[0], *expected, "{st}");
    }
    send(&mut s, json!({"seq": 30, "op": "redo"})).await;
    let st = until(&mut s, "status", &mut seen).await;
    assert_eq!(st["edit"], "redo");
    assert_eq!(st["history"]["redo"].as_array().unwrap().len(), 3);
    // Probe: a material by name (apple everywhere after the fill).
    send(
        &mut s,
        json!({"seq": 31, "op": "probe", "piece": 0, "point": [0, r0, 0]}),
    )
    .await;
    let p = until(&mut s, "probe", &mut seen).await;
    assert_eq!(p["material"], "apple");
    // Exports: written, then refused without overwrite, then replaced.
    let name = "shot.png";
    send(
        &mut s,
        json!({"seq": 32, "op": "export", "kind": "png", "name": name, "size": 64}),
    )
    .await;
    until(&mut s, "export", &mut seen).await;
    let path = dir.path().join(name);
    let first = std::fs::read_to_string(&path).unwrap();
    assert!(first.starts_with("Png 64"));
    send(
        &mut s,
        json!({"seq": 33, "op": "export", "kind": "png", "name": name, "size": 128}),
    )
    .await;
    let e = until(&mut s, "error", &mut seen).await;
    assert_eq!(e["exists"], true);
    // The page shows this in its "Replace it?" dialog: no command-line advice.
    let message = e["message"].as_str().unwrap();
    assert!(message.ends_with("shot.png: the file exists"), "{message}");
    assert!(!message.contains("--force"), "{message}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), first);
    send(&mut s, json!({"seq": 34, "op": "export", "kind": "png", "name": name, "size": 128, "overwrite": true})).await;
    until(&mut s, "export", &mut seen).await;
    assert!(
        std::fs::read_to_string(&path)
            .unwrap()
            .starts_with("Png 128")
    );
    // The session file lists the applied edits and reads back.
    send(
        &mut s,
        json!({"seq": 35, "op": "export", "kind": "session", "name": "s.json"}),
    )
    .await;
    until(&mut s, "export", &mut seen).await;
    let text = std::fs::read_to_string(dir.path().join("s.json")).unwrap();
    let (_, log) = trilux::view::session_file::from_json(&text).unwrap();
    let names: Vec<&str> = log.edits.iter().map(|l| l.edit.name()).collect();
    assert_eq!(names, ["paint", "lights", "material", "cut", "cut"]);
    // The stroke's gesture is kept (a replay undoes it as one step).
    let gestures: Vec<Option<u64>> = log.edits.iter().map(|l| l.gesture).collect();
    assert_eq!(gestures, [Some(42), None, None, None, None]);
    // The glTF surface is written by the server itself (not the
    // exporter): broken in two, one object per piece, each piece's surface
    // vertices with the radiance as colours and attributes.
    send(
        &mut s,
        json!({"seq": 36, "op": "fracture", "piece": 0, "point": [0, 0, 0], "normal": [0, 1, 0]}),
    )
    .await;
    let st = loop {
        let st = until(&mut s, "status", &mut seen).await;
        if st["seqs"].as_array().unwrap().contains(&json!(36)) {
            break st;
        }
    };
    assert_eq!(st["pieces"], 2);
    let glb = dir.path().join("surface.glb");
    send(
        &mut s,
        json!({"seq": 37, "op": "export", "kind": "glb", "name": "surface.glb", "size": 64,
               "view": [0, 0, 1]}),
    )
    .await;
    let written = until(&mut s, "export", &mut seen).await;
    assert_eq!(written["seq"], 37);
    test_support::gltf::validate(&glb);
    let scene = trilux_io::mesh::gltf::read_scene(&glb).unwrap();
    let names: Vec<&str> = scene.mesh.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["piece 0", "piece 1"]);
    let vertices: u64 = st["surface_vertices"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(scene.mesh.positions.len() as u64, vertices);
    let colours = scene.vertex_data.colors.as_ref().unwrap();
    assert!(colours.iter().flatten().all(|c| (0.0..=1.0).contains(c)));
    // The exposure puts the brightest percent of the picture at white.
    assert!(colours.iter().any(|c| c[..3].contains(&1.0)));
    for (name, components) in [("RADIANCE", 3), ("PHI", 3)] {
        let a = scene.vertex_data.attribute(name).unwrap();
        assert_eq!((a.len(), a.components()), (vertices as usize, components));
    }
    // Not over an existing file unless the page asks.
    let before = std::fs::read(&glb).unwrap();
    send(
        &mut s,
        json!({"seq": 38, "op": "export", "kind": "glb", "name": "surface.glb", "size": 32}),
    )
    .await;
    let e = until(&mut s, "error", &mut seen).await;
    assert_eq!(
        (e["seq"].clone(), e["exists"].clone()),
        (json!(38), json!(true))
    );
    assert_eq!(std::fs::read(&glb).unwrap(), before);
    // No temporary files left behind.
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("partial"))
        .collect();
    assert!(left.is_empty());
    assert!(seen.finals >= 1, "refined results arrive when idle");
    r.stop().await.unwrap();
}

/// A small deterministic generator of random JSON values.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn value(&mut self, depth: u32) -> Value {
        let ops = [
            "paint",
            "lights",
            "cut",
            "fracture",
            "move",
            "recombine",
            "probe",
            "export",
            "undo",
            "x",
        ];
        match self.next() % if depth > 2 { 5 } else { 8 } {
            0 => Value::Null,
            1 => json!(self.next().is_multiple_of(2)),
            2 => json!((self.next() % 2001) as f64 / 10.0 - 100.0),
            3 => json!(ops[(self.next() % ops.len() as u64) as usize]),
            4 => json!(self.next() % 300),
            5 | 6 => {
                let n = self.next() % 5;
                Value::Array((0..n).map(|_| self.value(depth + 1)).collect())
            }
            _ => {
                let keys = [
                    "seq", "op", "points", "radius", "strength", "material", "lights", "plane",
                    "stroke", "piece", "point", "normal", "offset", "a", "b", "kind", "name",
                    "size", "view",
                ];
                let n = self.next() % 7;
                Value::Object(
                    (0..n)
                        .map(|_| {
                            let k = keys[(self.next() % keys.len() as u64) as usize].to_string();
                            (k, self.value(depth + 1))
                        })
                        .collect(),
                )
            }
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_messages_get_an_error_naming_the_field_and_keep_the_session() {
    let dir = tempfile::tempdir().unwrap();
    let r = server(dir.path()).await;
    let mut s = connect(&r).await;
    let mut seen = Seen::default();
    until(&mut s, "status", &mut seen).await;
    let named = [
        (json!({"seq": 1, "op": "paint", "material": "ketchup", "radius": 1, "strength": 2, "points": [[0, 0, 0]]}).to_string(), "strength"),
        (json!({"seq": 2, "op": "teleport"}).to_string(), "op"),
        (r#"{"seq": 3, "op": "move", "piece": 0, "offset": [NaN, 0, 0]}"#.to_string(), "(message)"),
        (json!({"seq": 4, "op": "move", "piece": 9, "offset": [0, 0, 0]}).to_string(), "the piece to move"),
        (json!({"seq": 5, "op": "lights", "lights": vec![json!({"kind": "dir", "dir": [0, 1, 0]}); 40]}).to_string(), "lights"),
        (json!({"seq": 6, "op": "cut", "stroke": {"points": vec![[0, 0, 0]; 4200], "view": [0, 0, 1]}}).to_string(), "stroke.points"),
        (json!({"seq": 7, "op": "export", "kind": "png", "name": "/etc/passwd.png"}).to_string(), "name"),
        (json!({"seq": 8, "op": "cut", "plane": {"point": [1e3, 1e3, 1e3], "normal": [-1, 0, 0]}}).to_string(), "op"),
    ];
    for (m, field) in &named {
        send_raw(&mut s, m.clone()).await.unwrap();
        let e = until(&mut s, "error", &mut seen).await;
        assert_eq!(e["field"], *field, "{m}: {e}");
    }
    // Random JSON: each message answered by an error or a status, none
    // crashes the server (property-tested over 300 seeded values).
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for k in 0..300u64 {
        let mut v = rng.value(0);
        if k.is_multiple_of(3) && v.is_object() {
            v["seq"] = json!(1000 + k);
        }
        send_raw(&mut s, v.to_string()).await.unwrap();
    }
    send(
        &mut s,
        json!({"seq": 5000, "op": "probe", "piece": 0, "point": [0, 0, 0]}),
    )
    .await;
    until(&mut s, "probe", &mut seen).await;
    // A text message over the size limit gets an error; the connection
    // stays.
    let huge = format!(
        r#"{{"seq": 1, "op": "hello", "pad": "{}"}}"#,
        "x".repeat(200_000)
    );
    send_raw(&mut s, huge).await.unwrap();
    let e = until(&mut s, "error", &mut seen).await;
    assert_eq!(e["field"], "(message)", "{e}");
    // Uploads: a wrong header and a file that is no image are errors
    // naming the upload; one over the upload limit closes this
    // connection only.
    s.send(Message::Binary(b"TLXF\x01\x01".to_vec().into()))
        .await
        .unwrap();
    let e = until(&mut s, "error", &mut seen).await;
    assert_eq!(e["field"], "(upload)", "{e}");
    let mut not_hdr = protocol::upload_header(77).to_vec();
    not_hdr.extend_from_slice(b"#?RADIANCE\nnonsense");
    s.send(Message::Binary(not_hdr.into())).await.unwrap();
    let e = until(&mut s, "error", &mut seen).await;
    assert_eq!(
        (e["field"].as_str(), e["seq"].as_u64()),
        (Some("(upload)"), Some(77)),
        "{e}"
    );
    let mut big = protocol::upload_header(78).to_vec();
    big.resize(protocol::MAX_UPLOAD + 1, 0);
    let _ = s.send(Message::Binary(big.into())).await;
    let closed = tokio::time::timeout(Duration::from_secs(60), async {
        loop {
            match s.next().await {
                None | Some(Err(_)) | Some(Ok(Message::Close(_))) => break,
                _ => {}
            }
        }
    })
    .await;
    assert!(closed.is_ok());
    let mut again = connect(&r).await;
    let mut seen2 = Seen::default();
    let st = until(&mut again, "status", &mut seen2).await;
    assert_eq!(st["pieces"], 1);
    r.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_dropped_connection_keeps_the_session_and_floods_are_limited() {
    let dir = tempfile::tempdir().unwrap();
    let r = server(dir.path()).await;
    let mut s = connect(&r).await;
    let mut seen = Seen::default();
    until(&mut s, "status", &mut seen).await;
    send(
        &mut s,
        json!({"seq": 1, "op": "cut", "plane": {"point": [0, 0, 0], "normal": [0, 1, 0]}}),
    )
    .await;
    // The cut's own status (an earlier one, of the first solve's
    // refinement, may still be on its way under load).
    let st = loop {
        let st = until(&mut s, "status", &mut seen).await;
        if st["seqs"].as_array().unwrap().contains(&json!(1)) {
            break st;
        }
    };
    let tets = st["tets"].clone();
    drop(s);
    let mut s = connect(&r).await;
    let mut seen = Seen::default();
    let st = until(&mut s, "status", &mut seen).await;
    assert_eq!(st["tets"], tets);
    assert_eq!(st["history"]["done"][0], "cut");
    assert!(seen.surfaces >= 1 && seen.radiance >= 1);
    // A flood: more than the burst allows gets "(rate)" errors.
    for k in 0..1000 {
        send_raw(&mut s, json!({"seq": k, "op": "nope"}).to_string())
            .await
            .unwrap();
    }
    let mut rated = false;
    for _ in 0..1000 {
        let e = until(&mut s, "error", &mut seen).await;
        if e["field"] == "(rate)" {
            rated = true;
            break;
        }
    }
    assert!(rated);
    r.stop().await.unwrap();
}

/// A tiny Radiance `.hdr`: 4 × 2 flat RGBE pixels, a bright top row.
fn tiny_hdr() -> Vec<u8> {
    let mut f = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n".to_vec();
    for row in 0..2 {
        for _ in 0..4 {
            // RGBE: 1.0 is (128, 128, 128, 129); the top row 8× brighter.
            let e = if row == 0 { 132 } else { 129 };
            f.extend_from_slice(&[128, 128, 128, e]);
        }
    }
    f
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_uploaded_environment_map_lights_the_object_and_is_saved_with_the_session() {
    let dir = tempfile::tempdir().unwrap();
    let r = server(dir.path()).await;
    let mut s = connect(&r).await;
    let mut seen = Seen::default();
    until(&mut s, "status", &mut seen).await;
    let status_of = async |s: &mut Socket, seen: &mut Seen, seq: u64| loop {
        let st = until(s, "status", seen).await;
        let errors: Vec<&Value> = seen.texts.iter().filter(|t| t["type"] == "error").collect();
        assert!(errors.is_empty(), "{errors:?}");
        if st["seqs"].as_array().unwrap().contains(&json!(seq)) {
            break st;
        }
    };
    let mut upload = protocol::upload_header(5).to_vec();
    upload.extend_from_slice(&tiny_hdr());
    s.send(Message::Binary(upload.into())).await.unwrap();
    let st = status_of(&mut s, &mut seen, 5).await;
    assert_eq!(st["edit"], "lights");
    let kinds = |st: &Value| -> Vec<String> {
        st["lights"]
            .as_array()
            .unwrap()
            .iter()
            .map(|l| l["kind"].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(kinds(&st), ["dir", "env"]);
    let file = st["lights"][1]["file"].as_str().unwrap().to_string();
    assert!(file.starts_with("env-") && file.ends_with(".hdr"), "{file}");
    assert_eq!(std::fs::read(dir.path().join(&file)).unwrap(), tiny_hdr());
    // The page's light drag replaces the directional light; the map stays.
    send(
        &mut s,
        json!({"seq": 6, "op": "lights", "lights": [{"kind": "dir", "dir": [0, 0, 1]}]}),
    )
    .await;
    let st = status_of(&mut s, &mut seen, 6).await;
    assert_eq!(kinds(&st), ["dir", "env"]);
    // Saved in the session file by its file name, and read back from it.
    send(
        &mut s,
        json!({"seq": 7, "op": "export", "kind": "session", "name": "env.json"}),
    )
    .await;
    until(&mut s, "export", &mut seen).await;
    let text = std::fs::read_to_string(dir.path().join("env.json")).unwrap();
    assert!(text.contains(&file), "{text}");
    let (_, log, envs) = session_file::from_json_in(&text, Some(dir.path())).unwrap();
    assert_eq!(envs.len(), 1);
    assert!(matches!(&log.edits[0].edit, tet_diffusion::Edit::Lights(l)
        if matches!(l[1], Light::Environment(_))));
    // Without the map's file the session file names the entry.
    std::fs::remove_file(dir.path().join(&file)).unwrap();
    let e = session_file::from_json_in(&text, Some(dir.path())).unwrap_err();
    assert!(
        e.contains("edits[0].lights[1].file") && e.contains(&file),
        "{e}"
    );
    // An empty upload removes the map; undo brings it back.
    s.send(Message::Binary(protocol::upload_header(8).to_vec().into()))
        .await
        .unwrap();
    let st = status_of(&mut s, &mut seen, 8).await;
    assert_eq!(kinds(&st), ["dir"]);
    send(&mut s, json!({"seq": 9, "op": "undo"})).await;
    let st = status_of(&mut s, &mut seen, 9).await;
    assert_eq!(kinds(&st), ["dir", "env"]);
    r.stop().await.unwrap();
}

/// Everything `s` is sent until nothing more comes for `quiet`.
async fn drain(s: &mut Socket, quiet: Duration) -> Vec<Value> {
    let mut texts = Vec::new();
    while let Ok(Some(Ok(m))) = tokio::time::timeout(quiet, s.next()).await {
        if let Message::Text(t) = m {
            texts.push(serde_json::from_str(&t).unwrap());
        }
    }
    texts
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn answers_go_to_the_asking_tab_and_the_shared_state_to_every_tab() {
    let dir = tempfile::tempdir().unwrap();
    let r = server(dir.path()).await;
    let (mut a, mut b) = (connect(&r).await, connect(&r).await);
    let mut seen = Seen::default();
    until(&mut a, "status", &mut seen).await;
    until(&mut b, "status", &mut seen).await;
    // A probe, a refused undo, an export and one that is refused because
    // the file exists: each answered on a only.
    std::fs::write(dir.path().join("taken.png"), b"mine").unwrap();
    for m in [
        json!({"seq": 1, "op": "probe", "piece": 0, "point": [0, 0, 0]}),
        json!({"seq": 2, "op": "undo"}),
        json!({"seq": 3, "op": "export", "kind": "png", "name": "a.png", "size": 32}),
        json!({"seq": 4, "op": "export", "kind": "png", "name": "taken.png", "size": 32}),
    ] {
        send(&mut a, m).await;
    }
    let answers = drain(&mut a, Duration::from_secs(3)).await;
    let kinds: Vec<(&str, u64)> = answers
        .iter()
        .filter_map(|v| Some((v["type"].as_str()?, v["seq"].as_u64()?)))
        .collect();
    for want in [("probe", 1), ("error", 2), ("export", 3), ("error", 4)] {
        assert!(kinds.contains(&want), "a got {answers:?}");
    }
    let exists = answers.iter().find(|v| v["seq"] == 4).unwrap();
    assert_eq!(exists["exists"], true, "{exists}");
    let on_b = drain(&mut b, Duration::from_millis(500)).await;
    assert!(
        on_b.iter().all(|v| v["type"] == "status"),
        "b got another tab's answers: {on_b:?}"
    );
    // An edit's status (the shared state) reaches both.
    let paint = json!({"seq": 5, "op": "paint", "material": "apple", "radius": 0.1,
                       "strength": 1, "points": [[0, 0, 0]]});
    send(&mut a, paint).await;
    for s in [&mut a, &mut b] {
        let status = until(s, "status", &mut seen).await;
        assert_eq!(status["seqs"], json!([5]), "{status}");
    }
    r.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_tet_exports_ele_in_the_way_asks_to_replace_it() {
    let dir = tempfile::tempdir().unwrap();
    let r = server(dir.path()).await;
    let mut s = connect(&r).await;
    let mut seen = Seen::default();
    until(&mut s, "status", &mut seen).await;
    // Only the .ele of the pair exists: still a file the export replaces.
    std::fs::write(dir.path().join("mesh.ele"), b"old").unwrap();
    let export = json!({"seq": 1, "op": "export", "kind": "tet", "name": "mesh.node"});
    send(&mut s, export).await;
    let e = until(&mut s, "error", &mut seen).await;
    assert_eq!(
        (e["seq"].clone(), e["exists"].clone()),
        (json!(1), json!(true)),
        "{e}"
    );
    let message = e["message"].as_str().unwrap();
    assert!(message.ends_with("mesh.ele: the file exists"), "{message}");
    assert!(!dir.path().join("mesh.node").exists());
    // The page's "replace" sends it again with overwrite.
    let export = json!({"seq": 2, "op": "export", "kind": "tet", "name": "mesh.node",
                        "overwrite": true});
    send(&mut s, export).await;
    assert_eq!(until(&mut s, "export", &mut seen).await["seq"], 2);
    // A writer's own failure is not taken for an existing file.
    std::fs::create_dir(dir.path().join("sub.png")).unwrap();
    let export = json!({"seq": 3, "op": "export", "kind": "png", "name": "sub.png",
                        "overwrite": true});
    send(&mut s, export).await;
    let e = until(&mut s, "error", &mut seen).await;
    assert_eq!(
        (e["seq"].clone(), e["exists"].clone()),
        (json!(3), json!(false)),
        "{e}"
    );
    r.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_pages_hello_is_answered_by_a_status_to_it_alone_not_the_whole_state_again() {
    let dir = tempfile::tempdir().unwrap();
    let r = server(dir.path()).await;
    let (mut a, mut b) = (connect(&r).await, connect(&r).await);
    let mut seen = Seen::default();
    // The snapshot: hello, the surface, the radiance, the status.
    until(&mut a, "status", &mut seen).await;
    assert_eq!((seen.surfaces, seen.radiance), (1, 1));
    // The first solve's refinement, to both.
    for s in [&mut a, &mut b] {
        drain(s, Duration::from_secs(1)).await;
    }
    send(&mut a, json!({"seq": 9, "op": "hello"})).await;
    let mut after = Seen::default();
    let status = until(&mut a, "status", &mut after).await;
    assert_eq!(status["seqs"], json!([9]), "{status}");
    assert_eq!(
        (after.texts.len(), after.surfaces, after.radiance),
        (1, 0, 0)
    );
    let on_b = drain(&mut b, Duration::from_millis(500)).await;
    assert!(on_b.is_empty(), "b got {on_b:?}");
    r.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_web_cores_guard_holds_for_view() {
    let dir = tempfile::tempdir().unwrap();
    let r = server(dir.path()).await;
    web::check_guard(r.addr, &r.token, "view").await;
    r.stop().await.unwrap();
}
