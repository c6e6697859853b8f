//! `trilux view`: interactive TransCut in the browser — an app of the
//! [web core](crate::web) over a [`tet_diffusion::Session`], and a page
//! of a few dependency-free ES modules compiled into the binary.
//!
//! The core does the serving and its security (loopback bind, the URL
//! token, `Host`/`Origin` checks, message size and rate limits, files
//! only from the binary); this module is the app: its page ([`PAGE`]),
//! its protocol ([`protocol`]), the thread that owns the session (the
//! `worker` module, which implements [`web::App`]) and
//! its session file ([`session_file`]). A bad message gets a JSON error
//! naming the field and changes nothing; exports are atomic and never
//! replace a file unless the page says the user confirmed.

use std::net::IpAddr;
use std::path::PathBuf;

use serde_json::Value;
use tet_diffusion::glam::DVec3;
use tet_diffusion::{Log, Object, Session, SessionOptions};

use crate::web::{self, Asset, Limits};

pub mod builtin;
pub mod protocol;
pub mod session_file;
mod worker;

use protocol::ExportKind;

pub use crate::web::{Out, Running, random_token};

/// Largest message from the page.
pub const MAX_MESSAGE: usize = 64 * 1024;
/// Messages per second a connection may send on average, and in a burst.
pub const RATE: (f64, f64) = (200.0, 400.0);

/// The page's limits: [`MAX_MESSAGE`] of text, [`RATE`], and uploads
/// (environment maps) up to [`protocol::MAX_UPLOAD`].
pub const LIMITS: Limits = Limits {
    text: MAX_MESSAGE,
    binary: protocol::MAX_UPLOAD,
    rate: RATE,
};

/// The page's own files (served beside the core's, [`web::assets::CORE`]).
pub const PAGE: &[Asset] = &[
    Asset::html("index.html", include_str!("page/index.html")),
    Asset::css("style.css", include_str!("page/style.css")),
    Asset::js("app.js", include_str!("page/app.js")),
    Asset::js("gl.js", include_str!("page/gl.js")),
    Asset::js("protocol.js", include_str!("page/protocol.js")),
];

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
    // Bound before the first solve, so that a port in use is reported at
    // once, not after a large mesh's solve.
    let serve = web::Serve {
        host: options.host,
        port: options.port,
        token: options.token.clone(),
    };
    let bound = web::bind(&serve, <worker::Worker as web::App>::NAME).await?;
    let session_options = options.session;
    let session = tokio::task::spawn_blocking(move || open_session(object, session_options, log))
        .await
        .map_err(|e| e.to_string())??;
    let white = white_point(&session);
    bound.serve(worker::Worker {
        session,
        exporter,
        export_dir: options.export_dir,
        source,
        white,
        envs: options.environments,
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

/// The body of a request without the token or with a wrong one
/// ([`web::guard::needs_token`] of `view`).
pub const NEEDS_TOKEN: &str = "trilux view: this address needs the full URL trilux printed when it \
started (it holds a secret token); copy that URL, or restart trilux view for a new one\n";

/// The body of a 403 for a foreign `Host` ([`web::guard::wrong_host`] of
/// `view`).
pub const WRONG_HOST: &str = "trilux view: wrong Host header; open the page by the address \
trilux printed (or, when it listens on every interface, by one of this machine's IP addresses), \
not by a host name\n";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_texts_are_the_cores_in_views_name() {
        assert_eq!(NEEDS_TOKEN, web::guard::needs_token("view"));
        assert_eq!(WRONG_HOST, web::guard::wrong_host("view"));
    }

    #[test]
    fn the_page_shadows_no_core_file_and_imports_only_served_files() {
        assert_eq!(web::assets::check_page(PAGE), Ok(()));
    }
}
