//! The WebSocket and HTTP client of the web apps' tests (`trilux view`,
//! `trilux paint`): both serve through `trilux::web`, so they are driven
//! the same way.

use std::net::SocketAddr;

use futures_util::SinkExt;
use serde_json::Value;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio_tungstenite::tungstenite::client::IntoClientRequest;
use tokio_tungstenite::tungstenite::{self, Message};

/// A page's connection.
pub(crate) type Socket =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

/// Opens `/TOKEN/ws` at `addr` (`host:port`) with the `Origin` header
/// `origin` (none: no header).
pub(crate) async fn connect_with(
    addr: &str,
    token: &str,
    origin: Option<&str>,
) -> Result<Socket, tungstenite::Error> {
    let mut request = format!("ws://{addr}/{token}/ws").into_client_request()?;
    if let Some(o) = origin {
        request.headers_mut().insert("Origin", o.parse().unwrap());
    }
    tokio_tungstenite::connect_async(request)
        .await
        .map(|(s, _)| s)
}

/// Opens the page's socket as the page does (its own `Origin`).
pub(crate) async fn connect(addr: &str, token: &str) -> Socket {
    connect_with(addr, token, Some(&format!("http://{addr}")))
        .await
        .unwrap()
}

/// Sends `v` as a text message.
pub(crate) async fn send(s: &mut Socket, v: Value) {
    s.send(Message::Text(v.to_string().into())).await.unwrap();
}

/// Sends `text` as it is.
pub(crate) async fn send_raw(s: &mut Socket, text: String) -> Result<(), tungstenite::Error> {
    s.send(Message::Text(text.into())).await
}

/// A raw HTTP/1.1 GET of `path` at `addr` with the `Host` header `host`
/// (and `Origin` when given); the status code and body.
pub(crate) async fn get(
    addr: SocketAddr,
    path: &str,
    host: &str,
    origin: Option<&str>,
) -> (u16, String) {
    // A server on every interface (0.0.0.0) is reached through loopback.
    let mut to = addr;
    if to.ip().is_unspecified() {
        to.set_ip(std::net::Ipv4Addr::LOCALHOST.into());
    }
    let mut c = tokio::net::TcpStream::connect(to).await.unwrap();
    let origin = origin.map_or(String::new(), |o| format!("Origin: {o}\r\n"));
    let req = format!("GET {path} HTTP/1.1\r\nHost: {host}\r\n{origin}Connection: close\r\n\r\n");
    c.write_all(req.as_bytes()).await.unwrap();
    let mut out = Vec::new();
    c.read_to_end(&mut out).await.unwrap();
    let text = String::from_utf8_lossy(&out).to_string();
    let code = text[9..12].parse().unwrap();
    let body = text.split_once("\r\n\r\n").map_or("", |x| x.1).to_string();
    (code, body)
}

/// The checks every web app's server must pass, whatever the app: the
/// token (404 in the app's words without it, the token never in the
/// body), `/TOKEN` redirected to `/TOKEN/`, a foreign `Host` or
/// `Origin` refused (403), and a WebSocket only with the token and this
/// server's `Origin`. `app` is the app's name (`view`).
pub(crate) async fn check_guard(addr: SocketAddr, token: &str, app: &str) {
    let host = addr.to_string();
    let wrong = "f".repeat(token.len());
    for path in [
        "/".to_string(),
        "/index.html".into(),
        format!("/{wrong}/"),
        format!("/{wrong}/net.js"),
    ] {
        let (code, body) = get(addr, &path, &host, None).await;
        assert_eq!(code, 404, "{path}");
        assert!(
            body.starts_with(&format!("trilux {app}: this address needs the full URL")),
            "{path}: {body}"
        );
        assert!(!body.contains(token), "{path}: the body reveals the token");
    }
    assert_eq!(get(addr, &format!("/{token}"), &host, None).await.0, 308);
    for file in ["", "index.html", "net.js", "camera.js", "base.css"] {
        let (code, _) = get(addr, &format!("/{token}/{file}"), &host, None).await;
        assert_eq!(code, 200, "/TOKEN/{file}");
    }
    let (code, body) = get(addr, &format!("/{token}/"), "evil.example:80", None).await;
    assert_eq!(code, 403);
    assert!(
        body.starts_with(&format!("trilux {app}: wrong Host header")),
        "{body}"
    );
    let foreign = Some("http://evil.example");
    assert_eq!(
        get(addr, &format!("/{token}/"), &host, foreign).await.0,
        403
    );
    let origin = format!("http://{host}");
    assert!(connect_with(&host, &wrong, Some(&origin)).await.is_err());
    assert!(connect_with(&host, token, foreign).await.is_err());
    assert!(connect_with(&host, token, None).await.is_err());
    assert!(connect_with(&host, token, Some(&origin)).await.is_ok());
}
