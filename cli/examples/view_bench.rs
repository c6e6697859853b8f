//! The `trilux view` benchmark: drives the server through its protocol
//! (a WebSocket client in this process, like the page) and prints one
//! Markdown table, medians of `--edits` edits (20 by default), with the
//! same edit through `trilux diffuse`'s batch path (assemble, edit and
//! solve from scratch) in the same run as the baseline; the undo memory
//! is that of 20 paint steps whatever `--edits` is.
//!
//! ```sh
//! TRILUX_DATA=../shared/data cargo run --release -p trilux --example view_bench
//! cargo run --release -p trilux --example view_bench -- --edits 5 --only ball
//! ```
//!
//! Meshes: `tets/bunny_50k.node`, the built-in ball at 105 456 tets (the
//! "about 100k" row; made in code), `tets/bunny_500k.node`.

use std::time::{Duration, Instant};

use futures_util::{SinkExt, StreamExt};
use serde_json::{Value, json};
use tet_diffusion::glam::DVec3;
use tet_diffusion::{Light, Medium, Object, Session, Stroke};
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;
use trilux::view::protocol::{self, ExportKind};

type Socket =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

struct NoExport;

impl trilux::view::Exporter for NoExport {
    fn export(
        &self,
        _: &Session,
        _: ExportKind,
        _: &std::path::Path,
        _: u32,
        _: Option<DVec3>,
        _: bool,
    ) -> Result<(), String> {
        Err("the benchmark exports nothing".into())
    }
}

/// What arrives for an edit.
#[derive(Debug, Default, Clone, Copy)]
struct Arrivals {
    surface: Option<f64>,
    coarse: Option<f64>,
    refined: Option<f64>,
    status: Option<f64>,
}

struct Client {
    socket: Socket,
    seq: u64,
    last_status: Value,
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

    /// Reads until the edit `seq` has its refined radiance (or, with
    /// `status_only`, its status), timing each arrival from `start`.
    /// Panics on an error frame: only [`Client::try_follow`]'s callers
    /// know which refusals are expected.
    async fn follow(&mut self, seq: u64, start: Instant, status_only: bool) -> Arrivals {
        match self.try_follow(seq, start, status_only).await {
            Ok(a) => a,
            Err(v) => panic!("the server refused edit {seq}: {v}"),
        }
    }

    /// [`Client::follow`], with the server's error frame for `seq` (or
    /// any other error frame) returned instead of a panic.
    async fn try_follow(
        &mut self,
        seq: u64,
        start: Instant,
        status_only: bool,
    ) -> Result<Arrivals, Value> {
        let mut a = Arrivals::default();
        let ms = |start: Instant| start.elapsed().as_secs_f64() * 1e3;
        loop {
            let m = tokio::time::timeout(Duration::from_secs(600), self.socket.next())
                .await
                .expect("an answer within 10 minutes")
                .expect("open")
                .expect("no error");
            match m {
                Message::Binary(b) => {
                    let flags = b[6];
                    let tag = u32::from_le_bytes(b[12..16].try_into().unwrap_or_default());
                    if b[5] == protocol::SURFACE {
                        a.surface.get_or_insert(ms(start));
                    } else if flags & protocol::FINAL != 0 {
                        if a.status.is_some() {
                            a.refined = Some(ms(start));
                            a.coarse.get_or_insert(ms(start));
                        }
                    } else if tag as u64 == seq {
                        a.coarse.get_or_insert(ms(start));
                    }
                }
                Message::Text(t) => {
                    let v: Value = serde_json::from_str(&t).unwrap_or_default();
                    if v["type"] == "error" {
                        return Err(v);
                    }
                    if v["type"] == "status" {
                        let ours = v["seqs"]
                            .as_array()
                            .is_some_and(|s| s.contains(&json!(seq)));
                        if ours {
                            a.status = Some(ms(start));
                            if !v["coarse"].as_bool().unwrap_or(true) {
                                a.refined.get_or_insert(ms(start));
                                a.coarse.get_or_insert(ms(start));
                            }
                        }
                        self.last_status = v;
                        if status_only && a.status.is_some() {
                            return Ok(a);
                        }
                    }
                }
                _ => {}
            }
            if a.refined.is_some() {
                return Ok(a);
            }
        }
    }
}

/// Whether an error frame is the exact cut's refusal of a plane that
/// would make a sliver past the dihedral-angle bound: the server's
/// documented answer to an unlucky plane, not a failure of the bench.
fn angle_refusal(error: &Value) -> bool {
    let m = error["message"].as_str().unwrap_or("");
    m.contains("dihedral angle") && m.contains("cut a little elsewhere")
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        f64::NAN
    } else {
        v[v.len() / 2]
    }
}

fn load(name: &str) -> Option<Object> {
    let marble = Medium::measured("marble").ok()?;
    let mut object = if name == "ball" {
        let mut o = trilux::view::builtin::object(26).ok()?;
        let n = o.media().len();
        o = Object::new(o.mesh().clone(), 1.0, vec![marble; n], 1.3).ok()?;
        o
    } else {
        let dir = std::env::var("TRILUX_DATA").ok()?;
        let path = std::path::Path::new(&dir)
            .join("tets")
            .join(format!("{name}.node"));
        let t = trilux_io::tet::TetMesh::read(&path).ok()?;
        let mesh = tet_diffusion::TetMesh::new(&t.positions, &t.tets).ok()?;
        Object::homogeneous(mesh, 1000.0, marble, 1.3).ok()?
    };
    object
        .add_light(Light::Directional {
            to_light: DVec3::new(0.4, 1.0, 0.7),
            irradiance: [1.0; 3],
        })
        .ok()?;
    Some(object)
}

fn surface_point(o: &Object, k: usize) -> DVec3 {
    let b = o.mesh().boundary_vertices();
    o.mesh().positions()[b[(k * 7919) % b.len()] as usize]
}

/// Paint steps whose undo memory is reported (the issue's figure).
const MEMORY_PAINTS: usize = 20;

/// What `trilux diffuse` does for the same edit, from scratch: assemble,
/// light, edit, solve (medians of 3), ms: `[paint, light, cut]`.
fn baselines(object: &Object, point: DVec3, size: f64, z: f64) -> Option<[f64; 3]> {
    let fresh = || -> Option<Object> {
        let mut o = Object::new(
            object.mesh().clone(),
            object.length_unit_mm(),
            object.media().to_vec(),
            1.3,
        )
        .ok()?;
        o.add_light(Light::Directional {
            to_light: DVec3::new(0.4, 1.0, 0.7),
            irradiance: [1.0; 3],
        })
        .ok()?;
        Some(o)
    };
    let time = |edit: &dyn Fn(&mut Object) -> Option<()>| -> Option<f64> {
        let mut runs = Vec::new();
        for _ in 0..3 {
            let t = Instant::now();
            let mut o = fresh()?;
            edit(&mut o)?;
            o.solve().ok()?;
            runs.push(t.elapsed().as_secs_f64() * 1e3);
        }
        Some(median(runs))
    };
    let paint = time(&|o| {
        o.paint(&Stroke {
            points: vec![point],
            radius: size * 0.03,
            medium: Medium::measured("ketchup").ok()?,
            strength: 1.0,
        })
        .ok()
        .map(|_| ())
    })?;
    let light = time(&|_| Some(()))?;
    let cut = time(&|o| {
        let plane = tet_diffusion::Cut::Plane {
            point: DVec3::new(0.0, 0.0, z),
            normal: DVec3::new(0.1, 0.0, 1.0),
        };
        o.cut(&plane, tet_diffusion::CutMethod::Exact)
            .ok()
            .map(|_| ())
    })?;
    Some([paint, light, cut])
}

async fn connect(running: &trilux::view::Running) -> Option<Client> {
    let mut request = format!("ws://{}/{}/ws", running.addr, running.token)
        .into_client_request()
        .ok()?;
    request
        .headers_mut()
        .insert("Origin", format!("http://{}", running.addr).parse().ok()?);
    let (socket, _) = tokio_tungstenite::connect_async(request).await.ok()?;
    let mut c = Client {
        socket,
        seq: 0,
        last_status: Value::Null,
    };
    // The hello's status, then wait until the first solve is refined.
    let s = c.send("hello", json!({})).await;
    c.follow(s, Instant::now(), true).await;
    Some(c)
}

/// Paints (first results, ms), the undo memory of [`MEMORY_PAINTS`]
/// paints against the object, and undos of paints (ms).
async fn paints(
    c: &mut Client,
    points: &[DVec3],
    size: f64,
    edits: usize,
) -> (Vec<f64>, f64, Vec<f64>) {
    let mut paint = Vec::new();
    for (k, &p) in points.iter().enumerate() {
        let t = Instant::now();
        let s = c
            .send(
                "paint",
                json!({"material": if k % 2 == 0 { "ketchup" } else { "skin1" },
                "radius": size * 0.03, "strength": 1.0, "points": [p.to_array()]}),
            )
            .await;
        let first = c.follow(s, t, false).await.coarse.unwrap_or(f64::NAN);
        if k < edits {
            paint.push(first);
        }
    }
    let object = c.last_status["object_bytes"].as_f64().unwrap_or(1.0);
    let memory = c.last_status["undo_bytes"].as_f64().unwrap_or(0.0) / object;
    eprintln!(
        "undo memory of {} paints: {} of {object} bytes",
        points.len(),
        c.last_status["undo_parts"]
    );
    let mut undo = Vec::new();
    for _ in 0..edits.min(points.len()) {
        let t = Instant::now();
        let s = c.send("undo", json!({})).await;
        undo.push(c.follow(s, t, true).await.status.unwrap_or(f64::NAN));
    }
    (paint, memory, undo)
}

fn light_message(a: f64) -> Value {
    json!({"lights": [{"kind": "dir", "dir": [a.cos(), 1.0, a.sin()]}]})
}

/// Light changes (first results, ms) and a drag's drawn updates per
/// second (60 messages per second for 3 s).
async fn lights(c: &mut Client, edits: usize) -> (Vec<f64>, f64) {
    let mut light = Vec::new();
    for k in 0..edits {
        let t = Instant::now();
        let s = c
            .send("lights", light_message(k as f64 / edits as f64 * 6.0))
            .await;
        light.push(c.follow(s, t, false).await.coarse.unwrap_or(f64::NAN));
    }
    let drag_start = Instant::now();
    let mut frames = 0usize;
    let mut sent = 0usize;
    let mut next = Instant::now();
    while drag_start.elapsed() < Duration::from_secs(3) {
        if Instant::now() >= next {
            c.send("lights", light_message(sent as f64 * 0.05)).await;
            sent += 1;
            next += Duration::from_millis(16);
        }
        if let Ok(Some(Ok(Message::Binary(b)))) =
            tokio::time::timeout(Duration::from_millis(4), c.socket.next()).await
            && b[5] == protocol::RADIANCE
        {
            frames += 1;
        }
    }
    let rate = frames as f64 / drag_start.elapsed().as_secs_f64();
    let s = c.send("hello", json!({})).await;
    c.follow(s, Instant::now(), true).await;
    (light, rate)
}

/// Cuts (new surface shown, converged) and their undos, ms, and how many
/// planes the exact cut refused by its angle bound (skipped: nothing to
/// time or undo; noted on stderr).
async fn cuts(c: &mut Client, zs: &[f64]) -> ([Vec<f64>; 3], usize) {
    let [mut shown, mut done, mut undo] = [Vec::new(), Vec::new(), Vec::new()];
    let mut refused = 0;
    for &z in zs {
        let t = Instant::now();
        let s = c
            .send(
                "cut",
                json!({"plane": {"point": [0.0, 0.0, z], "normal": [0.1, 0.0, 1.0]}}),
            )
            .await;
        let a = match c.try_follow(s, t, false).await {
            Ok(a) => a,
            Err(e) if angle_refusal(&e) => {
                eprintln!("cut at z = {z} refused (skipped): {}", e["message"]);
                refused += 1;
                continue;
            }
            Err(e) => panic!("the server refused cut {s}: {e}"),
        };
        shown.push(a.surface.unwrap_or(f64::NAN));
        done.push(a.refined.unwrap_or(f64::NAN));
        let t = Instant::now();
        let s = c.send("undo", json!({})).await;
        undo.push(c.follow(s, t, true).await.status.unwrap_or(f64::NAN));
    }
    ([shown, done, undo], refused)
}

async fn bench(name: &str, edits: usize) -> Option<Vec<String>> {
    let object = load(name)?;
    let tets = object.mesh().tets().len();
    let (lo, hi) = object
        .mesh()
        .positions()
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &p| {
            (a.min(p), b.max(p))
        });
    let size = (hi - lo).length();
    let points: Vec<DVec3> = (0..edits.max(MEMORY_PAINTS))
        .map(|k| surface_point(&object, k))
        .collect();
    let zs: Vec<f64> = (0..edits)
        .map(|k| lo.z + (hi.z - lo.z) * (0.55 + 0.3 * k as f64 / edits as f64))
        .collect();
    let base = baselines(&object, points[0], size, zs[0])?;
    let running = trilux::view::start(
        object,
        json!({"mesh": name}),
        None,
        trilux::view::Options::default(),
        Box::new(NoExport),
    )
    .await
    .ok()?;
    let mut c = connect(&running).await?;
    let (paint, memory, undo_paint) = paints(&mut c, &points, size, edits).await;
    let (light, drag_rate) = lights(&mut c, edits).await;
    let ([cut_shown, cut_done, undo_cut], refused) = cuts(&mut c, &zs).await;
    running.stop().await.ok()?;
    let f = |x: f64| format!("{x:.0}");
    let diffuse = |x: f64| format!("{} (diffuse: assemble + edit + solve)", f(x));
    Some(vec![
        format!(
            "| {name} ({tets} tets) | paint: first result, ms | {} | {} |",
            f(median(paint)),
            diffuse(base[0])
        ),
        format!(
            "| {name} | light: first result, ms | {} | {} |",
            f(median(light)),
            diffuse(base[1])
        ),
        format!(
            "| {name} | light drag, drawn updates/s | {drag_rate:.1} | {:.1} (diffuse) |",
            1e3 / base[1]
        ),
        format!(
            "| {name} | cut: shown / converged, ms{} | {} / {} | {} |",
            if refused > 0 {
                format!(
                    " ({refused} of {} planes refused by the angle bound)",
                    zs.len()
                )
            } else {
                String::new()
            },
            f(median(cut_shown)),
            f(median(cut_done)),
            diffuse(base[2])
        ),
        format!(
            "| {name} | undo of a paint (max) / of a cut, ms | {} ({}) / {} | {} / {} (diffuse: the edit list again) |",
            f(median(undo_paint.clone())),
            f(undo_paint.iter().copied().fold(f64::NAN, f64::max)),
            f(median(undo_cut)),
            f(base[1]),
            f(base[1])
        ),
        format!(
            "| {name} | undo memory of {MEMORY_PAINTS} paints / object | {:.1} % | |",
            memory * 100.0
        ),
    ])
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut edits = 20;
    let mut only: Option<String> = None;
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--edits" => {
                edits = args.get(i + 1).and_then(|s| s.parse().ok()).unwrap_or(20);
                i += 1;
            }
            "--only" => {
                only = args.get(i + 1).cloned();
                i += 1;
            }
            other => {
                eprintln!("unknown argument {other:?} (--edits N, --only NAME)");
                std::process::exit(2);
            }
        }
        i += 1;
    }
    let runtime = match tokio::runtime::Runtime::new() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("no runtime: {e}");
            std::process::exit(1);
        }
    };
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "`trilux view` through its protocol, medians of {edits} edits (load: {})\n",
        load.trim()
    );
    println!("| mesh | edit | view | baseline |");
    println!("|---|---|---|---|");
    for name in ["bunny_50k", "ball", "bunny_500k"] {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        match runtime.block_on(bench(name, edits)) {
            Some(rows) => rows.iter().for_each(|r| println!("{r}")),
            None => println!("| {name} | skipped (set TRILUX_DATA for the data meshes) | | |"),
        }
    }
}
