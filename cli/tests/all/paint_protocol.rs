//! `trilux paint`'s server driven through its protocol by a WebSocket
//! client: a stroke sent dab by dab comes back as the texels it changed,
//! the eyedropper reads the painted colour, the detail brush raises the
//! sample count and sends the new layout, undo/redo, saves and exports
//! (atomic, never over a file unless asked), a session file that replays
//! to the saved colours bit for bit, and bad messages that get an error
//! naming the field and leave the session as it was.
#![cfg(feature = "paint")]

use std::time::Duration;

use futures_util::{SinkExt, StreamExt};
use serde_json::{Value, json};
use tokio_tungstenite::tungstenite::Message;
use trilux::ColorMesh;
use trilux::mesh_colors::MeshColors;
use trilux::paint::{Document, Options, Running};

use crate::common::web::{Socket, send};

/// The built-in blob at resolution 8, grey, with a `density` channel.
fn document() -> Document {
    let surface = ColorMesh::new(&trilux::shapes::blob(2)).unwrap();
    let mut colors = MeshColors::uniform(surface.topology().unwrap(), 8, 4).unwrap();
    for s in colors.samples_mut().chunks_mut(4) {
        s.copy_from_slice(&[0.8, 0.8, 0.8, 0.0]);
    }
    Document {
        surface,
        colors,
        base: vec![0.8, 0.8, 0.8, 0.0],
        scalars: vec!["density".into()],
        source: json!({"mesh": null}),
    }
}

async fn server(dir: &std::path::Path) -> Running {
    let options = Options {
        export_dir: dir.to_path_buf(),
        autosave: Some(dir.join("autosave.meshcolors")),
        ..Options::default()
    };
    trilux::paint::start(document(), None, options)
        .await
        .unwrap()
}

async fn connect(r: &Running) -> Socket {
    crate::common::web::connect(&r.addr.to_string(), &r.token).await
}

/// What came: JSON messages and the binary frames' kinds.
#[derive(Default)]
struct Seen {
    frames: Vec<u8>,
}

/// The next JSON message of type `kind`; frames on the way are counted.
async fn until(s: &mut Socket, kind: &str, seen: &mut Seen) -> Value {
    loop {
        let m = tokio::time::timeout(Duration::from_secs(120), s.next())
            .await
            .expect("the server answers")
            .expect("the connection stays open")
            .expect("no protocol error");
        match m {
            Message::Text(t) => {
                let v: Value = serde_json::from_str(&t).unwrap();
                if v["type"] == kind {
                    return v;
                }
                assert_ne!(v["type"], "error", "{v}");
            }
            Message::Binary(b) => {
                assert_eq!(&b[..4], b"TLXM");
                assert_eq!(b[4], trilux::paint::VERSION);
                seen.frames.push(b[5]);
            }
            _ => {}
        }
    }
}

/// The status answering `seq`.
async fn status_of(s: &mut Socket, seq: u64, seen: &mut Seen) -> Value {
    loop {
        let v = until(s, "status", seen).await;
        if v["seqs"].as_array().unwrap().contains(&json!(seq)) {
            return v;
        }
    }
}

/// The error answering `seq`.
async fn error_of(s: &mut Socket, seq: u64) -> Value {
    loop {
        let m = tokio::time::timeout(Duration::from_secs(60), s.next())
            .await
            .unwrap()
            .unwrap()
            .unwrap();
        if let Message::Text(t) = m {
            let v: Value = serde_json::from_str(&t).unwrap();
            if v["type"] == "error" && v["seq"] == seq {
                return v;
            }
        }
    }
}

fn brush() -> Value {
    json!({"mode": "mix", "channel": "color", "color": [0.9, 0.1, 0.05],
           "strength": 1.0, "hardness": 1.0, "mirror": false, "eye": null})
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn paint_detail_undo_save_and_replay_through_the_protocol() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let r = server(d).await;
    let mut s = connect(&r).await;
    let mut seen = Seen::default();
    let hello = until(&mut s, "hello", &mut seen).await;
    assert_eq!(hello["app"], "paint");
    assert_eq!(hello["channels"], json!(["color", "density"]));
    let start = until(&mut s, "status", &mut seen).await;
    // The snapshot: mesh, face table, samples.
    assert_eq!(seen.frames, vec![1, 2, 3]);

    // A stroke in two messages of dabs: texel updates, one undo step.
    let doc = document();
    let p = doc.surface.positions[0];
    send(&mut s, json!({"seq": 1, "op": "begin", "brush": brush()})).await;
    let dab = |dx: f32| json!([p.x + dx, p.y, p.z, 0.2, 1.0]);
    send(&mut s, json!({"seq": 2, "op": "dabs", "dabs": [dab(0.0)]})).await;
    send(
        &mut s,
        json!({"seq": 3, "op": "dabs", "dabs": [dab(0.02), dab(0.04)]}),
    )
    .await;
    send(&mut s, json!({"seq": 4, "op": "end"})).await;
    seen.frames.clear();
    let painted = status_of(&mut s, 4, &mut seen).await;
    assert_eq!(painted["undo"], 1);
    assert!(seen.frames.contains(&4), "{:?}", seen.frames);
    assert!(
        !seen.frames.contains(&3),
        "a stroke sends texels, not the texture"
    );

    // The eyedropper at vertex 0 (the dab's centre): the brush colour.
    let (face, k) = doc
        .surface
        .faces
        .iter()
        .enumerate()
        .find_map(|(f, t)| t.iter().position(|&v| v == 0).map(|k| (f, k)))
        .unwrap();
    let mut b = [0.0; 3];
    b[k] = 1.0;
    send(
        &mut s,
        json!({"seq": 5, "op": "pick", "face": face, "barycentric": b}),
    )
    .await;
    let picked = until(&mut s, "pick", &mut seen).await;
    assert_eq!(picked["seq"], 5);
    let c: Vec<f64> = picked["color"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!(
        (c[0] - 0.9).abs() < 1e-6 && (c[1] - 0.1).abs() < 1e-6 && c[3] == 0.0,
        "{c:?}"
    );

    // The density channel alone.
    let mut density = brush();
    density["channel"] = json!("density");
    density["color"] = json!([0.5]);
    send(
        &mut s,
        json!({"seq": 6, "op": "fill", "face": 0, "brush": density}),
    )
    .await;
    status_of(&mut s, 6, &mut seen).await;

    // Detail up under a brush: more samples, the new layout sent.
    seen.frames.clear();
    send(
        &mut s,
        json!({"seq": 7, "op": "detail", "center": p.to_array(), "radius": 0.3, "levels": 1}),
    )
    .await;
    let detailed = status_of(&mut s, 7, &mut seen).await;
    assert!(detailed["samples"].as_u64() > start["samples"].as_u64());
    assert_eq!(detailed["finest_level"], 4);
    assert!(
        seen.frames.contains(&2) && seen.frames.contains(&3),
        "{:?}",
        seen.frames
    );

    // Undo the detail, redo it.
    send(&mut s, json!({"seq": 8, "op": "undo"})).await;
    let undone = status_of(&mut s, 8, &mut seen).await;
    assert_eq!(undone["samples"], start["samples"]);
    assert_eq!(
        (undone["undo"].clone(), undone["redo"].clone()),
        (json!(2), json!(1))
    );
    send(&mut s, json!({"seq": 9, "op": "redo"})).await;
    assert_eq!(
        status_of(&mut s, 9, &mut seen).await["samples"],
        detailed["samples"]
    );

    // Save, refuse to save over it, then export the session and a GLB.
    send(
        &mut s,
        json!({"seq": 10, "op": "save", "name": "blob.meshcolors"}),
    )
    .await;
    assert_eq!(until(&mut s, "export", &mut seen).await["seq"], 10);
    send(
        &mut s,
        json!({"seq": 11, "op": "save", "name": "blob.meshcolors"}),
    )
    .await;
    let refused = error_of(&mut s, 11).await;
    assert_eq!(refused["exists"], true, "{refused}");
    send(
        &mut s,
        json!({"seq": 12, "op": "export", "kind": "session", "name": "s.json"}),
    )
    .await;
    until(&mut s, "export", &mut seen).await;
    send(
        &mut s,
        json!({"seq": 13, "op": "export", "kind": "glb", "name": "blob.glb"}),
    )
    .await;
    until(&mut s, "export", &mut seen).await;
    test_support::gltf::validate(&d.join("blob.glb"));
    r.stop().await.unwrap();

    // The session file replays to the saved colours, bit for bit.
    let (saved, _) = trilux::mesh_colors::file::load(d.join("blob.meshcolors")).unwrap();
    let text = std::fs::read_to_string(d.join("s.json")).unwrap();
    let doc = document();
    let (_, log) =
        trilux::paint::session_file::from_json(&text, &doc.scalars, doc.mirror_x()).unwrap();
    let (source, _) =
        trilux::paint::session_file::from_json(&text, &doc.scalars, doc.mirror_x()).unwrap();
    assert_eq!(
        trilux::paint::session_file::check_replays_on(&source, &doc),
        Ok(())
    );
    assert_eq!(log.len(), 5);
    let replayed = trilux::paint::open_session(&doc, &log, 10).unwrap();
    let bits = |c: &MeshColors| c.samples().iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(replayed.colors()), bits(&saved));
    // Stopping wrote the autosave: the same colours.
    let (auto, _) = trilux::mesh_colors::file::load(d.join("autosave.meshcolors")).unwrap();
    assert_eq!(bits(&auto), bits(&saved));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_messages_get_an_error_naming_the_field_and_change_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let r = server(dir.path()).await;
    let mut s = connect(&r).await;
    let mut seen = Seen::default();
    let start = until(&mut s, "status", &mut seen).await;
    let cases = [
        (json!({"seq": 1, "op": "smudge"}), "op"),
        (
            json!({"seq": 2, "op": "dabs", "dabs": [[0, 0, 0, 0.1, 1]]}),
            "dabs",
        ),
        (
            json!({"seq": 3, "op": "begin", "brush": {"mode": "mix"}}),
            "brush.channel",
        ),
        (
            json!({"seq": 4, "op": "dabs", "dabs": [[0, 0, 0, -1, 1]]}),
            "dabs[0][3]",
        ),
        (
            json!({"seq": 5, "op": "dabs", "dabs": [[0, 0, 1e300, 0.1, 1]]}),
            "dabs[0][2]",
        ),
        (
            json!({"seq": 6, "op": "fill", "face": 999_999, "brush": brush()}),
            "face",
        ),
        (
            json!({"seq": 7, "op": "pick", "face": 0, "barycentric": [2, 0, 0]}),
            "barycentric",
        ),
        (
            json!({"seq": 8, "op": "save", "name": "../up.meshcolors"}),
            "name",
        ),
        (json!({"seq": 9, "op": "resolution", "level": 64}), "level"),
        (
            json!({"seq": 10, "op": "begin", "brush": {"mode": "mix", "channel": "wetness",
                "color": [1], "strength": 1, "hardness": 1}}),
            "brush.channel",
        ),
    ];
    for (m, field) in cases {
        let seq = m["seq"].as_u64().unwrap();
        send(&mut s, m.clone()).await;
        let e = error_of(&mut s, seq).await;
        assert_eq!(e["field"], field, "{m}: {e}");
    }
    // A message beyond the socket's size ends that connection only: the
    // session goes on for the next one.
    let huge = format!(
        r#"{{"seq":11,"op":"dabs","dabs":[{}]}}"#,
        vec!["[0,0,0,1,1]"; 40_000].join(",")
    );
    let _ = s.send(Message::Text(huge.into())).await;
    let mut s = connect(&r).await;
    send(&mut s, json!({"seq": 12, "op": "undo"})).await;
    let after = status_of(&mut s, 12, &mut seen).await;
    assert_eq!(after["samples"], start["samples"]);
    assert_eq!(after["edits"], 1, "only the undo was logged: {after}");
    // The page's URL needs the token, in paint's words.
    let mut tcp = tokio::net::TcpStream::connect(r.addr).await.unwrap();
    use tokio::io::{AsyncReadExt, AsyncWriteExt};
    tcp.write_all(
        format!(
            "GET /wrong/ HTTP/1.1\r\nHost: {}\r\nConnection: close\r\n\r\n",
            r.addr
        )
        .as_bytes(),
    )
    .await
    .unwrap();
    let mut answer = String::new();
    tcp.read_to_string(&mut answer).await.unwrap();
    assert!(answer.starts_with("HTTP/1.1 404"), "{answer}");
    assert!(
        answer.contains(trilux::paint::NEEDS_TOKEN.trim()),
        "{answer}"
    );
    r.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_web_cores_guard_holds_for_paint() {
    let dir = tempfile::tempdir().unwrap();
    let r = server(dir.path()).await;
    crate::common::web::check_guard(r.addr, &r.token, "paint").await;
    r.stop().await.unwrap();
}
