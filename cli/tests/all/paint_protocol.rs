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

/// What came: JSON messages and the binary frames' kinds; the last
/// scatter points (kind 5) and strands header (kind 6: strands, points
/// each).
#[derive(Default)]
struct Seen {
    frames: Vec<u8>,
    points: Option<Vec<[f32; 3]>>,
    strands: Option<(u32, u32)>,
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
                let word = |i: usize| u32::from_le_bytes(b[i..i + 4].try_into().unwrap());
                if b[5] == 5 {
                    let xyz: Vec<f32> = b[16..]
                        .chunks_exact(4)
                        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                        .collect();
                    assert_eq!(xyz.len(), 3 * word(8) as usize);
                    seen.points = Some(xyz.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect());
                    seen.strands = None;
                }
                if b[5] == 6 {
                    assert_eq!(b.len() - 16, 12 * (word(8) * word(12)) as usize);
                    seen.strands = Some((word(8), word(12)));
                }
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

    // Detail up under a brush: more samples, which the textures' spare
    // rows (there from the start) hold: only the runs it changed are
    // sent (kind 7), not the whole textures again (kinds 2 and 3).
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
        seen.frames.contains(&7) && !seen.frames.contains(&3),
        "{:?}",
        seen.frames
    );

    // Undo the detail, redo it: both fit the textures as they are, so
    // only the changed runs go (kind 7), not the textures.
    seen.frames.clear();
    send(&mut s, json!({"seq": 8, "op": "undo"})).await;
    let undone = status_of(&mut s, 8, &mut seen).await;
    assert_eq!(seen.frames, vec![7], "{:?}", seen.frames);
    assert_eq!(undone["samples"], start["samples"]);
    assert_eq!(
        (undone["undo"].clone(), undone["redo"].clone()),
        (json!(2), json!(1))
    );
    seen.frames.clear();
    send(&mut s, json!({"seq": 9, "op": "redo"})).await;
    assert_eq!(
        status_of(&mut s, 9, &mut seen).await["samples"],
        detailed["samples"]
    );
    assert_eq!(seen.frames, vec![7], "{:?}", seen.frames);

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
    glb_has_the_density_as_its_own_texture(&d.join("blob.glb"));
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
async fn a_resolution_the_textures_cannot_hold_is_refused_and_taken_back() {
    let dir = tempfile::tempdir().unwrap();
    let r = server(dir.path()).await;
    let mut s = connect(&r).await;
    let mut seen = Seen::default();
    until(&mut s, "hello", &mut seen).await;
    let start = until(&mut s, "status", &mut seen).await;
    // Level 8 on the blob's 320 faces: 10⁷ samples, which the colours
    // allow but whose pyramid needs more than WebGL2's 2048² texels.
    send(&mut s, json!({"seq": 1, "op": "resolution", "level": 8})).await;
    // The error (a reply) and the status (to every page) come by two
    // queues: in either order.
    let (mut error, mut after) = (None, None);
    while error.is_none() || after.is_none() {
        let m = tokio::time::timeout(Duration::from_secs(120), s.next())
            .await
            .expect("the server answers")
            .unwrap()
            .unwrap();
        if let Message::Text(t) = m {
            let v: Value = serde_json::from_str(&t).unwrap();
            if v["type"] == "error" && v["seq"] == 1 {
                error = Some(v);
            } else if v["type"] == "status" && v["seqs"].as_array().unwrap().contains(&json!(1)) {
                after = Some(v);
            }
        }
    }
    let (e, after) = (error.unwrap(), after.unwrap());
    let message = e["message"].as_str().unwrap();
    assert!(
        message.contains("GPU textures") && message.contains("not made"),
        "{e}"
    );
    for key in ["samples", "memory", "undo", "redo", "edits", "finest_level"] {
        assert_eq!(after[key], start[key], "{key}");
    }
    // The session goes on: a dab is painted and sent as texels.
    seen.frames.clear();
    let p = document().surface.positions[0];
    send(&mut s, json!({"seq": 2, "op": "begin", "brush": brush()})).await;
    send(
        &mut s,
        json!({"seq": 3, "op": "dabs", "dabs": [[p.x, p.y, p.z, 0.2, 1.0]]}),
    )
    .await;
    send(&mut s, json!({"seq": 4, "op": "end"})).await;
    let painted = status_of(&mut s, 4, &mut seen).await;
    assert_eq!(painted["undo"], 1);
    assert!(seen.frames.contains(&4), "{:?}", seen.frames);
    // And a resolution that fits still does.
    send(&mut s, json!({"seq": 5, "op": "resolution", "level": 4})).await;
    let raised = status_of(&mut s, 5, &mut seen).await;
    assert_eq!(raised["finest_level"], 4);
    assert_eq!(raised["undo"], 2);
    r.stop().await.unwrap();
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

/// The scatter panel through the protocol: points by rate where the
/// density channel is painted, a second stroke elsewhere only adds points
/// (the first stroke's stay bit for bit), undo gives the first set back,
/// a count of blue-noise points, strands and their export, and bad
/// requests named.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_scatter_follows_the_painted_density() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let r = server(d).await;
    let mut s = connect(&r).await;
    let mut seen = Seen::default();
    let hello = until(&mut s, "hello", &mut seen).await;
    let area = hello["area"].as_f64().unwrap();
    assert!(area > 0.0);
    until(&mut s, "status", &mut seen).await;

    // Nothing painted yet: no points.
    let rate = 4000.0 / area;
    let scatter = json!({"seq": 1, "op": "scatter", "mode": "rate", "channel": "density",
        "rate": rate, "seed": 3, "hair": {"length": 0.05, "segments": 4}});
    send(&mut s, scatter).await;
    let st = status_of(&mut s, 1, &mut seen).await;
    assert_eq!(st["points"], 0);
    // The status names the request, for a page that connects later.
    assert_eq!(
        st["scatter"],
        json!({"mode": "rate", "channel": "density", "rate": rate, "seed": 3,
            "hair": {"length": 0.05f32, "segments": 4, "length_channel": null}})
    );
    assert_eq!(seen.points.as_deref().map(<[_]>::len), Some(0));

    // A stroke of density 1 around vertex 0: points there.
    let doc = document();
    let mut density = brush();
    density["channel"] = json!("density");
    density["color"] = json!([1.0]);
    let stroke = |seq: u64, p: glam::Vec3| {
        [
            json!({"seq": seq, "op": "begin", "brush": density.clone()}),
            json!({"seq": seq + 1, "op": "dabs", "dabs": [[p.x, p.y, p.z, 0.4, 1.0]]}),
            json!({"seq": seq + 2, "op": "end"}),
        ]
    };
    let (p0, p1) = (doc.surface.positions[0], -doc.surface.positions[0]);
    for m in stroke(2, p0) {
        send(&mut s, m).await;
    }
    let st = status_of(&mut s, 4, &mut seen).await;
    let first = seen.points.clone().unwrap();
    assert!(first.len() > 20, "{} points", first.len());
    assert_eq!(st["points"], first.len());
    assert_eq!(seen.strands.unwrap().1, 5, "4 segments: 5 points a strand");
    assert!(
        first
            .iter()
            .all(|q| (glam::Vec3::from(*q) - p0).length() < 0.6),
        "points only near the stroke"
    );

    // A stroke on the other side adds points and keeps the first ones.
    for m in stroke(5, p1) {
        send(&mut s, m).await;
    }
    status_of(&mut s, 7, &mut seen).await;
    let second = seen.points.clone().unwrap();
    assert!(second.len() > first.len());
    let bits = |v: &[[f32; 3]]| -> std::collections::BTreeSet<[u32; 3]> {
        v.iter().map(|p| p.map(f32::to_bits)).collect()
    };
    assert!(
        bits(&first).is_subset(&bits(&second)),
        "the first stroke's points stay"
    );

    // Undo: exactly the first set again.
    send(&mut s, json!({"seq": 8, "op": "undo"})).await;
    status_of(&mut s, 8, &mut seen).await;
    assert_eq!(bits(seen.points.as_ref().unwrap()), bits(&first));

    // Exports: the points as PLY, the strands as USD.
    send(
        &mut s,
        json!({"seq": 9, "op": "export", "kind": "points", "name": "roots.ply"}),
    )
    .await;
    until(&mut s, "export", &mut seen).await;
    let ply = trilux::trilux_io::mesh::ply::read(d.join("roots.ply")).unwrap();
    assert_eq!(ply.positions.len(), first.len());
    send(
        &mut s,
        json!({"seq": 10, "op": "export", "kind": "strands", "name": "hair.usda"}),
    )
    .await;
    until(&mut s, "export", &mut seen).await;
    let usda = std::fs::read_to_string(d.join("hair.usda")).unwrap();
    assert!(usda.contains("BasisCurves"), "{usda}");

    // Blue noise by count: exactly that many.
    send(
        &mut s,
        json!({"seq": 11, "op": "scatter", "mode": "blue_noise", "channel": "density",
        "count": 300, "seed": 1}),
    )
    .await;
    let st = status_of(&mut s, 11, &mut seen).await;
    assert_eq!(st["points"], 300);
    assert_eq!(seen.points.as_ref().unwrap().len(), 300);

    // Bad requests name their field and keep the points.
    let bad = [
        (
            json!({"mode": "rate", "channel": "density", "rate": -1}),
            "rate",
        ),
        (
            json!({"mode": "rate", "channel": "nope", "rate": 1}),
            "channel",
        ),
        (json!({"mode": "sprinkle", "channel": "density"}), "mode"),
        (
            json!({"mode": "count", "channel": "density", "count": 0}),
            "count",
        ),
        (
            json!({"mode": "rate", "channel": "density", "rate": 1e12}),
            "rate",
        ),
        (
            json!({"mode": "count", "channel": "density", "count": 5,
            "hair": {"length": 0.1, "segments": 0}}),
            "hair.segments",
        ),
        (
            json!({"mode": "count", "channel": "density", "count": 5,
            "hair": {"length": 0.1, "segments": 2, "length_channel": "nope"}}),
            "hair.length_channel",
        ),
    ];
    for (k, (fields, field)) in bad.into_iter().enumerate() {
        let seq = 20 + k as u64;
        let mut m = fields.clone();
        m["seq"] = json!(seq);
        m["op"] = json!("scatter");
        send(&mut s, m).await;
        let e = error_of(&mut s, seq).await;
        assert_eq!(e["field"], field, "{fields}: {e}");
    }
    send(
        &mut s,
        json!({"seq": 40, "op": "export", "kind": "strands", "name": "x.usda"}),
    )
    .await;
    let e = error_of(&mut s, 40).await;
    assert!(e["message"].as_str().unwrap().contains("strands"), "{e}");
    send(
        &mut s,
        json!({"seq": 41, "op": "pick", "face": 0, "barycentric": [1, 0, 0]}),
    )
    .await;
    let st = status_of(&mut s, 41, &mut seen).await;
    assert_eq!(st["points"], 300, "the refused requests kept the points");
    r.stop().await.unwrap();
}

/// The GLB's scalar channel `density` (filled with 0.5 above) is a texture
/// of its own, named and listed in the material's extras, stored as data
/// (byte 128, no sRGB curve); the base colour is opaque (the density is
/// not its alpha).
fn glb_has_the_density_as_its_own_texture(path: &std::path::Path) {
    let bytes = std::fs::read(path).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let doc: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin = &bytes[20 + json_len + 8..];
    let material = &doc["materials"][0];
    // Named after the model (the built-in one here), not "atlas".
    assert_eq!(material["name"], "model", "{doc:#}");
    assert_eq!(doc["meshes"][0]["name"], "model", "{doc:#}");
    let density = material["extras"]["scalar_textures"]["density"]
        .as_u64()
        .unwrap() as usize;
    assert_eq!(doc["textures"][density]["name"], "density", "{doc:#}");
    let image = |texture: usize| {
        let source = doc["textures"][texture]["source"].as_u64().unwrap() as usize;
        let view =
            &doc["bufferViews"][doc["images"][source]["bufferView"].as_u64().unwrap() as usize];
        let at = view["byteOffset"].as_u64().unwrap_or(0) as usize;
        let png = &bin[at..at + view["byteLength"].as_u64().unwrap() as usize];
        trilux_io::image::decode(png, std::path::Path::new("t.png"), Default::default()).unwrap()
    };
    // decode reads colour as sRGB: undo it to see the stored byte.
    let stored = |v: f32| (trilux_io::image::linear_to_srgb(v) * 255.0).round() as u8;
    let values = image(density);
    assert!(
        values.pixels.iter().any(|p| stored(p[0]) == 128),
        "no texel of the 0.5 fill"
    );
    let base = material["pbrMetallicRoughness"]["baseColorTexture"]["index"]
        .as_u64()
        .unwrap();
    assert!(
        image(base as usize).pixels.iter().all(|p| p[3] == 1.0),
        "the base colour is opaque"
    );
}
