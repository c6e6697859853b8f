//! `trilux view`: interactive TransCut in the browser — a local server
//! (axum on tokio) over a [`tet_diffusion::Session`], and a page of a few
//! dependency-free ES modules compiled into the binary.
//!
//! Security, because it runs on users' machines: it binds `127.0.0.1`
//! unless told otherwise; every HTTP and WebSocket request must carry the
//! random token in its path (`/TOKEN/…`), and the `Host` and `Origin`
//! headers must name this server, so that another page in the same
//! browser cannot drive it (cross-site WebSocket hijacking, DNS
//! rebinding); files are served only from the binary; messages are
//! limited in size (64 KiB) and rate (per connection); a bad message gets
//! a JSON error naming the field and changes nothing; exports are atomic
//! and never replace a file unless the page says the user confirmed.
//!
//! The protocol is in [`protocol`]; the session file in [`session_file`].

use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use axum::Router;
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::{Path as UrlPath, State};
use axum::http::{HeaderMap, StatusCode, header};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use serde_json::{Value, json};
use tet_diffusion::glam::DVec3;
use tet_diffusion::{Log, Object, Session, SessionOptions};
use tokio::sync::{broadcast, watch};

pub mod builtin;
pub mod protocol;
pub mod session_file;
mod worker;

use protocol::{ExportKind, Request};

/// Largest message from the page.
pub const MAX_MESSAGE: usize = 64 * 1024;
/// Messages per second a connection may send on average, and in a burst.
pub const RATE: (f64, f64) = (200.0, 400.0);

/// A message to the page.
#[derive(Debug, Clone)]
pub enum Out {
    /// JSON.
    Text(String),
    /// A binary frame.
    Binary(Arc<Vec<u8>>),
}

/// Writes what the page asks to export other than the session file and
/// the glTF surface (which the server writes itself, with the library's
/// writers): pictures as `trilux diffuse` renders them, VTU, tet meshes.
/// The binary supplies it.
pub trait Exporter: Send + 'static {
    /// Writes `kind` of `session` to `path` (`size` pixels, seen from
    /// `view`), atomically, refusing an existing file unless `overwrite`.
    ///
    /// # Errors
    /// A message for the page.
    fn export(
        &self,
        session: &Session,
        kind: ExportKind,
        path: &std::path::Path,
        size: u32,
        view: Option<DVec3>,
        overwrite: bool,
    ) -> Result<(), String>;
}

/// How to serve.
#[derive(Debug, Clone)]
pub struct Options {
    /// Address to bind (127.0.0.1 by default).
    pub host: IpAddr,
    /// Port (0: any free one).
    pub port: u16,
    /// The token (random when `None`).
    pub token: Option<String>,
    /// Folder exports are written to.
    pub export_dir: PathBuf,
    /// The session's options.
    pub session: SessionOptions,
    /// The environment maps a replayed log uses, with their files (from
    /// [`session_file::from_json_in`]).
    pub environments: session_file::EnvFiles,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            host: IpAddr::from([127, 0, 0, 1]),
            port: 0,
            token: None,
            export_dir: PathBuf::from("."),
            session: SessionOptions::default(),
            environments: Vec::new(),
        }
    }
}

/// A running server.
#[derive(Debug)]
pub struct Running {
    /// Where it listens.
    pub addr: SocketAddr,
    /// The token every request needs.
    pub token: String,
    stop: watch::Sender<bool>,
    task: tokio::task::JoinHandle<std::io::Result<()>>,
}

impl Running {
    /// The page's URL.
    pub fn url(&self) -> String {
        format!("http://{}/{}/", self.addr, self.token)
    }

    /// Stops the server (open pages are disconnected) and waits for it.
    ///
    /// # Errors
    /// The server's I/O error, if it failed.
    pub async fn stop(self) -> std::io::Result<()> {
        let _ = self.stop.send(true);
        self.task.await.unwrap_or(Ok(()))
    }

    /// Waits until the server stops (Ctrl+C when `ctrl_c`).
    ///
    /// # Errors
    /// The server's I/O error.
    pub async fn wait(self, ctrl_c: bool) -> std::io::Result<()> {
        if ctrl_c {
            tokio::signal::ctrl_c().await?;
            self.stop().await
        } else {
            self.task.await.unwrap_or(Ok(()))
        }
    }
}

#[derive(Clone)]
struct Shared {
    token: Arc<str>,
    /// `host:port` values a request's Host may have.
    hosts: Arc<Vec<String>>,
    /// Bound to every interface (0.0.0.0 or ::): the port with which any
    /// IP-literal Host is also accepted, since a user on another machine
    /// types one of this machine's addresses, which the server does not
    /// list. A DNS-rebinding page always sends a host *name*, so this
    /// does not let one in.
    any_ip_port: Option<u16>,
    requests: mpsc::Sender<(u64, Request)>,
    cancel: Arc<AtomicBool>,
    out: broadcast::Sender<Out>,
    latest: Arc<Mutex<worker::Latest>>,
    stop: watch::Receiver<bool>,
}

/// A random 128-bit token, hex.
///
/// # Errors
/// When the operating system gives no randomness.
pub fn random_token() -> std::io::Result<String> {
    let mut bytes = [0u8; 16];
    getrandom::fill(&mut bytes).map_err(|e| std::io::Error::other(e.to_string()))?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

/// Starts a server on a session of `object`, replaying `log` first when
/// given. `source` describes how the object was made (written into
/// session files).
///
/// # Errors
/// Binding the address, the token, or the first solve / the replay.
pub async fn start(
    object: Object,
    source: Value,
    log: Option<Log>,
    options: Options,
    exporter: Box<dyn Exporter>,
) -> Result<Running, String> {
    let token = match options.token.clone() {
        Some(t) => t,
        None => random_token().map_err(|e| format!("no random token: {e}"))?,
    };
    // Bound before the first solve, so that a port in use is reported at
    // once, not after a large mesh's solve.
    let listener = tokio::net::TcpListener::bind((options.host, options.port))
        .await
        .map_err(|e| {
            let why = match e.kind() {
                // Most often a trilux view still running from before.
                std::io::ErrorKind::AddrInUse => format!(
                    "port {} is in use (another trilux view?); choose another --port, or leave --port out for a free one",
                    options.port
                ),
                std::io::ErrorKind::AddrNotAvailable => {
                    "not an address of this machine (--host)".to_string()
                }
                _ => e.to_string(),
            };
            format!("{}:{}: {why}", options.host, options.port)
        })?;
    let session_options = options.session;
    let session = tokio::task::spawn_blocking(move || open_session(object, session_options, log))
        .await
        .map_err(|e| e.to_string())??;
    let addr = listener.local_addr().map_err(|e| e.to_string())?;
    let hosts = allowed_hosts(options.host, addr);
    let (requests, receiver) = mpsc::channel();
    let (out, _) = broadcast::channel(256);
    let cancel = Arc::new(AtomicBool::new(false));
    let latest = Arc::new(Mutex::new(worker::Latest::default()));
    let white = white_point(&session);
    let w = worker::Worker {
        session,
        requests: receiver,
        cancel: cancel.clone(),
        out: out.clone(),
        latest: latest.clone(),
        exporter,
        export_dir: options.export_dir.clone(),
        source,
        white,
        envs: options.environments.clone(),
    };
    std::thread::Builder::new()
        .name("trilux-view-session".into())
        .spawn(move || w.run())
        .map_err(|e| e.to_string())?;
    let (stop, stop_rx) = watch::channel(false);
    let shared = Shared {
        token: token.clone().into(),
        hosts: Arc::new(hosts),
        any_ip_port: options.host.is_unspecified().then_some(addr.port()),
        requests,
        cancel,
        out,
        latest,
        stop: stop_rx.clone(),
    };
    let app = router(shared);
    let mut stopped = stop_rx;
    let task = tokio::spawn(async move {
        axum::serve(listener, app)
            .with_graceful_shutdown(async move {
                let _ = stopped.wait_for(|s| *s).await;
            })
            .await
    });
    Ok(Running {
        addr,
        token,
        stop,
        task,
    })
}

/// The session the server edits: `object` as it is, or after replaying
/// a session file's `log` (an edit that fails names its index).
fn open_session(
    object: Object,
    options: SessionOptions,
    log: Option<Log>,
) -> Result<Session, String> {
    match log {
        Some(log) => Session::replay(object, options, &log)
            .map_err(|(k, e)| format!("the session file's edit {k}: {e}")),
        None => Session::new(object, options).map_err(|e| e.to_string()),
    }
}

/// The `Host` headers a request may carry: the bound address, and on a
/// loopback address its other loopback names (a DNS-rebinding page
/// sends its own host name, which is never in this list).
fn allowed_hosts(host: IpAddr, addr: SocketAddr) -> Vec<String> {
    let mut hosts = vec![addr.to_string()];
    // On every interface the loopback names reach it too.
    if host.is_loopback() || host.is_unspecified() {
        hosts.push(format!("localhost:{}", addr.port()));
        hosts.push(format!("127.0.0.1:{}", addr.port()));
        hosts.push(format!("[::1]:{}", addr.port()));
    }
    hosts
}

/// The routes: everything under the token; the rest is 404.
fn router(shared: Shared) -> Router {
    Router::new()
        .route("/{token}/ws", get(websocket))
        .route("/{token}/", get(index))
        .route("/{token}", get(slash))
        .route("/{token}/{file}", get(asset))
        .fallback(not_found)
        .with_state(shared)
}

/// The exposure's white point: the 99th percentile of the surface
/// vertices' luminance (the CLI's PNGs use the 99th percentile of the
/// covered pixels'), fixed for the session.
fn white_point(session: &Session) -> f64 {
    let mut lum: Vec<f64> = session
        .pieces()
        .iter()
        .flat_map(|o| o.radiance(None))
        .map(|l| 0.2126 * l[0] + 0.7152 * l[1] + 0.0722 * l[2])
        .filter(|l| *l > 0.0)
        .collect();
    lum.sort_by(f64::total_cmp);
    lum.get(lum.len() * 99 / 100)
        .copied()
        .unwrap_or(1.0)
        .max(1e-12)
}

/// The body of a request without the token or with a wrong one: still a
/// 404 (the token stays unguessable and is not revealed), but one that
/// tells a user who typed or bookmarked a shortened address what to do.
pub const NEEDS_TOKEN: &str = "trilux view: this address needs the full URL trilux printed when it \
started (it holds a secret token); copy that URL, or restart trilux view for a new one\n";

async fn not_found() -> Response {
    (StatusCode::NOT_FOUND, NEEDS_TOKEN).into_response()
}

/// Equal in constant time (the token must not leak through timing).
fn same(a: &str, b: &str) -> bool {
    a.len() == b.len()
        && a.bytes()
            .zip(b.bytes())
            .fold(0u8, |acc, (x, y)| acc | (x ^ y))
            == 0
}

/// The body of a 403 for a foreign `Host`: what a user who reached the
/// server by a host name (not an address) should do.
pub const WRONG_HOST: &str = "trilux view: wrong Host header; open the page by the address \
trilux printed (or, when it listens on every interface, by one of this machine's IP addresses), \
not by a host name\n";

/// Whether `host` (`host:port`, from a `Host` or `Origin` header) names
/// this server.
fn allowed_host(s: &Shared, host: &str) -> bool {
    s.hosts.iter().any(|h| h == host)
        || s.any_ip_port
            .is_some_and(|port| host.parse::<SocketAddr>().is_ok_and(|a| a.port() == port))
}

/// The token, `Host` and `Origin` checks every request passes.
fn check(s: &Shared, token: &str, headers: &HeaderMap) -> Result<(), (StatusCode, &'static str)> {
    if !same(token, &s.token) {
        return Err((StatusCode::NOT_FOUND, NEEDS_TOKEN));
    }
    let host = headers
        .get(header::HOST)
        .and_then(|h| h.to_str().ok())
        .unwrap_or_default();
    if !allowed_host(s, host) {
        return Err((StatusCode::FORBIDDEN, WRONG_HOST));
    }
    if let Some(origin) = headers.get(header::ORIGIN) {
        let ok = origin
            .to_str()
            .ok()
            .and_then(|o| o.strip_prefix("http://"))
            .is_some_and(|o| allowed_host(s, o));
        if !ok {
            return Err((StatusCode::FORBIDDEN, "foreign Origin"));
        }
    }
    Ok(())
}

/// The page's files, compiled in.
const FILES: [(&str, &str, &str); 6] = [
    (
        "index.html",
        "text/html; charset=utf-8",
        include_str!("page/index.html"),
    ),
    (
        "style.css",
        "text/css; charset=utf-8",
        include_str!("page/style.css"),
    ),
    (
        "app.js",
        "text/javascript; charset=utf-8",
        include_str!("page/app.js"),
    ),
    (
        "gl.js",
        "text/javascript; charset=utf-8",
        include_str!("page/gl.js"),
    ),
    (
        "camera.js",
        "text/javascript; charset=utf-8",
        include_str!("page/camera.js"),
    ),
    (
        "net.js",
        "text/javascript; charset=utf-8",
        include_str!("page/net.js"),
    ),
];

fn file(name: &str) -> Response {
    match FILES.iter().find(|f| f.0 == name) {
        Some((_, mime, body)) => (
            [
                (header::CONTENT_TYPE, *mime),
                (header::CACHE_CONTROL, "no-store"),
                (header::X_CONTENT_TYPE_OPTIONS, "nosniff"),
                (
                    header::CONTENT_SECURITY_POLICY,
                    "default-src 'self'; connect-src 'self'; img-src 'self' blob: data:",
                ),
            ],
            *body,
        )
            .into_response(),
        None => (StatusCode::NOT_FOUND, "not found").into_response(),
    }
}

async fn index(
    State(s): State<Shared>,
    UrlPath(token): UrlPath<String>,
    headers: HeaderMap,
) -> Response {
    match check(&s, &token, &headers) {
        Ok(()) => file("index.html"),
        Err(r) => r.into_response(),
    }
}

/// `/TOKEN` → `/TOKEN/`, so that the page's relative imports resolve.
async fn slash(
    State(s): State<Shared>,
    UrlPath(token): UrlPath<String>,
    headers: HeaderMap,
) -> Response {
    match check(&s, &token, &headers) {
        Ok(()) => axum::response::Redirect::permanent(&format!("/{token}/")).into_response(),
        Err(r) => r.into_response(),
    }
}

async fn asset(
    State(s): State<Shared>,
    UrlPath((token, name)): UrlPath<(String, String)>,
    headers: HeaderMap,
) -> Response {
    match check(&s, &token, &headers) {
        Ok(()) => file(&name),
        Err(r) => r.into_response(),
    }
}

async fn websocket(
    State(s): State<Shared>,
    UrlPath(token): UrlPath<String>,
    headers: HeaderMap,
    ws: WebSocketUpgrade,
) -> Response {
    if let Err(r) = check(&s, &token, &headers) {
        return r.into_response();
    }
    // A page always sends Origin with a WebSocket; one without is not a page.
    if !headers.contains_key(header::ORIGIN) {
        return (StatusCode::FORBIDDEN, "missing Origin").into_response();
    }
    // Uploads (environment maps) are the only large messages; text is
    // held to MAX_MESSAGE below.
    ws.max_message_size(protocol::MAX_UPLOAD)
        .max_frame_size(protocol::MAX_UPLOAD)
        .on_upgrade(move |socket| client(socket, s))
}

/// The state a new page starts from.
fn latest_messages(s: &Shared) -> Vec<Out> {
    let l = s
        .latest
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let mut out = Vec::new();
    if let Some(h) = &l.hello {
        out.push(Out::Text(h.clone()));
    }
    out.extend(l.surfaces.iter().cloned().map(Out::Binary));
    out.extend(l.radiance.iter().cloned().map(Out::Binary));
    if let Some(st) = &l.status {
        out.push(Out::Text(st.clone()));
    }
    out
}

fn to_message(o: Out) -> Message {
    match o {
        Out::Text(t) => Message::Text(t.into()),
        Out::Binary(b) => Message::Binary(b.as_ref().clone().into()),
    }
}

fn error_text(seq: Option<u64>, field: &str, message: &str) -> Message {
    Message::Text(
        json!({"type": "error", "seq": seq, "field": field, "message": message})
            .to_string()
            .into(),
    )
}

/// Resolves when the server is asked to stop.
async fn stopped(mut stop: watch::Receiver<bool>) {
    let _ = stop.wait_for(|s| *s).await;
}

/// One page's connection: requests up to the session's thread, its
/// frames down. Closing it leaves the session as it is.
async fn client(mut socket: WebSocket, s: Shared) {
    let mut frames = s.out.subscribe();
    if let Flow::Close = send_all(&mut socket, latest_messages(&s)).await {
        return;
    }
    let stop = stopped(s.stop.clone());
    tokio::pin!(stop);
    let mut bucket = Bucket::full();
    loop {
        let flow = tokio::select! {
            () = &mut stop => {
                let _ = socket.send(Message::Close(None)).await;
                Flow::Close
            }
            incoming = socket.recv() => match incoming {
                Some(Ok(message)) => receive(&mut socket, &s, message, &mut bucket).await,
                _ => Flow::Close,
            },
            frame = frames.recv() => match frame {
                Ok(m) => send_all(&mut socket, vec![m]).await,
                // Too slow for the stream: catch up with the latest state.
                Err(broadcast::error::RecvError::Lagged(_)) => {
                    send_all(&mut socket, latest_messages(&s)).await
                }
                Err(broadcast::error::RecvError::Closed) => Flow::Close,
            },
        };
        if let Flow::Close = flow {
            return;
        }
    }
}

/// Whether a connection goes on after one message in or out.
enum Flow {
    Continue,
    Close,
}

/// The per-connection rate limit: a token bucket refilled at `RATE.0`
/// messages per second up to `RATE.1`.
struct Bucket {
    tokens: f64,
    refilled: Instant,
}

impl Bucket {
    fn full() -> Self {
        Bucket {
            tokens: RATE.1,
            refilled: Instant::now(),
        }
    }

    /// Takes a token; false when the client is over the limit.
    fn take(&mut self) -> bool {
        let now = Instant::now();
        let refill = now.duration_since(self.refilled).as_secs_f64() * RATE.0;
        self.tokens = (self.tokens + refill).min(RATE.1);
        self.refilled = now;
        if self.tokens < 1.0 {
            return false;
        }
        self.tokens -= 1.0;
        true
    }
}

/// One message from the page: an edit is queued for the session worker
/// (cancelling its refinement); anything wrong is answered with an error
/// frame naming the field, and the connection goes on. Binary messages
/// (uploads) are not rate-limited: they are size-checked instead.
async fn receive(
    socket: &mut WebSocket,
    s: &Shared,
    message: Message,
    bucket: &mut Bucket,
) -> Flow {
    let text = match message {
        Message::Text(t) if t.len() > MAX_MESSAGE => {
            let problem = format!(
                "{} bytes: a text message may have at most {MAX_MESSAGE}",
                t.len()
            );
            return reply(socket, error_text(None, "(message)", &problem)).await;
        }
        Message::Text(t) => t,
        Message::Close(_) => return Flow::Close,
        Message::Ping(_) | Message::Pong(_) => return Flow::Continue,
        Message::Binary(b) => {
            return match protocol::parse_upload(&b) {
                Ok(edit) => submit(s, edit),
                Err(bad) => reply(socket, error_text(None, &bad.field, &bad.problem)).await,
            };
        }
    };
    // The sequence number of a message refused as a whole, when it has one.
    let seq = || {
        serde_json::from_str::<Value>(&text)
            .ok()
            .as_ref()
            .and_then(protocol::seq_of)
    };
    if !bucket.take() {
        let dropped = error_text(seq(), "(rate)", "too many messages; this one was dropped");
        return reply(socket, dropped).await;
    }
    match protocol::parse(&text) {
        Ok(edit) => submit(s, edit),
        Err(bad) => reply(socket, error_text(seq(), &bad.field, &bad.problem)).await,
    }
}

/// Queues an edit for the session worker, cancelling its refinement.
fn submit(s: &Shared, edit: (u64, Request)) -> Flow {
    s.cancel.store(true, Ordering::SeqCst);
    match s.requests.send(edit) {
        Ok(()) => Flow::Continue,
        Err(_) => Flow::Close,
    }
}

async fn reply(socket: &mut WebSocket, message: Message) -> Flow {
    match socket.send(message).await {
        Ok(()) => Flow::Continue,
        Err(_) => Flow::Close,
    }
}

async fn send_all(socket: &mut WebSocket, messages: Vec<Out>) -> Flow {
    for m in messages {
        if let Flow::Close = reply(socket, to_message(m)).await {
            return Flow::Close;
        }
    }
    Flow::Continue
}
