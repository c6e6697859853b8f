//! The app's thread and what joins it to the connections: the [`Inbox`]
//! of parsed requests, and the [`Outbox`] of snapshot slots, broadcasts
//! and replies.

use std::collections::{BTreeMap, HashMap};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError, TryRecvError};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use tokio::sync::{broadcast, mpsc as async_mpsc};

use super::{App, ConnId, Idle, Out, ReplyTo};

/// How many broadcast messages a slow page may fall behind before it is
/// sent the snapshot instead.
const BACKLOG: usize = 256;

/// What the connections share with the app's thread.
#[derive(Debug)]
pub(crate) struct Hub {
    state: Mutex<State>,
    all: broadcast::Sender<Out>,
}

#[derive(Debug, Default)]
struct State {
    /// The snapshot a page that connects is sent first, in slot order.
    slots: BTreeMap<usize, Vec<Out>>,
    /// Each open connection's queue of replies.
    conns: HashMap<ConnId, async_mpsc::UnboundedSender<Out>>,
}

/// A connection's view of the hub: everything broadcast, the replies to
/// it, and the snapshot it starts from.
pub(crate) struct Joined {
    pub(crate) all: broadcast::Receiver<Out>,
    pub(crate) replies: async_mpsc::UnboundedReceiver<Out>,
    pub(crate) snapshot: Vec<Out>,
}

impl Hub {
    pub(crate) fn new() -> Arc<Self> {
        Arc::new(Self {
            state: Mutex::new(State::default()),
            all: broadcast::channel(BACKLOG).0,
        })
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        // A panic while publishing leaves whole slots: keep serving them.
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Registers connection `conn`. Under one lock with [`Outbox::publish`],
    /// so that the snapshot and the broadcasts after it neither miss nor
    /// repeat a publication.
    pub(crate) fn join(&self, conn: ConnId) -> Joined {
        let mut state = self.lock();
        let (tx, replies) = async_mpsc::unbounded_channel();
        state.conns.insert(conn, tx);
        Joined {
            all: self.all.subscribe(),
            replies,
            snapshot: state.slots.values().flatten().cloned().collect(),
        }
    }

    /// The snapshot alone (a page that fell behind catches up with it).
    pub(crate) fn snapshot(&self) -> Vec<Out> {
        self.lock().slots.values().flatten().cloned().collect()
    }

    /// Forgets connection `conn`.
    pub(crate) fn leave(&self, conn: ConnId) {
        self.lock().conns.remove(&conn);
    }
}

/// What the app sends to the pages.
#[derive(Debug, Clone)]
pub struct Outbox {
    hub: Arc<Hub>,
}

impl Outbox {
    /// Replaces snapshot slot `slot` with `messages` and broadcasts them.
    /// A page that connects later is sent every slot, in slot order.
    pub fn publish(&self, slot: usize, messages: Vec<Out>) {
        let mut state = self.hub.lock();
        for m in &messages {
            // No page connected is not an error: the slot keeps it.
            let _ = self.hub.all.send(m.clone());
        }
        state.slots.insert(slot, messages);
    }

    /// Broadcasts `message` and adds it to the end of slot `slot`: a
    /// change that pages apply on top of the slot (paint's texel updates
    /// during a stroke), under the same lock as a page's join, so that a
    /// page that connects meanwhile gets it exactly once.
    pub fn append(&self, slot: usize, message: Out) {
        let mut state = self.hub.lock();
        let _ = self.hub.all.send(message.clone());
        state.slots.entry(slot).or_default().push(message);
    }

    /// Replaces slot `slot` with `messages` without sending them: state
    /// every page already has (a slot and its appended changes, folded
    /// into one message), kept for pages that connect later.
    pub fn keep(&self, slot: usize, messages: Vec<Out>) {
        self.hub.lock().slots.insert(slot, messages);
    }

    /// The number of messages slot `slot` holds.
    pub fn slot_len(&self, slot: usize) -> usize {
        self.hub.lock().slots.get(&slot).map_or(0, Vec::len)
    }

    /// Sends `message` to every connected page (not kept for later ones).
    pub fn broadcast(&self, message: Out) {
        let _ = self.hub.all.send(message);
    }

    /// Sends `message` to the connection `to` names, if it is still open.
    pub fn reply(&self, to: ReplyTo, message: Out) {
        if let Some(conn) = self.hub.lock().conns.get(&to.conn) {
            let _ = conn.send(message);
        }
    }

    /// Answers `to` with an error naming `field`.
    pub fn error(&self, to: ReplyTo, field: &str, message: &str) {
        self.reply(to, Out::Text(super::json::error(to.seq, field, message)));
    }
}

/// What the app's thread is sent.
pub(crate) enum Msg<R> {
    /// A page's request.
    Request(ReplyTo, R),
    /// The server stops: run [`App::stop`] and end.
    Stop,
}

/// The requests waiting for the app.
#[derive(Debug)]
pub struct Inbox<R> {
    rx: mpsc::Receiver<Msg<R>>,
    /// A stop came while the app was taking requests.
    stopping: bool,
}

impl<R> Inbox<R> {
    /// The next request if one is already waiting.
    pub fn try_next(&mut self) -> Option<(ReplyTo, R)> {
        match self.rx.try_recv() {
            Ok(Msg::Request(to, r)) => Some((to, r)),
            Ok(Msg::Stop) => {
                self.stopping = true;
                None
            }
            Err(_) => None,
        }
    }
}

impl<R> std::fmt::Debug for Msg<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Msg::Request(to, _) => write!(f, "Request({to:?})"),
            Msg::Stop => write!(f, "Stop"),
        }
    }
}

/// The queue the connections put requests in.
pub(crate) type Requests<R> = mpsc::Sender<Msg<R>>;

/// The app's thread, seen from the server.
pub(crate) struct Thread {
    pub(crate) handle: std::thread::JoinHandle<()>,
    /// The panic that ended it, if one did.
    pub(crate) panic: Arc<Mutex<Option<String>>>,
    /// Asks it to stop: cancels background work, then [`App::stop`].
    pub(crate) ask_stop: Box<dyn Fn() + Send + Sync>,
}

impl std::fmt::Debug for Thread {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Thread")
            .field("handle", &self.handle)
            .field("panic", &self.panic)
            .finish_non_exhaustive()
    }
}

/// Moves `app` onto its own thread (named after the app) and returns the
/// queue of its requests. The thread ends when every sender is gone. If
/// the app panics, the panic is kept and `on_panic` runs (it stops the
/// server: a page would otherwise be told "reconnecting…" forever).
pub(crate) fn spawn<A: App>(
    app: A,
    hub: Arc<Hub>,
    cancel: Arc<AtomicBool>,
    on_panic: impl FnOnce() + Send + 'static,
) -> Result<(Requests<A::Request>, Thread), String> {
    let (requests, rx) = mpsc::channel();
    let out = Outbox { hub };
    let (stopper, stop_cancel) = (requests.clone(), cancel.clone());
    let ask_stop = Box::new(move || {
        stop_cancel.store(true, Ordering::SeqCst);
        let _ = stopper.send(Msg::Stop);
    });
    let panic = Arc::new(Mutex::new(None));
    let kept = panic.clone();
    let handle = std::thread::Builder::new()
        .name(format!("trilux-{}-session", A::NAME))
        .spawn(move || {
            let ran = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let inbox = Inbox {
                    rx,
                    stopping: false,
                };
                run(app, inbox, &out, &cancel);
            }));
            if let Err(payload) = ran {
                let what = payload
                    .downcast_ref::<&str>()
                    .map(|s| (*s).to_string())
                    .or_else(|| payload.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "a panic without a message".into());
                *kept.lock().unwrap_or_else(PoisonError::into_inner) = Some(what);
                on_panic();
            }
        })
        .map_err(|e| format!("trilux {}: could not start its thread: {e}", A::NAME))?;
    Ok((
        requests,
        Thread {
            handle,
            panic,
            ask_stop,
        },
    ))
}

/// The app's loop: requests in order, background work in between (see
/// [`Idle`]), until the server stops (then [`App::stop`]).
fn run<A: App>(mut app: A, mut inbox: Inbox<A::Request>, out: &Outbox, cancel: &AtomicBool) {
    app.begin(out);
    let mut next = Idle::Busy;
    while !inbox.stopping {
        let message = match next {
            Idle::Busy => {
                cancel.store(false, Ordering::SeqCst);
                match inbox.rx.try_recv() {
                    Ok(m) => Some(m),
                    Err(TryRecvError::Empty) => None,
                    Err(TryRecvError::Disconnected) => break,
                }
            }
            Idle::Wait => match inbox.rx.recv() {
                Ok(m) => Some(m),
                Err(_) => break,
            },
            Idle::WaitAtMost(d) => match inbox.rx.recv_timeout(d) {
                Ok(m) => Some(m),
                Err(RecvTimeoutError::Timeout) => None,
                Err(RecvTimeoutError::Disconnected) => break,
            },
        };
        next = match message {
            Some(Msg::Request(to, r)) => {
                app.handle((to, r), &mut inbox, out);
                Idle::Busy
            }
            Some(Msg::Stop) => break,
            None => app.idle(cancel, out),
        };
    }
    app.stop(out);
}
