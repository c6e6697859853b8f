//! The `trilux paint` server benchmark: drives the server through its
//! protocol (a WebSocket client in this process, like the page) on the
//! Spot cow with its texture converted to mesh colours (about 10⁶
//! samples; the built-in blob at a similar count without the data) and
//! prints one Markdown table of medians, each beside the same change made
//! the way a tool without incremental updates would (a new MIP pyramid
//! and a new packed texture) in the same run.
//!
//! ```sh
//! TRILUX_DATA=../shared/data cargo run --release -p trilux --example paint_bench
//! ```
//!
//! What it measures is the server's part (apply, refresh the pyramid,
//! pack and send the texels); the page's upload and draw are the browser
//! test's and the shader's measurement.

use std::time::{Duration, Instant};

use futures_util::{SinkExt, StreamExt};
use serde_json::{Value, json};
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;
use trilux::ColorMesh;
use trilux::mesh_colors::gpu::GpuLayout;
use trilux::mesh_colors::{MeshColors, MipMap};
use trilux::paint::{Document, Options};

type Socket =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

struct Client {
    socket: Socket,
    seq: u64,
}

impl Client {
    async fn send(&mut self, op: &str, mut fields: Value) -> u64 {
        self.seq += 1;
        fields["seq"] = json!(self.seq);
        fields["op"] = json!(op);
        self.socket
            .send(Message::Text(fields.to_string().into()))
            .await
            .expect("send");
        self.seq
    }

    /// The status answering `seq` (texel frames on the way are counted).
    async fn status(&mut self, seq: u64) -> (Value, usize) {
        let (status, kinds) = self.status_kinds(seq).await;
        (status, kinds.len())
    }

    /// The status answering `seq` and the kinds of the frames on the way.
    async fn status_kinds(&mut self, seq: u64) -> (Value, Vec<u8>) {
        let mut frames = Vec::new();
        loop {
            let m = tokio::time::timeout(Duration::from_secs(600), self.socket.next())
                .await
                .expect("an answer")
                .expect("open")
                .expect("no error");
            match m {
                Message::Binary(b) => frames.push(b.get(5).copied().unwrap_or(0)),
                Message::Text(t) => {
                    let v: Value = serde_json::from_str(&t).unwrap_or_default();
                    assert_ne!(v["type"], "error", "{v}");
                    if v["type"] == "status"
                        && v["seqs"]
                            .as_array()
                            .is_some_and(|s| s.contains(&json!(seq)))
                    {
                        return (v, frames);
                    }
                }
                _ => {}
            }
        }
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Spot with its texture converted, or the blob at about 10⁶ samples.
fn document() -> (String, Document) {
    let data = std::env::var_os("TRILUX_DATA").map(std::path::PathBuf::from);
    let spot = data.as_ref().map(|d| {
        (
            d.join("meshes/spot.obj"),
            d.join("textures/spot_texture.png"),
        )
    });
    let (name, surface, colors) = match spot.filter(|(m, t)| m.exists() && t.exists()) {
        Some((mesh, texture)) => {
            let mesh = trilux_io::mesh::TriMesh::read(mesh).unwrap();
            let image = trilux_io::image::read(texture).unwrap();
            let (surface, colors) =
                trilux::to_mesh_colors(&mesh, Some(&image), &Default::default()).unwrap();
            ("spot, texture converted".to_string(), surface, colors)
        }
        None => {
            let surface = ColorMesh::new(&trilux::shapes::blob(5)).unwrap();
            let mut colors = MeshColors::uniform(surface.topology().unwrap(), 8, 3).unwrap();
            colors.samples_mut().fill(0.8);
            ("the built-in blob".to_string(), surface, colors)
        }
    };
    let doc = Document {
        surface,
        colors,
        base: vec![0.8; 3],
        scalars: Vec::new(),
        source: json!({"mesh": null}),
    };
    (name, doc)
}

/// The time of a rebuild after a change: a new pyramid and a new packed
/// texture (what a tool without incremental updates does).
fn rebuild_ms(colors: &MeshColors) -> f64 {
    let t = Instant::now();
    let mip = MipMap::new(colors.clone());
    let gpu = GpuLayout::new(&mip, 2048).unwrap();
    std::hint::black_box(gpu.sample_texels().len());
    t.elapsed().as_secs_f64() * 1e3
}

/// Connects a client the way the page does.
async fn connect(running: &trilux::paint::Running) -> Client {
    let mut request = format!("ws://{}/{}/ws", running.addr, running.token)
        .into_client_request()
        .unwrap();
    request.headers_mut().insert(
        "Origin",
        format!("http://{}", running.addr).parse().unwrap(),
    );
    // The whole samples texture comes first: tens of MB, as a page
    // takes it.
    let config = tokio_tungstenite::tungstenite::protocol::WebSocketConfig::default()
        .max_message_size(Some(1 << 30))
        .max_frame_size(Some(1 << 30));
    let socket = tokio_tungstenite::connect_async_with_config(request, Some(config), false)
        .await
        .unwrap()
        .0;
    Client { socket, seq: 0 }
}

/// The scatter panel on `doc` with a `density` channel: the whole surface
/// painted 1 with a rate that gives about 10⁶ points, then strokes of one
/// dab (1 % of the diagonal) that lower the density under them, each
/// timed from the dab sent to its points frame received (medians), beside
/// a scatter of the whole surface again in the same run (what a node
/// graph re-evaluates). Returns (stroke → points ms, points, rebuild ms).
async fn scatter_rows(doc: &Document, diagonal: f32) -> (f64, usize, f64) {
    let mut colors = MeshColors::uniform(
        doc.surface.topology().unwrap(),
        doc.colors.face_resolution(0).unwrap_or(8),
        4,
    )
    .unwrap();
    for s in colors.samples_mut().chunks_mut(4) {
        s.copy_from_slice(&[0.8, 0.8, 0.8, 1.0]);
    }
    let area = doc.area();
    let dense = Document {
        surface: doc.surface.clone(),
        colors,
        base: vec![0.8, 0.8, 0.8, 0.0],
        scalars: vec!["density".into()],
        source: json!({"mesh": null}),
    };
    let positions = dense.surface.positions.clone();
    let dir = tempfile::tempdir().unwrap();
    let options = Options {
        export_dir: dir.path().to_path_buf(),
        autosave: None,
        ..Options::default()
    };
    let running = trilux::paint::start(dense, None, options).await.unwrap();
    let mut c = connect(&running).await;
    let rate = 1e6 / area;
    let mut rebuild_ms = Vec::new();
    let mut points = 0;
    for seed in 0..5 {
        let t = Instant::now();
        let seq = c
            .send(
                "scatter",
                json!({"mode": "rate", "channel": "density", "rate": rate, "seed": seed}),
            )
            .await;
        let (status, kinds) = c.status_kinds(seq).await;
        assert!(kinds.contains(&5));
        rebuild_ms.push(t.elapsed().as_secs_f64() * 1e3);
        points = status["points"].as_u64().unwrap() as usize;
    }
    let brush = json!({"mode": "mix", "channel": "density", "color": [0.3],
                       "strength": 1.0, "hardness": 0.5, "mirror": false, "eye": null});
    let radius = 0.01 * diagonal;
    let mut stroke_ms = Vec::new();
    for k in 0..21 {
        let p = positions[(k * 7919) % positions.len()];
        let t = Instant::now();
        c.send("begin", json!({"brush": brush})).await;
        c.send("dabs", json!({"dabs": [[p.x, p.y, p.z, radius, 1.0]]}))
            .await;
        let seq = c.send("end", json!({})).await;
        let (_, kinds) = c.status_kinds(seq).await;
        assert!(kinds.contains(&5), "{kinds:?}");
        stroke_ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    running.stop().await.unwrap();
    (median(stroke_ms), points, median(rebuild_ms))
}

fn main() {
    let (name, doc) = document();
    let samples = doc.colors.sample_count();
    let colors_start = doc.colors.clone();
    let diagonal = {
        let (lo, hi) = doc.bounds();
        (hi - lo).length()
    };
    let positions = doc.surface.positions.clone();
    let faces = doc.surface.faces.clone();
    let runtime = tokio::runtime::Runtime::new().unwrap();
    runtime.block_on(async move {
        let dir = tempfile::tempdir().unwrap();
        let options = Options {
            export_dir: dir.path().to_path_buf(),
            autosave: None,
            ..Options::default()
        };
        let scatter = scatter_rows(&doc, diagonal).await;
        let running = trilux::paint::start(doc, None, options).await.unwrap();
        let mut c = connect(&running).await;
        let brush = json!({"mode": "mix", "channel": "color", "color": [0.9, 0.1, 0.1],
                           "strength": 1.0, "hardness": 0.5, "mirror": false, "eye": null});
        // A brush of 1 % of the diagonal.
        let radius = 0.01 * diagonal;
        let dab = |k: usize| {
            let p = positions[(k * 7919) % positions.len()];
            json!([p.x, p.y, p.z, radius, 1.0])
        };

        // One dab → its texels and status, 40 times within a stroke.
        let seq = c.send("begin", json!({"brush": brush})).await;
        c.status(seq).await;
        let mut dab_ms = Vec::new();
        for k in 0..40 {
            let t = Instant::now();
            let seq = c.send("dabs", json!({"dabs": [dab(k)]})).await;
            let (_, frames) = c.status(seq).await;
            assert!(frames >= 1);
            dab_ms.push(t.elapsed().as_secs_f64() * 1e3);
        }
        // Dabs per second: 300 dabs as fast as the page could send them.
        let t = Instant::now();
        let mut last = 0;
        for k in 0..300 {
            last = c.send("dabs", json!({"dabs": [dab(1000 + k)]})).await;
        }
        c.status(last).await;
        let dabs_per_s = 300.0 / t.elapsed().as_secs_f64();
        let seq = c.send("end", json!({})).await;
        c.status(seq).await;

        // 50 strokes of 20 dabs a quarter radius apart (each 5 radii, 5 %
        // of the diagonal, long): undo memory against the colours'. Their
        // 150 messages come right after the 340 above: first let the
        // server's rate limit (200 a second, bursts of 400) fill up again,
        // as a page's pause between gestures would.
        tokio::time::sleep(Duration::from_secs(2)).await;
        let mut status = Value::Null;
        for s in 0..50 {
            let seq = c.send("begin", json!({"brush": brush})).await;
            c.status(seq).await;
            let start = positions[(s * 7919) % positions.len()];
            let dabs: Vec<Value> = (0..20)
                .map(|k| {
                    let p = start + glam::Vec3::new(0.25 * radius * k as f32, 0.0, 0.0);
                    json!([p.x, p.y, p.z, radius, 1.0])
                })
                .collect();
            c.send("dabs", json!({"dabs": dabs})).await;
            let seq = c.send("end", json!({})).await;
            status = c.status(seq).await.0;
        }
        let undo_share = status["undo_memory"].as_f64().unwrap() / status["memory"].as_f64().unwrap();

        // The detail brush on about 1,000 faces: the radius that reaches
        // the 1,000 faces nearest a vertex.
        let centre = positions[0];
        let mut d: Vec<f32> = faces
            .iter()
            .map(|f| {
                f.iter()
                    .map(|&v| positions[v as usize].distance(centre))
                    .fold(f32::INFINITY, f32::min)
            })
            .collect();
        d.sort_by(f32::total_cmp);
        let reach = d[999.min(d.len() - 1)];
        let mut detail_ms = Vec::new();
        for _ in 0..9 {
            let t = Instant::now();
            let seq = c
                .send("detail", json!({"center": centre.to_array(), "radius": reach, "levels": 1}))
                .await;
            c.status(seq).await;
            detail_ms.push(t.elapsed().as_secs_f64() * 1e3);
            let seq = c.send("undo", json!({})).await;
            c.status(seq).await;
        }
        running.stop().await.unwrap();

        let rebuild = median((0..5).map(|_| rebuild_ms(&colors_start)).collect());
        let (dab, detail) = (median(dab_ms), median(detail_ms));
        println!("`trilux paint` server, {name}: {samples} samples, {} faces (load {}).\n", faces.len(), load());
        println!("| row | trilux paint | rebuild (new pyramid + texture), same run | target |");
        println!("|---|---|---|---|");
        println!("| dab → its texels and status | {dab:.1} ms | {rebuild:.1} ms ({:.0}×) | ≤ 33 ms with upload and draw |", rebuild / dab);
        println!("| dabs applied per second in a stroke | {dabs_per_s:.0} /s | {:.0} /s | ≥ 60 /s |", 1000.0 / rebuild);
        println!("| detail brush, ~1,000 faces up one level | {detail:.1} ms | {rebuild:.1} ms | ≤ 50 ms |");
        println!("| undo memory of 50 strokes / colours | {:.1} % | — | ≤ 10 % |", 100.0 * undo_share);
        let (stroke, points, scatter_all) = scatter;
        println!("| density stroke → its points frame received, {points} points | {stroke:.1} ms | {scatter_all:.1} ms (a new scatter of every face, {:.0}×) | ≤ 100 ms with the page's upload and draw |", scatter_all / stroke);
    });
}

/// The machine's load averages.
fn load() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .unwrap_or_default()
        .split_whitespace()
        .take(3)
        .collect::<Vec<_>>()
        .join(" ")
}
