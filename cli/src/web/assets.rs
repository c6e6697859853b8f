//! The page's files, compiled in: the app's and the core's, served side
//! by side under `/TOKEN/` (so that `import … from './camera.js'` works
//! from either), with headers that keep them from being cached, sniffed
//! or made to load anything from elsewhere.
//!
//! The core's files are app-neutral: `camera.js` (an orbit camera),
//! `net.js` (the socket, reconnecting), `frame.js` (the binary frames'
//! header), `glutil.js` (WebGL2 shaders, canvas size, offscreen
//! targets), `pick.js` (the nearest hit of a ray on triangle meshes) and
//! `base.css` (the bars, buttons, HUD and help box).

use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Response};

/// One file of a page.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Asset {
    /// Its name under `/TOKEN/`.
    pub name: &'static str,
    /// Its `Content-Type`.
    pub mime: &'static str,
    /// Its text.
    pub body: &'static str,
}

impl Asset {
    /// An HTML file.
    pub const fn html(name: &'static str, body: &'static str) -> Self {
        Self {
            name,
            mime: "text/html; charset=utf-8",
            body,
        }
    }

    /// A JavaScript module.
    pub const fn js(name: &'static str, body: &'static str) -> Self {
        Self {
            name,
            mime: "text/javascript; charset=utf-8",
            body,
        }
    }

    /// A style sheet.
    pub const fn css(name: &'static str, body: &'static str) -> Self {
        Self {
            name,
            mime: "text/css; charset=utf-8",
            body,
        }
    }
}

/// The core's page files, served beside every app's.
pub const CORE: &[Asset] = &[
    Asset::js("camera.js", include_str!("page/camera.js")),
    Asset::js("net.js", include_str!("page/net.js")),
    Asset::js("frame.js", include_str!("page/frame.js")),
    Asset::js("glutil.js", include_str!("page/glutil.js")),
    Asset::js("pick.js", include_str!("page/pick.js")),
    Asset::css("base.css", include_str!("page/base.css")),
];

/// The file `name` of `page` or of the core, with its headers; 404 when
/// there is none.
pub(crate) fn file(page: &[Asset], name: &str) -> Response {
    match page.iter().chain(CORE).find(|f| f.name == name) {
        Some(f) => (
            [
                (header::CONTENT_TYPE, f.mime),
                (header::CACHE_CONTROL, "no-store"),
                (header::X_CONTENT_TYPE_OPTIONS, "nosniff"),
                (
                    header::CONTENT_SECURITY_POLICY,
                    "default-src 'self'; connect-src 'self'; img-src 'self' blob: data:",
                ),
            ],
            f.body,
        )
            .into_response(),
        None => (StatusCode::NOT_FOUND, "not found").into_response(),
    }
}

/// Checks an app's page against the core's files: it has an
/// `index.html`, no file of it shadows a core file (or another of its
/// own), and every relative import or link in it and in the core's files
/// names a served file.
///
/// # Errors
/// Every problem found, one a line, naming the file.
pub fn check_page(page: &[Asset]) -> Result<(), String> {
    let mut problems = Vec::new();
    if !page.iter().any(|f| f.name == "index.html") {
        problems.push("the page has no index.html".to_string());
    }
    for (k, f) in page.iter().enumerate() {
        if CORE.iter().any(|c| c.name == f.name) {
            problems.push(format!("{}: shadows the core's file of that name", f.name));
        }
        if page[..k].iter().any(|g| g.name == f.name) {
            problems.push(format!("{}: listed twice", f.name));
        }
    }
    for f in page.iter().chain(CORE) {
        for target in references(f.body) {
            if !page.iter().chain(CORE).any(|g| g.name == target) {
                problems.push(format!(
                    "{}: refers to {target}, which is not served",
                    f.name
                ));
            }
        }
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems.join("\n"))
    }
}

/// The same-folder files `text` refers to: ES module imports
/// (`from './x.js'`, `import './x.js'`) and HTML `src`/`href` values
/// that are plain file names (not `data:`, a scheme, `#…` or a path).
fn references(text: &str) -> Vec<&str> {
    let mut found = Vec::new();
    for opener in [
        "from '",
        "from \"",
        "import '",
        "import \"",
        "src=\"",
        "href=\"",
    ] {
        let quote = &opener[opener.len() - 1..];
        let mut rest = text;
        while let Some(k) = rest.find(opener) {
            rest = &rest[k + opener.len()..];
            let Some(end) = rest.find(quote) else { break };
            let target = &rest[..end];
            let target = target.strip_prefix("./").unwrap_or(target);
            let plain = !target.is_empty()
                && !target.contains([':', '/', '#', '?', ' ', '{', '$', '+'])
                && target.contains('.');
            if plain {
                found.push(target);
            }
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_core_alone_is_consistent() {
        let page = [Asset::html(
            "index.html",
            "<script src=\"net.js\"></script>",
        )];
        assert_eq!(check_page(&page), Ok(()));
    }

    #[test]
    fn shadowing_and_dangling_imports_are_found() {
        let page = [
            Asset::html(
                "index.html",
                "<link href=\"style.css\"><link rel=\"icon\" href=\"data:,\"><a href=\"#x\">",
            ),
            Asset::js("net.js", ""),
            Asset::js(
                "app.js",
                "import { a } from './gone.js';\nimport './net.js';",
            ),
        ];
        let problems = check_page(&page).unwrap_err();
        assert!(problems.contains("net.js: shadows"), "{problems}");
        assert!(problems.contains("app.js: refers to gone.js"), "{problems}");
        assert!(
            problems.contains("index.html: refers to style.css"),
            "{problems}"
        );
        assert_eq!(problems.lines().count(), 3, "{problems}");
        assert!(check_page(&[]).unwrap_err().contains("no index.html"));
    }

    #[test]
    fn references_are_same_folder_names() {
        let text = "import { x } from './a.js'; import \"b.js\"; from 'https://x/y.js' \
                    src=\"c.png\" href=\"/abs.css\" href=\"data:,\" from '${v}'";
        assert_eq!(references(text), ["a.js", "b.js", "c.png"]);
    }
}
