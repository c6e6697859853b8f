//! What `trilux view` and `trilux paint` share on the command line around
//! the web core (`trilux::web`): `--port`, `--host` and `--open`, the
//! warnings about the address, the URL line (or its `--json`), opening
//! the browser, and waiting until the server stops.

use std::future::Future;
use std::net::IpAddr;

use serde_json::{Map, Value};

use super::{Context, Result, invalid};

/// Where a web app listens and whether its page is opened.
#[derive(Debug, clap::Args)]
pub(crate) struct ServeArgs {
    /// Port (default: a free one; the URL printed names it).
    // 0 asks the system for a free port; clap's "[default: 0]" would read
    // as a port number.
    #[arg(long, default_value_t = 0, hide_default_value = true)]
    pub(crate) port: u16,
    /// Address to listen on; anything but 127.0.0.1 exposes the page to
    /// the network (the token still guards it).
    #[arg(long, default_value = "127.0.0.1")]
    pub(crate) host: IpAddr,
    /// Open the page in the system's browser.
    #[arg(long)]
    pub(crate) open: bool,
}

/// Warns when `host` lets other machines reach the page.
pub(crate) fn warn_host(host: IpAddr) {
    if host.is_loopback() {
        return;
    }
    eprintln!(
        "warning: listening on {host}: other machines that can reach it may open the page (with its token)"
    );
    // The printed URL holds the unspecified address, which only works on
    // this machine.
    if host.is_unspecified() {
        eprintln!(
            "note: from another machine, use this machine's IP address in place of {host} in the URL"
        );
    }
}

/// Starts the server `start` makes on a runtime of its own, announces it
/// (`trilux APP: COUNT WHAT; open URL  (Ctrl+C stops)`, or with `--json`
/// `{"command": APP, "url": URL, WHAT: COUNT}`), opens the page when
/// `open`, and waits until the server stops (Ctrl+C, SIGTERM, SIGHUP).
///
/// # Errors
/// The runtime, starting the server, or the server's own error (a panic
/// of the app's thread among them).
pub(crate) fn serve(
    context: &Context,
    app: &str,
    (count, what): (usize, &str),
    open: bool,
    start: impl Future<Output = std::result::Result<trilux::web::Running, String>>,
) -> Result<()> {
    let runtime = tokio::runtime::Runtime::new()
        .map_err(|e| invalid(format!("the server's runtime: {e}")))?;
    runtime.block_on(async move {
        let running = start.await.map_err(invalid)?;
        let url = running.url();
        if context.json {
            let mut line = Map::new();
            line.insert("command".into(), app.into());
            line.insert("url".into(), url.clone().into());
            line.insert(what.into(), count.into());
            println!("{}", Value::Object(line));
        } else {
            println!("trilux {app}: {count} {what}; open {url}  (Ctrl+C stops)");
        }
        if open {
            super::open_browser(&url);
        }
        running
            .wait(true)
            .await
            .map_err(|e| invalid(format!("the server: {e}")))
    })
}
