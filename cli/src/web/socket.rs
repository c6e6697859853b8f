//! The routes, and one page's connection: requests up to the app's
//! thread, its messages down. Closing a connection leaves the app's state
//! as it is (a reload continues it).

use std::marker::PhantomData;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

use axum::Router;
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::{Path as UrlPath, State};
use axum::http::{HeaderMap, StatusCode, header};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use tokio::sync::{broadcast, watch};

use super::guard::{Guard, MISSING_ORIGIN};
use super::hub::{Hub, Msg, Requests};
use super::{App, ConnId, Limits, Out, ReplyTo, assets, json};

/// What every request handler of app `A` shares.
pub(crate) struct Server<A: App> {
    pub(crate) guard: Arc<Guard>,
    pub(crate) requests: Requests<A::Request>,
    pub(crate) cancel: Arc<AtomicBool>,
    pub(crate) hub: Arc<Hub>,
    pub(crate) stop: watch::Receiver<bool>,
    pub(crate) next_conn: Arc<AtomicU64>,
    pub(crate) app: PhantomData<fn() -> A>,
}

impl<A: App> Clone for Server<A> {
    fn clone(&self) -> Self {
        Self {
            guard: self.guard.clone(),
            requests: self.requests.clone(),
            cancel: self.cancel.clone(),
            hub: self.hub.clone(),
            stop: self.stop.clone(),
            next_conn: self.next_conn.clone(),
            app: PhantomData,
        }
    }
}

/// The routes: everything under the token; the rest is 404.
pub(crate) fn router<A: App>(server: Server<A>) -> Router {
    Router::new()
        .route("/{token}/ws", get(websocket::<A>))
        .route("/{token}/", get(index::<A>))
        .route("/{token}", get(slash::<A>))
        .route("/{token}/{file}", get(asset::<A>))
        .fallback(not_found::<A>)
        .with_state(server)
}

async fn not_found<A: App>(State(s): State<Server<A>>) -> Response {
    s.guard.not_found().into_response()
}

/// `ok()` when the request passes the guard, else its refusal.
fn guarded(s: &Guard, token: &str, headers: &HeaderMap, ok: impl FnOnce() -> Response) -> Response {
    match s.check(token, headers) {
        Ok(()) => ok(),
        Err(r) => r.into_response(),
    }
}

async fn index<A: App>(
    State(s): State<Server<A>>,
    UrlPath(token): UrlPath<String>,
    headers: HeaderMap,
) -> Response {
    guarded(&s.guard, &token, &headers, || {
        assets::file(A::PAGE, "index.html")
    })
}

/// `/TOKEN` → `/TOKEN/`, so that the page's relative imports resolve.
async fn slash<A: App>(
    State(s): State<Server<A>>,
    UrlPath(token): UrlPath<String>,
    headers: HeaderMap,
) -> Response {
    guarded(&s.guard, &token, &headers, || {
        axum::response::Redirect::permanent(&format!("/{token}/")).into_response()
    })
}

async fn asset<A: App>(
    State(s): State<Server<A>>,
    UrlPath((token, name)): UrlPath<(String, String)>,
    headers: HeaderMap,
) -> Response {
    guarded(&s.guard, &token, &headers, || assets::file(A::PAGE, &name))
}

async fn websocket<A: App>(
    State(s): State<Server<A>>,
    UrlPath(token): UrlPath<String>,
    headers: HeaderMap,
    ws: WebSocketUpgrade,
) -> Response {
    if let Err(r) = s.guard.check(&token, &headers) {
        return r.into_response();
    }
    // A page always sends Origin with a WebSocket; one without is not a page.
    if !headers.contains_key(header::ORIGIN) {
        return (StatusCode::FORBIDDEN, MISSING_ORIGIN).into_response();
    }
    // The socket buffers a message up to the larger limit before it
    // knows its kind (tungstenite has one limit for both): an app with no
    // binary messages buffers no more than its text limit; a text
    // message between the two limits is refused below, after buffering.
    let largest = A::LIMITS.binary.max(A::LIMITS.text);
    let conn = s.next_conn.fetch_add(1, Ordering::Relaxed);
    ws.max_message_size(largest)
        .max_frame_size(largest)
        .on_upgrade(move |socket| client(socket, s, conn))
}

fn to_message(o: Out) -> Message {
    match o {
        Out::Text(t) => Message::Text(t.into()),
        Out::Binary(b) => Message::Binary(b),
    }
}

/// Resolves when the server is asked to stop.
async fn stopped(mut stop: watch::Receiver<bool>) {
    let _ = stop.wait_for(|s| *s).await;
}

/// One page's connection.
async fn client<A: App>(mut socket: WebSocket, s: Server<A>, conn: ConnId) {
    let joined = s.hub.join(conn);
    let (mut frames, mut replies) = (joined.all, joined.replies);
    if let Flow::Continue = send_all(&mut socket, joined.snapshot).await {
        let stop = stopped(s.stop.clone());
        tokio::pin!(stop);
        let mut bucket = Bucket::full(A::LIMITS);
        loop {
            let flow = tokio::select! {
                () = &mut stop => {
                    let _ = socket.send(Message::Close(None)).await;
                    Flow::Close
                }
                incoming = socket.recv() => match incoming {
                    Some(Ok(message)) => receive(&mut socket, &s, conn, message, &mut bucket).await,
                    _ => Flow::Close,
                },
                frame = frames.recv() => match frame {
                    Ok(m) => send_all(&mut socket, vec![m]).await,
                    // Too slow for the stream: catch up with the latest state.
                    Err(broadcast::error::RecvError::Lagged(_)) => {
                        send_all(&mut socket, s.hub.snapshot()).await
                    }
                    Err(broadcast::error::RecvError::Closed) => Flow::Close,
                },
                Some(reply) = replies.recv() => send_all(&mut socket, vec![reply]).await,
            };
            if let Flow::Close = flow {
                break;
            }
        }
    }
    s.hub.leave(conn);
}

/// Whether a connection goes on after one message in or out.
enum Flow {
    Continue,
    Close,
}

/// The per-connection rate limit: a token bucket refilled at `rate.0`
/// messages per second up to `rate.1`.
struct Bucket {
    rate: (f64, f64),
    tokens: f64,
    refilled: Instant,
}

impl Bucket {
    fn full(limits: Limits) -> Self {
        Bucket {
            rate: limits.rate,
            tokens: limits.rate.1,
            refilled: Instant::now(),
        }
    }

    /// Takes a token; false when the client is over the limit.
    fn take(&mut self) -> bool {
        let now = Instant::now();
        let refill = now.duration_since(self.refilled).as_secs_f64() * self.rate.0;
        self.tokens = (self.tokens + refill).min(self.rate.1);
        self.refilled = now;
        if self.tokens < 1.0 {
            return false;
        }
        self.tokens -= 1.0;
        true
    }
}

/// The error of a message over the rate limit.
const DROPPED: &str = "too many messages; this one was dropped";

/// One message from the page: a request is queued for the app; anything
/// wrong is answered with an error naming the field, and the connection
/// goes on. Text and binary messages take from one rate bucket; the
/// app's [`App::parse_binary`] checks a binary message's size and
/// content.
async fn receive<A: App>(
    socket: &mut WebSocket,
    s: &Server<A>,
    conn: ConnId,
    message: Message,
    bucket: &mut Bucket,
) -> Flow {
    let limit = A::LIMITS.text;
    let text = match message {
        Message::Text(t) if t.len() > limit => {
            let problem = format!("{} bytes: a text message may have at most {limit}", t.len());
            return reply(socket, json::error(None, "(message)", &problem)).await;
        }
        Message::Text(t) => t,
        Message::Close(_) => return Flow::Close,
        Message::Ping(_) | Message::Pong(_) => return Flow::Continue,
        Message::Binary(_) if !bucket.take() => {
            return reply(socket, json::error(None, "(rate)", DROPPED)).await;
        }
        Message::Binary(b) => {
            return match A::parse_binary(&b) {
                Ok((seq, request)) => submit(s, conn, Some(seq), request),
                Err(bad) => reply(socket, json::error(None, &bad.field, &bad.problem)).await,
            };
        }
    };
    let value = json::read(&text);
    // The sequence number of a message refused as a whole, when it has one.
    let seq = value.as_ref().ok().and_then(json::seq_of);
    if !bucket.take() {
        let dropped = json::error(seq, "(rate)", DROPPED);
        return reply(socket, dropped).await;
    }
    let parsed = value.and_then(|v| {
        let m = json::incoming(&v)?;
        A::parse(&m).map(|request| (m.seq, request))
    });
    match parsed {
        Ok((seq, request)) => submit(s, conn, Some(seq), request),
        Err(bad) => reply(socket, json::error(seq, &bad.field, &bad.problem)).await,
    }
}

/// Queues a request for the app, cancelling its background work when
/// the app says the request interrupts it.
fn submit<A: App>(s: &Server<A>, conn: ConnId, seq: Option<u64>, request: A::Request) -> Flow {
    if A::interrupts(&request) {
        s.cancel.store(true, Ordering::SeqCst);
    }
    match s
        .requests
        .send(Msg::Request(ReplyTo { conn, seq }, request))
    {
        Ok(()) => Flow::Continue,
        Err(_) => Flow::Close,
    }
}

async fn reply(socket: &mut WebSocket, text: String) -> Flow {
    match socket.send(Message::Text(text.into())).await {
        Ok(()) => Flow::Continue,
        Err(_) => Flow::Close,
    }
}

async fn send_all(socket: &mut WebSocket, messages: Vec<Out>) -> Flow {
    for m in messages {
        if socket.send(to_message(m)).await.is_err() {
            return Flow::Close;
        }
    }
    Flow::Continue
}
