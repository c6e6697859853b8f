//! The core with a tiny echo app: the snapshot a page starts from,
//! replies to the asking connection only, size and rate limits, error
//! frames, and an app that panics.

use std::time::Duration;

use futures_util::{SinkExt, StreamExt};
use serde_json::{Value, json};
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;

use super::*;

type Socket =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

/// Echoes text to the asking page, publishes to all, or panics; `work`
/// starts background work that a cancel restarts, `peek` answers without
/// interrupting it.
struct Echo {
    /// Set by [`App::stop`].
    stopped: Arc<std::sync::atomic::AtomicBool>,
    published: usize,
    /// Steps of background work left.
    work: u32,
    /// How often the background work was cancelled and restarted.
    restarts: u32,
}

/// Steps of the echo app's background work.
const WORK: u32 = 20;

enum Request {
    Echo(String),
    Publish(String),
    Append(String),
    Fold,
    Panic,
    Work,
    Peek,
}

impl App for Echo {
    const NAME: &'static str = "echo";
    const PAGE: &'static [Asset] = &[Asset::html(
        "index.html",
        "<link rel=\"stylesheet\" href=\"base.css\"><script type=\"module\" src=\"net.js\"></script>",
    )];
    const LIMITS: Limits = Limits {
        text: 1024,
        binary: 4096,
        rate: (20.0, 10.0),
    };
    type Request = Request;

    fn parse(m: &Incoming<'_>) -> Result<Request, BadField> {
        let text = || {
            json::get(m.fields, "text")?
                .as_str()
                .map(str::to_string)
                .ok_or_else(|| BadField::new("text", "expected a string"))
        };
        match m.op {
            "echo" => Ok(Request::Echo(text()?)),
            "publish" => Ok(Request::Publish(text()?)),
            "append" => Ok(Request::Append(text()?)),
            "fold" => Ok(Request::Fold),
            "panic" => Ok(Request::Panic),
            "work" => Ok(Request::Work),
            "peek" => Ok(Request::Peek),
            other => Err(BadField::new("op", format!("unknown op {other:?}"))),
        }
    }

    fn interrupts(request: &Request) -> bool {
        !matches!(request, Request::Peek)
    }

    fn idle(&mut self, cancel: &std::sync::atomic::AtomicBool, out: &Outbox) -> Idle {
        if self.work == 0 {
            return Idle::Wait;
        }
        std::thread::sleep(Duration::from_millis(10));
        if cancel.load(std::sync::atomic::Ordering::SeqCst) {
            // As view's refinement: cancelled work starts over.
            self.restarts += 1;
            self.work = WORK;
            return Idle::Busy;
        }
        self.work -= 1;
        if self.work == 0 {
            let done = json!({"type": "done", "restarts": self.restarts});
            out.broadcast(Out::Text(done.to_string()));
        }
        Idle::Busy
    }

    fn parse_binary(bytes: &[u8]) -> Result<(u64, Request), BadField> {
        Ok((0, Request::Echo(format!("{} bytes", bytes.len()))))
    }

    fn begin(&mut self, out: &Outbox) {
        out.publish(0, vec![Out::Text(json!({"type": "hello"}).to_string())]);
        out.publish(1, vec![Out::Binary(Bytes::from_static(b"frame"))]);
    }

    fn stop(&mut self, _: &Outbox) {
        self.stopped
            .store(true, std::sync::atomic::Ordering::SeqCst);
    }

    fn handle(&mut self, first: (ReplyTo, Request), _: &mut Inbox<Request>, out: &Outbox) {
        let (to, request) = first;
        match request {
            Request::Echo(text) => out.reply(
                to,
                Out::Text(json!({"type": "echo", "seq": to.seq, "text": text}).to_string()),
            ),
            Request::Publish(text) => {
                self.published += 1;
                let m = json!({"type": "published", "text": text, "n": self.published});
                out.publish(0, vec![Out::Text(m.to_string())]);
            }
            Request::Append(text) => {
                out.append(
                    1,
                    Out::Text(json!({"type": "appended", "text": text}).to_string()),
                );
            }
            Request::Fold => {
                let folded = json!({"type": "folded", "from": out.slot_len(1)});
                out.keep(1, vec![Out::Text(folded.to_string())]);
                out.reply(to, Out::Text(json!({"type": "done"}).to_string()));
            }
            Request::Panic => panic!("the echo app was asked to panic"),
            Request::Work => (self.work, self.restarts) = (WORK, 0),
            Request::Peek => out.reply(to, Out::Text(json!({"type": "peek"}).to_string())),
        }
    }
}

async fn start() -> Running {
    start_with(Arc::default()).await
}

/// The echo app, which sets `stopped` when it stops.
async fn start_with(stopped: Arc<std::sync::atomic::AtomicBool>) -> Running {
    let serve = Serve {
        host: IpAddr::from([127, 0, 0, 1]),
        port: 0,
        token: None,
    };
    bind(&serve, Echo::NAME)
        .await
        .unwrap()
        .serve(Echo {
            stopped,
            published: 0,
            work: 0,
            restarts: 0,
        })
        .unwrap()
}

async fn connect(r: &Running) -> Socket {
    let mut request = format!("ws://{}/{}/ws", r.addr, r.token)
        .into_client_request()
        .unwrap();
    let origin = format!("http://{}", r.addr);
    request
        .headers_mut()
        .insert("Origin", origin.parse().unwrap());
    tokio_tungstenite::connect_async(request).await.unwrap().0
}

/// A page connected and past the first slot's hello.
async fn opened(r: &Running) -> Socket {
    let mut s = connect(r).await;
    assert_eq!(text(&mut s).await["type"], "hello");
    s
}

/// The next message, or `None` when the connection ends or nothing comes
/// within `wait`.
async fn next(s: &mut Socket, wait: Duration) -> Option<Message> {
    match tokio::time::timeout(wait, s.next()).await {
        Ok(Some(Ok(m))) if !matches!(m, Message::Close(_)) => Some(m),
        _ => None,
    }
}

/// The next text message as JSON (binary ones are skipped).
async fn text(s: &mut Socket) -> Value {
    loop {
        match next(s, Duration::from_secs(20)).await {
            Some(Message::Text(t)) => return serde_json::from_str(&t).unwrap(),
            Some(_) => {}
            None => panic!("no text message came"),
        }
    }
}

async fn send(s: &mut Socket, v: Value) {
    s.send(Message::Text(v.to_string().into())).await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_page_starts_from_the_snapshot_in_slot_order() {
    let r = start().await;
    let mut a = connect(&r).await;
    assert_eq!(text(&mut a).await["type"], "hello");
    match next(&mut a, Duration::from_secs(20)).await {
        Some(Message::Binary(b)) => assert_eq!(&b[..], b"frame"),
        other => panic!("expected slot 1's frame, got {other:?}"),
    }
    send(&mut a, json!({"seq": 1, "op": "publish", "text": "x"})).await;
    let published = text(&mut a).await;
    assert_eq!(
        (published["type"].clone(), published["n"].clone()),
        ("published".into(), 1.into())
    );
    // A page that connects later gets the replaced slot 0, then slot 1.
    let mut b = connect(&r).await;
    assert_eq!(text(&mut b).await["text"], "x");
    assert!(matches!(
        next(&mut b, Duration::from_secs(20)).await,
        Some(Message::Binary(_))
    ));
    r.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn appended_changes_reach_every_page_once_and_folding_sends_nothing() {
    let r = start().await;
    let mut a = opened(&r).await;
    send(&mut a, json!({"seq": 1, "op": "append", "text": "d1"})).await;
    assert_eq!(text(&mut a).await["text"], "d1");
    // A page that connects now: hello, the frame, then the change.
    let mut b = opened(&r).await;
    assert!(matches!(
        next(&mut b, Duration::from_secs(20)).await,
        Some(Message::Binary(_))
    ));
    assert_eq!(text(&mut b).await["text"], "d1");
    send(&mut a, json!({"seq": 2, "op": "fold"})).await;
    // The fold answers the asking page only and broadcasts nothing.
    assert_eq!(text(&mut a).await["type"], "done");
    assert!(next(&mut b, Duration::from_millis(300)).await.is_none());
    // A later page gets the folded slot in place of frame and change.
    let mut c = opened(&r).await;
    let folded = text(&mut c).await;
    assert_eq!(
        (folded["type"].clone(), folded["from"].clone()),
        ("folded".into(), 2.into())
    );
    r.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_reply_goes_to_the_asking_page_only() {
    let r = start().await;
    let (mut a, mut b) = (opened(&r).await, opened(&r).await);
    send(&mut a, json!({"seq": 5, "op": "echo", "text": "hi"})).await;
    let echo = text(&mut a).await;
    assert_eq!(
        (echo["seq"].clone(), echo["text"].clone()),
        (5.into(), "hi".into())
    );
    // b got slot 1's frame and nothing else.
    assert!(matches!(
        next(&mut b, Duration::from_secs(20)).await,
        Some(Message::Binary(_))
    ));
    assert!(next(&mut b, Duration::from_millis(300)).await.is_none());
    r.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_messages_get_errors_naming_the_field_and_the_page_goes_on() {
    let r = start().await;
    let mut s = opened(&r).await;
    let cases = [
        ("{".to_string(), Value::Null, "(message)"),
        (r#"{"seq":3}"#.to_string(), 3.into(), "op"),
        (r#"{"seq":4,"op":"echo"}"#.to_string(), 4.into(), "text"),
        (r#"{"seq":5,"op":"nope"}"#.to_string(), 5.into(), "op"),
        (
            format!(r#"{{"seq":6,"op":"echo","text":"{}"}}"#, "x".repeat(2000)),
            Value::Null,
            "(message)",
        ),
    ];
    for (message, seq, field) in cases {
        s.send(Message::Text(message.into())).await.unwrap();
        let e = text(&mut s).await;
        assert_eq!(e["type"], "error", "{e}");
        assert_eq!(
            (e["seq"].clone(), e["field"].as_str()),
            (seq, Some(field)),
            "{e}"
        );
    }
    // A binary message within its limit reaches the app.
    s.send(Message::Binary(vec![0u8; 4000].into()))
        .await
        .unwrap();
    assert_eq!(text(&mut s).await["text"], "4000 bytes");
    send(
        &mut s,
        json!({"seq": 7, "op": "echo", "text": "still here"}),
    )
    .await;
    assert_eq!(text(&mut s).await["text"], "still here");
    r.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_flood_is_refused_by_rate_per_connection() {
    let r = start().await;
    let mut s = opened(&r).await;
    for seq in 0..40u64 {
        send(&mut s, json!({"seq": seq, "op": "echo", "text": "f"})).await;
    }
    let (mut echoed, mut dropped) = (0, 0);
    for _ in 0..40 {
        let m = text(&mut s).await;
        match m["type"].as_str() {
            Some("echo") => echoed += 1,
            Some("error") => {
                assert_eq!(m["field"], "(rate)");
                assert!(m["seq"].is_u64(), "{m}");
                dropped += 1;
            }
            _ => panic!("unexpected {m}"),
        }
    }
    // A burst of 10, and a few refilled while the 40 went out.
    assert!(
        echoed >= 10 && dropped >= 10,
        "{echoed} echoed, {dropped} dropped"
    );
    // Binary messages take from the same bucket.
    tokio::time::sleep(Duration::from_secs(1)).await;
    for _ in 0..40 {
        s.send(Message::Binary(vec![1u8; 8].into())).await.unwrap();
    }
    let mut binary_dropped = 0;
    for _ in 0..40 {
        let m = text(&mut s).await;
        if m["field"] == "(rate)" {
            binary_dropped += 1;
        }
    }
    assert!(
        binary_dropped >= 10,
        "{binary_dropped} binary messages dropped"
    );
    // Another page has its own bucket.
    let mut other = opened(&r).await;
    send(&mut other, json!({"seq": 1, "op": "echo", "text": "mine"})).await;
    assert_eq!(text(&mut other).await["text"], "mine");
    r.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_page_of_an_app_is_served_beside_the_cores_files_in_its_name() {
    let r = start().await;
    let get = |path: String| {
        let addr = r.addr;
        async move {
            use tokio::io::{AsyncReadExt, AsyncWriteExt};
            let mut c = tokio::net::TcpStream::connect(addr).await.unwrap();
            let req = format!("GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n");
            c.write_all(req.as_bytes()).await.unwrap();
            let mut out = Vec::new();
            c.read_to_end(&mut out).await.unwrap();
            String::from_utf8_lossy(&out).to_string()
        }
    };
    let index = get(format!("/{}/", r.token)).await;
    assert!(
        index.starts_with("HTTP/1.1 200") && index.contains("net.js"),
        "{index}"
    );
    let net = get(format!("/{}/net.js", r.token)).await;
    assert!(
        net.contains("text/javascript") && net.contains("class Connection"),
        "{net}"
    );
    let missing = get("/nope/".to_string()).await;
    assert!(missing.starts_with("HTTP/1.1 404") && missing.contains("restart trilux echo"));
    assert_eq!(assets::check_page(Echo::PAGE), Ok(()));
    r.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_panicking_app_stops_the_server_and_wait_says_why() {
    let r = start().await;
    let mut s = opened(&r).await;
    send(&mut s, json!({"seq": 1, "op": "panic"})).await;
    // The page is disconnected rather than left waiting for answers.
    loop {
        match next(&mut s, Duration::from_secs(20)).await {
            Some(Message::Text(t)) => assert!(!t.contains("echo"), "answered: {t}"),
            Some(_) => {}
            None => break,
        }
    }
    let stopped = tokio::time::timeout(Duration::from_secs(20), r.wait(false))
        .await
        .expect("the server stops by itself");
    let e = stopped.unwrap_err().to_string();
    assert_eq!(
        e,
        "trilux echo: its session thread panicked: the echo app was asked to panic"
    );
}

/// Sends `work`, then `op` 8 times 20 ms apart (while the work, 200 ms,
/// goes on); how often the work restarted.
async fn restarts_under(op: &str) -> u64 {
    let r = start().await;
    let mut s = opened(&r).await;
    send(&mut s, json!({"seq": 1, "op": "work"})).await;
    for seq in 2..10 {
        send(&mut s, json!({"seq": seq, "op": op, "text": "t"})).await;
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    let done = loop {
        let v = text(&mut s).await;
        if v["type"] == "done" {
            break v;
        }
    };
    r.stop().await.unwrap();
    done["restarts"].as_u64().unwrap()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn only_requests_the_app_calls_interrupting_cancel_its_background_work() {
    assert_eq!(restarts_under("peek").await, 0);
    assert!(restarts_under("echo").await > 0);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn stopping_the_server_runs_the_apps_stop_even_while_it_works() {
    let stopped = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let r = start_with(stopped.clone()).await;
    let mut s = opened(&r).await;
    // Long background work is under way when the server stops.
    send(&mut s, json!({"seq": 1, "op": "work"})).await;
    tokio::time::sleep(Duration::from_millis(30)).await;
    r.stop().await.unwrap();
    assert!(stopped.load(std::sync::atomic::Ordering::SeqCst));
}
