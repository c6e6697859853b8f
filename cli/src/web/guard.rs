//! The checks every HTTP and WebSocket request passes: the token in the
//! path (compared in constant time), the `Host` header, and the `Origin`
//! header when there is one. Their refusals tell a user what to do, in
//! the app's name.

use std::net::{IpAddr, SocketAddr};

use axum::http::{HeaderMap, StatusCode, header};

/// The body of a request without the token or with a wrong one: still a
/// 404 (the token stays unguessable and is not revealed), but one that
/// tells a user who typed or bookmarked a shortened address what to do.
pub fn needs_token(app: &str) -> String {
    format!(
        "trilux {app}: this address needs the full URL trilux printed when it \
started (it holds a secret token); copy that URL, or restart trilux {app} for a new one\n"
    )
}

/// The body of a 403 for a foreign `Host`: what a user who reached the
/// server by a host name (not an address) should do.
pub fn wrong_host(app: &str) -> String {
    format!(
        "trilux {app}: wrong Host header; open the page by the address \
trilux printed (or, when it listens on every interface, by one of this machine's IP addresses), \
not by a host name\n"
    )
}

/// The body of a 403 for an `Origin` that is not this server's.
pub const FOREIGN_ORIGIN: &str = "foreign Origin";

/// The body of a 403 for a WebSocket request without `Origin` (a page
/// always sends one).
pub const MISSING_ORIGIN: &str = "missing Origin";

/// The token and the names this server answers to.
#[derive(Debug)]
pub(crate) struct Guard {
    token: String,
    /// `host:port` values a request's Host may have.
    hosts: Vec<String>,
    /// Bound to every interface (0.0.0.0 or ::): the port with which any
    /// IP-literal Host is also accepted, since a user on another machine
    /// types one of this machine's addresses, which the server does not
    /// list. A DNS-rebinding page always sends a host *name*, so this
    /// does not let one in.
    any_ip_port: Option<u16>,
    needs_token: String,
    wrong_host: String,
}

impl Guard {
    /// The guard of a server bound to `host` (as asked) at `addr` (as
    /// bound), for the app `app`.
    pub(crate) fn new(token: &str, host: IpAddr, addr: SocketAddr, app: &str) -> Self {
        Self {
            token: token.to_string(),
            hosts: allowed_hosts(host, addr),
            any_ip_port: host.is_unspecified().then_some(addr.port()),
            needs_token: needs_token(app),
            wrong_host: wrong_host(app),
        }
    }

    /// The 404 of a path without the token.
    pub(crate) fn not_found(&self) -> (StatusCode, String) {
        (StatusCode::NOT_FOUND, self.needs_token.clone())
    }

    /// Whether `host` (`host:port`, from a `Host` or `Origin` header)
    /// names this server.
    fn allowed_host(&self, host: &str) -> bool {
        self.hosts.iter().any(|h| h == host)
            || self
                .any_ip_port
                .is_some_and(|port| host.parse::<SocketAddr>().is_ok_and(|a| a.port() == port))
    }

    /// The token, `Host` and `Origin` checks every request passes.
    pub(crate) fn check(
        &self,
        token: &str,
        headers: &HeaderMap,
    ) -> Result<(), (StatusCode, String)> {
        if !same(token, &self.token) {
            return Err(self.not_found());
        }
        let host = headers
            .get(header::HOST)
            .and_then(|h| h.to_str().ok())
            .unwrap_or_default();
        if !self.allowed_host(host) {
            return Err((StatusCode::FORBIDDEN, self.wrong_host.clone()));
        }
        if let Some(origin) = headers.get(header::ORIGIN) {
            let ok = origin
                .to_str()
                .ok()
                .and_then(|o| o.strip_prefix("http://"))
                .is_some_and(|o| self.allowed_host(o));
            if !ok {
                return Err((StatusCode::FORBIDDEN, FOREIGN_ORIGIN.to_string()));
            }
        }
        Ok(())
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

/// Equal in constant time (the token must not leak through timing).
fn same(a: &str, b: &str) -> bool {
    a.len() == b.len()
        && a.bytes()
            .zip(b.bytes())
            .fold(0u8, |acc, (x, y)| acc | (x ^ y))
            == 0
}

#[cfg(test)]
mod tests {
    use super::*;
    use axum::http::HeaderValue;

    fn headers(host: &str, origin: Option<&str>) -> HeaderMap {
        let mut h = HeaderMap::new();
        h.insert(header::HOST, HeaderValue::from_str(host).unwrap());
        if let Some(o) = origin {
            h.insert(header::ORIGIN, HeaderValue::from_str(o).unwrap());
        }
        h
    }

    #[test]
    fn token_host_and_origin_are_checked_and_refusals_name_the_app() {
        let addr: SocketAddr = "127.0.0.1:4000".parse().unwrap();
        let g = Guard::new("abc", addr.ip(), addr, "paint");
        assert!(g.check("abc", &headers("localhost:4000", None)).is_ok());
        assert!(
            g.check("abc", &headers("[::1]:4000", Some("http://127.0.0.1:4000")))
                .is_ok()
        );
        let (code, text) = g
            .check("abd", &headers("localhost:4000", None))
            .unwrap_err();
        assert_eq!(code, StatusCode::NOT_FOUND);
        assert!(text.starts_with("trilux paint: ") && text.contains("restart trilux paint"));
        let (code, text) = g
            .check("abc", &headers("evil.example:4000", None))
            .unwrap_err();
        assert_eq!(code, StatusCode::FORBIDDEN);
        assert_eq!(text, wrong_host("paint"));
        let (_, text) = g
            .check(
                "abc",
                &headers("localhost:4000", Some("http://evil.example")),
            )
            .unwrap_err();
        assert_eq!(text, FOREIGN_ORIGIN);
        // Another machine's address is not this one's on a loopback bind.
        assert!(g.check("abc", &headers("10.0.0.2:4000", None)).is_err());
        let any: SocketAddr = "0.0.0.0:4000".parse().unwrap();
        let g = Guard::new("abc", any.ip(), any, "paint");
        assert!(g.check("abc", &headers("10.0.0.2:4000", None)).is_ok());
        assert!(g.check("abc", &headers("10.0.0.2:4001", None)).is_err());
    }

    #[test]
    fn same_is_equality() {
        assert!(same("", ""));
        assert!(same("a1", "a1"));
        assert!(!same("a1", "a2"));
        assert!(!same("a1", "a12"));
    }
}
