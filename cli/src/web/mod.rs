//! The web core that `trilux view` (and `trilux paint`) stand on: a local
//! server (axum on tokio) for one app's state, and the app-neutral page
//! modules, compiled into the binary.
//!
//! Security, because it runs on users' machines: it binds `127.0.0.1`
//! unless told otherwise; every HTTP and WebSocket request must carry the
//! random token in its path (`/TOKEN/…`), and the `Host` and `Origin`
//! headers must name this server, so that another page in the same
//! browser cannot drive it (cross-site WebSocket hijacking, DNS
//! rebinding); files are served only from the binary; messages are
//! limited in size and rate per connection ([`Limits`]); a bad message
//! gets a JSON error naming the field and changes nothing.
//!
//! # How an app plugs in
//!
//! An app implements [`App`]: its name (in every text the core shows and
//! in its thread's name), its page files, its [`Limits`], and how a
//! message becomes its `Request` ([`App::parse`], [`App::parse_binary`]).
//! [`bind`] takes the port before the app is built (a port in use is
//! reported before a large mesh's solve), and [`Bound::serve`] moves the
//! app onto its own thread and serves it:
//!
//! - **Up.** The connection task parses each message ([`json::parse`]
//!   reads the `{"seq", "op", …}` envelope once, then [`App::parse`] the
//!   op) and queues it with a [`ReplyTo`] (the connection and the `seq`).
//!   A message refused here gets an error frame on its own connection;
//!   the app never sees it.
//! - **The app's thread** blocks on the queue while the app is idle
//!   ([`Idle::Wait`]), waits at most a while ([`Idle::WaitAtMost`], an
//!   autosave), or keeps calling [`App::idle`] while it has background
//!   work ([`Idle::Busy`], view's refinement). A queued request whose
//!   [`App::interrupts`] is true sets the `cancel` flag that background
//!   work polls. [`App::handle`] gets the first request and the
//!   [`Inbox`], from which it may take the ones already waiting
//!   (coalescing).
//! - **Down.** The [`Outbox`] publishes snapshot slots (what a page that
//!   connects later is sent first, in slot order), broadcasts, and
//!   replies to one connection.
//!
//! # Modules
//!
//! | module | what |
//! |---|---|
//! | [`guard`] | the token, `Host` and `Origin` checks and their texts |
//! | `socket` | one connection: limits, rate, error frames, snapshot, lag catch-up |
//! | `hub` | the app's thread, [`Inbox`] and [`Outbox`] |
//! | [`assets`] | the page files and their headers; the core's own files |
//! | [`frame`] | the 16-byte header of binary frames |
//! | [`json`] | the message envelope, [`json::BadField`] and validators |

use std::net::{IpAddr, SocketAddr};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use axum::body::Bytes;
use axum::serve::ListenerExt;
use tokio::sync::watch;

pub mod assets;
pub mod frame;
pub mod guard;
mod hub;
pub mod json;
mod socket;

pub use assets::Asset;
pub use hub::{Inbox, Outbox};
pub use json::{BadField, Incoming};

/// A connection's id, unique for the server's life.
pub type ConnId = u64;

/// Whom an answer goes to: the connection a request came on, and the
/// request's `seq` when it had one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReplyTo {
    /// The connection.
    pub conn: ConnId,
    /// The request's sequence number.
    pub seq: Option<u64>,
}

/// A message to the page.
#[derive(Debug, Clone)]
pub enum Out {
    /// JSON.
    Text(String),
    /// A binary frame (shared, not copied, by every page it goes to).
    Binary(Bytes),
}

/// How large and how frequent the page's messages may be.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Largest text message, bytes.
    pub text: usize,
    /// Largest binary message, bytes (0: none accepted).
    pub binary: usize,
    /// Messages (text or binary) per second a connection may send on
    /// average, and in a burst.
    pub rate: (f64, f64),
}

/// What the app's thread does when no request is waiting.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Idle {
    /// Block until the next request.
    Wait,
    /// Wait for the next request at most this long, then call
    /// [`App::idle`] again.
    WaitAtMost(Duration),
    /// More background work: call [`App::idle`] again at once unless a
    /// request is waiting.
    Busy,
}

/// One web app on the core: its page, its protocol and its state (which
/// lives on the app's own thread; see the [module docs](self)).
pub trait App: Send + 'static {
    /// The app's name (`view`): "trilux NAME" in the texts the core
    /// shows, and the thread's name.
    const NAME: &'static str;
    /// The app's page files; `index.html` is the page. They are served
    /// beside the core's ([`assets::CORE`]) and must not shadow one.
    const PAGE: &'static [Asset];
    /// The page's message limits.
    const LIMITS: Limits;
    /// A parsed request.
    type Request: Send + 'static;

    /// Parses a text message's op and fields (runs on the connection's
    /// task).
    ///
    /// # Errors
    /// The first bad field.
    fn parse(m: &Incoming<'_>) -> Result<Self::Request, BadField>;

    /// Parses a binary message into its `seq` and request; by default,
    /// binary messages are refused.
    ///
    /// # Errors
    /// What is wrong with it (field `(upload)` by convention).
    fn parse_binary(bytes: &[u8]) -> Result<(u64, Self::Request), BadField> {
        Err(BadField::new(
            "(upload)",
            format!("{} bytes: this page takes no binary messages", bytes.len()),
        ))
    }

    /// Whether `request` cancels the background work in progress
    /// ([`App::idle`]'s `cancel`).
    fn interrupts(request: &Self::Request) -> bool {
        let _ = request;
        true
    }

    /// Called once on the app's thread before any request: publish the
    /// state a page starts from.
    fn begin(&mut self, out: &Outbox) {
        let _ = out;
    }

    /// Handles `first`; more requests already waiting may be taken from
    /// `inbox` (to coalesce them).
    fn handle(
        &mut self,
        first: (ReplyTo, Self::Request),
        inbox: &mut Inbox<Self::Request>,
        out: &Outbox,
    );

    /// Background work while no request is waiting; stop early when
    /// `cancel` is set. Returns what to do next.
    fn idle(&mut self, cancel: &AtomicBool, out: &Outbox) -> Idle {
        let _ = (cancel, out);
        Idle::Wait
    }

    /// Called once when the server stops ([`Running::stop`], or Ctrl+C,
    /// SIGTERM or SIGHUP in [`Running::wait`]), after background work was
    /// cancelled: an autosave. [`Running::stop`] waits for it at most
    /// [`STOP_WAIT`]. Not called after a panic.
    fn stop(&mut self, out: &Outbox) {
        let _ = out;
    }
}

/// Where and how to serve.
#[derive(Debug, Clone)]
pub struct Serve {
    /// Address to bind.
    pub host: IpAddr,
    /// Port (0: any free one).
    pub port: u16,
    /// The token (random when `None`).
    pub token: Option<String>,
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

/// A bound port and its token, not yet serving.
#[derive(Debug)]
pub struct Bound {
    listener: tokio::net::TcpListener,
    host: IpAddr,
    addr: SocketAddr,
    token: String,
}

/// Binds `serve`'s address for the app named `name` (in the error), and
/// makes the token.
///
/// # Errors
/// The token, or binding the address: `HOST:PORT: why` (a port in use
/// suggests another `--port`).
pub async fn bind(serve: &Serve, name: &str) -> Result<Bound, String> {
    let token = match serve.token.clone() {
        Some(t) => t,
        None => random_token().map_err(|e| format!("no random token: {e}"))?,
    };
    let listener = tokio::net::TcpListener::bind((serve.host, serve.port))
        .await
        .map_err(|e| {
            let why = match e.kind() {
                // Most often the same app still running from before.
                std::io::ErrorKind::AddrInUse => format!(
                    "port {} is in use (another trilux {name}?); choose another --port, or leave --port out for a free one",
                    serve.port
                ),
                std::io::ErrorKind::AddrNotAvailable => {
                    "not an address of this machine (--host)".to_string()
                }
                std::io::ErrorKind::PermissionDenied if serve.port < 1024 => format!(
                    "{e}: ports below 1024 need an administrator; choose --port 1024 or above, or leave --port out for a free one"
                ),
                _ => e.to_string(),
            };
            format!("{}:{}: {why}", serve.host, serve.port)
        })?;
    let addr = listener
        .local_addr()
        .map_err(|e| format!("{}:{}: {e}", serve.host, serve.port))?;
    Ok(Bound {
        listener,
        host: serve.host,
        addr,
        token,
    })
}

impl Bound {
    /// Where it listens.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Moves `app` onto its own thread and serves its page.
    ///
    /// # Errors
    /// When the thread cannot be started.
    pub fn serve<A: App>(self, app: A) -> Result<Running, String> {
        let (stop, stop_rx) = watch::channel(false);
        let stop = Arc::new(stop);
        let hub = hub::Hub::new();
        let cancel = Arc::new(AtomicBool::new(false));
        let stop_on_panic = stop.clone();
        let (requests, thread) = hub::spawn(app, hub.clone(), cancel.clone(), move || {
            let _ = stop_on_panic.send(true);
        })?;
        let guard = guard::Guard::new(&self.token, self.host, self.addr, A::NAME);
        let router = socket::router::<A>(socket::Server {
            guard: Arc::new(guard),
            requests,
            cancel,
            hub,
            stop: stop_rx.clone(),
            next_conn: Arc::new(std::sync::atomic::AtomicU64::new(1)),
            app: std::marker::PhantomData,
        });
        let mut stopped = stop_rx;
        // Small messages go out at once: with Nagle's algorithm a frame
        // and the status after it wait for the page's delayed ACK (40 ms
        // a round trip on Linux), which a brush stroke feels.
        let listener = self.listener.tap_io(|tcp| {
            let _ = tcp.set_nodelay(true);
        });
        let stop_on_exit = stop.clone();
        let task = tokio::spawn(async move {
            let served = axum::serve(listener, router)
                .with_graceful_shutdown(async move {
                    let _ = stopped.wait_for(|s| *s).await;
                })
                .await;
            // Ended by an I/O error too: whoever waits is told.
            let _ = stop_on_exit.send(true);
            served
        });
        Ok(Running {
            addr: self.addr,
            token: self.token,
            name: A::NAME,
            stop,
            task,
            thread: Some(thread),
        })
    }
}

/// How long [`Running::stop`] waits for the app's [`App::stop`].
pub const STOP_WAIT: Duration = Duration::from_secs(10);

/// Resolves on Ctrl+C, or on Unix on SIGTERM (a service manager, `kill`)
/// or SIGHUP (the terminal closed).
async fn stop_signal() -> std::io::Result<()> {
    #[cfg(unix)]
    {
        use tokio::signal::unix::{SignalKind, signal};
        let (mut term, mut hup) = (
            signal(SignalKind::terminate())?,
            signal(SignalKind::hangup())?,
        );
        tokio::select! {
            pressed = tokio::signal::ctrl_c() => pressed,
            _ = term.recv() => Ok(()),
            _ = hup.recv() => Ok(()),
        }
    }
    #[cfg(not(unix))]
    {
        tokio::signal::ctrl_c().await
    }
}

/// A running server.
#[derive(Debug)]
pub struct Running {
    /// Where it listens.
    pub addr: SocketAddr,
    /// The token every request needs.
    pub token: String,
    name: &'static str,
    stop: Arc<watch::Sender<bool>>,
    task: tokio::task::JoinHandle<std::io::Result<()>>,
    thread: Option<hub::Thread>,
}

impl Running {
    /// The page's URL.
    pub fn url(&self) -> String {
        format!("http://{}/{}/", self.addr, self.token)
    }

    /// Stops the server (open pages are disconnected) and waits for it.
    ///
    /// # Errors
    /// The server's I/O error, if it failed; a panic of the app's thread
    /// (`trilux NAME: its session thread panicked: …`).
    pub async fn stop(mut self) -> std::io::Result<()> {
        let _ = self.stop.send(true);
        let served = (&mut self.task).await.unwrap_or(Ok(()));
        let Some(thread) = self.thread.take() else {
            return served;
        };
        // The app's last word (an autosave), bounded: a stop must not hang.
        (thread.ask_stop)();
        let handle = thread.handle;
        let joined = tokio::task::spawn_blocking(move || handle.join());
        let finished = tokio::time::timeout(STOP_WAIT, joined).await.is_ok();
        let panic = thread
            .panic
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .take();
        match panic {
            Some(what) => Err(std::io::Error::other(format!(
                "trilux {}: its session thread panicked: {what}",
                self.name
            ))),
            None if !finished => Err(std::io::Error::other(format!(
                "trilux {}: its session thread did not stop within {} s; its last work may be lost",
                self.name,
                STOP_WAIT.as_secs()
            ))),
            None => served,
        }
    }

    /// Waits until the server stops: asked to (when `signals`, by
    /// Ctrl+C, SIGTERM or SIGHUP), or because the app's thread panicked or
    /// the server failed. The app's [`App::stop`] runs before it returns.
    ///
    /// # Errors
    /// As [`Running::stop`]; or the signal handlers could not be set.
    pub async fn wait(self, signals: bool) -> std::io::Result<()> {
        let mut stopped = self.stop.subscribe();
        let signal = async {
            if signals {
                stop_signal().await
            } else {
                std::future::pending().await
            }
        };
        tokio::select! {
            signalled = signal => signalled?,
            _ = stopped.wait_for(|s| *s) => {}
        }
        self.stop().await
    }
}

#[cfg(test)]
mod tests;
