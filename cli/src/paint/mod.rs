//! `trilux paint`: Mesh Colors' 3D painting system (Yuksel, Keyser & House
//! 2010, Sec. 5.1) in the browser — an app of the [web core](crate::web)
//! over a [`PaintSession`], with the paper's real-time shader (Sec. 5.3)
//! in the page.
//!
//! The server owns the colours: strokes, fills and detail changes arrive
//! as messages ([`protocol`]), change the [`PaintSession`], and go down as
//! the texels of the packed layout ([`mesh_colors::gpu::GpuLayout`]) that
//! changed; the page draws the mesh with a fragment shader that filters
//! the samples per face as the CPU filters do. Nothing is lost: every
//! gesture is one undo step, the session's log replays bit for bit
//! (`--replay`), and the colours are autosaved atomically every few
//! strokes and when the server stops.
//!
//! Binary frames (magic `TLXM`, version [`VERSION`]), header fields as
//! [`crate::web::frame`]:
//!
//! | kind | `a`, `b` | payload |
//! |---|---|---|
//! | 1 mesh | vertices, faces | positions (3 f32 each), then triangles (3 u32 each) |
//! | 2 face table | width, height | `RGBA32UI` texels (4 u32 each) |
//! | 3 samples | width, height | `RGBA32F` texels (4 f32 each) |
//! | 4 sample texels | rectangles, width | per rectangle `x, y, w, h` (u32), then its `w·h` texels |
//! | 5 scatter points | points, 0 | positions (3 f32 each) |
//! | 6 strands | strands, points per strand | polylines' points (3 f32 each), strand by strand |
//! | 7 layout texels | sample rectangles, face-table rectangles | kind 4's rectangles of the samples, then the face table's the same way (`w·h` texels of 4 u32) |
//!
//! Kinds 4 and 7 carry absolute values: applied twice they change
//! nothing. A resolution change that fits the textures' room sends kind 7
//! (the resampled faces' new blocks, the MIP levels around them and the
//! face-table entries that point to them, as
//! [`mesh_colors::gpu::GpuLayout::refresh_resolutions`] reports them);
//! one that does not sends kinds 2 and 3 again, with spare rows.

use std::net::IpAddr;
use std::path::PathBuf;
use std::sync::Arc;

use glam::{Vec3, Vec3A};
use mesh_colors::MeshColors;
use mesh_colors::session::{Edit, Occluder, PaintSession};
use obvhs::BvhBuildParams;
use obvhs::bvh2::Bvh2;
use obvhs::ray::Ray;
use obvhs::triangle::Triangle;
use serde_json::Value;

use crate::colors::ColorMesh;
use crate::web::{self, Asset, Limits};

pub mod protocol;
mod reach;
pub mod scatter;
pub mod session_file;
mod worker;

pub use crate::web::Running;

/// The frames' magic.
pub const MAGIC: &[u8; 4] = b"TLXM";
/// The frames' version: bumped when a payload changes.
pub const VERSION: u8 = 1;

/// The page's limits: 256 KiB of text (a batch of dabs), no binary
/// messages, 200 messages a second (bursts of 400).
pub const LIMITS: Limits = Limits {
    text: 256 * 1024,
    binary: 0,
    rate: (200.0, 400.0),
};

/// The page's own files (served beside the core's).
pub const PAGE: &[Asset] = &[
    Asset::html("index.html", include_str!("page/index.html")),
    Asset::css("style.css", include_str!("page/style.css")),
    Asset::js("app.js", include_str!("page/app.js")),
    Asset::js("meshcolors.js", include_str!("page/meshcolors.js")),
    Asset::js("points.js", include_str!("page/points.js")),
];

/// What is painted: the welded surface, its colours, and how to name them.
#[derive(Debug, Clone)]
pub struct Document {
    /// The welded surface (positions relative to its `origin`).
    pub surface: ColorMesh,
    /// The colours at the start: RGB in channels 0–2, then the scalar
    /// channels.
    pub colors: MeshColors,
    /// What erase restores, one value per channel.
    pub base: Vec<f32>,
    /// The scalar channels' names (channels 3, 4, …).
    pub scalars: Vec<String>,
    /// How the surface was made (written into session files).
    pub source: Value,
}

impl Document {
    /// The model's name: its file's stem (`spot` for `spot.obj`), or
    /// `model` for the built-in one.
    pub fn model_name(&self) -> String {
        self.source["mesh"]
            .as_str()
            .and_then(|p| std::path::Path::new(p).file_stem())
            .map_or_else(|| "model".to_string(), |s| s.to_string_lossy().into_owned())
    }

    /// The surface's area, in model units squared (the scatter panel's
    /// rate is per unit area).
    pub fn area(&self) -> f64 {
        let s = &self.surface;
        let at = |v: u32| s.positions.get(v as usize).map(|p| p.as_dvec3());
        s.faces
            .iter()
            .filter_map(|&[a, b, c]| {
                let (a, b, c) = (at(a)?, at(b)?, at(c)?);
                Some(0.5 * (b - a).cross(c - a).length())
            })
            .sum()
    }

    /// The X symmetry plane: the middle of the bounding box in x.
    pub fn mirror_x(&self) -> f32 {
        let (lo, hi) = self.bounds();
        0.5 * (lo.x + hi.x)
    }

    /// The bounding box of the surface.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.surface.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        )
    }
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
    /// Folder saves and exports are written to.
    pub export_dir: PathBuf,
    /// Where the colours are autosaved (none: no autosave).
    pub autosave: Option<PathBuf>,
    /// Autosaves that earlier sessions of this model left (the page
    /// offers them: restart with `--colors` to resume one).
    pub earlier_autosaves: Vec<PathBuf>,
    /// Undo steps kept (within [`HISTORY_BYTES`]).
    pub history: usize,
}

/// The most bytes the undo steps may hold together, 256 MiB: the oldest
/// steps are dropped first, the newest always kept (a detail change keeps
/// the old samples of every face it resampled, megabytes for a large
/// brush, so a count of steps alone does not bound the memory).
pub const HISTORY_BYTES: usize = 256 << 20;

/// The page's textures' width and most rows (WebGL2 guarantees 2048).
pub const TEXTURE_WIDTH: u32 = 2048;

impl Default for Options {
    fn default() -> Self {
        Self {
            host: IpAddr::from([127, 0, 0, 1]),
            port: 0,
            token: None,
            export_dir: PathBuf::from("."),
            autosave: None,
            earlier_autosaves: Vec::new(),
            history: 200,
        }
    }
}

/// Starts a server painting `doc`, replaying `log` first when given.
///
/// # Errors
/// Binding the address, the token, or the replay (naming the edit).
pub async fn start(
    doc: Document,
    log: Option<Vec<Edit>>,
    options: Options,
) -> Result<Running, String> {
    let serve = web::Serve {
        host: options.host,
        port: options.port,
        token: options.token.clone(),
    };
    let bound = web::bind(&serve, <worker::Worker as web::App>::NAME).await?;
    let worker =
        tokio::task::spawn_blocking(move || worker::Worker::new(doc, log.as_deref(), options))
            .await
            .map_err(|e| e.to_string())??;
    bound.serve(worker)
}

/// The session over `doc`, with `log` replayed (an edit that fails names
/// its index in the log).
///
/// # Errors
/// The session's, or the first failing edit's.
pub fn open_session(doc: &Document, log: &[Edit], history: usize) -> Result<PaintSession, String> {
    let occluder: Arc<dyn Occluder> = Arc::new(SurfaceOccluder::new(&doc.surface));
    let mut session = PaintSession::new(
        doc.surface.positions.clone(),
        doc.colors.clone(),
        doc.base.clone(),
        history,
        Some(occluder),
    )
    .map_err(|e| e.to_string())?;
    // Before the replay, which then drops the steps the live session did.
    session.limit_history_bytes(HISTORY_BYTES);
    for (k, edit) in log.iter().enumerate() {
        session
            .apply(edit.clone())
            .map_err(|e| format!("the session file's edit {k}: {e}"))?;
    }
    Ok(session)
}

/// Ray casts against the surface (a BVH, `obvhs`): what hides a sample
/// from the painter's eye.
pub struct SurfaceOccluder {
    bvh: Bvh2,
    triangles: Vec<Triangle>,
    /// How close to the point a hit still counts as the point's own face:
    /// 10⁻⁴ of the bounding box's diagonal.
    slack: f32,
}

impl SurfaceOccluder {
    /// The tree over `surface`'s triangles.
    pub fn new(surface: &ColorMesh) -> Self {
        let p = &surface.positions;
        let triangles: Vec<Triangle> = surface
            .faces
            .iter()
            .map(|f| Triangle {
                v0: Vec3A::from(p[f[0] as usize]),
                v1: Vec3A::from(p[f[1] as usize]),
                v2: Vec3A::from(p[f[2] as usize]),
            })
            .collect();
        let bvh = obvhs::bvh2::builder::build_bvh2_from_tris(
            &triangles,
            BvhBuildParams::fast_build(),
            &mut std::time::Duration::default(),
        );
        let (lo, hi) = p.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &x| (lo.min(x), hi.max(x)),
        );
        let diagonal = (hi - lo).length();
        Self {
            bvh,
            triangles,
            slack: if diagonal.is_finite() {
                1e-4 * diagonal
            } else {
                0.0
            },
        }
    }
}

impl std::fmt::Debug for SurfaceOccluder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SurfaceOccluder")
            .field("triangles", &self.triangles.len())
            .field("slack", &self.slack)
            .finish()
    }
}

impl Occluder for SurfaceOccluder {
    fn blocked(&self, eye: Vec3, point: Vec3) -> bool {
        let d = point - eye;
        let distance = d.length();
        // NaN (a non-finite point) is never hidden.
        if distance.is_nan() || distance <= self.slack || self.triangles.is_empty() {
            return false;
        }
        let ray = Ray::new(
            Vec3A::from(eye),
            Vec3A::from(d / distance),
            0.0,
            distance - self.slack,
        );
        !self.bvh.ray_traverse_miss(ray, |ray, id| {
            self.triangles[self.bvh.primitive_indices[id] as usize].intersect(ray)
        })
    }
}

/// The body of a request without the token or with a wrong one.
pub const NEEDS_TOKEN: &str = "trilux paint: this address needs the full URL trilux printed when it \
started (it holds a secret token); copy that URL, or restart trilux paint for a new one\n";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_texts_are_the_cores_in_paints_name() {
        assert_eq!(NEEDS_TOKEN, web::guard::needs_token("paint"));
    }

    #[test]
    fn the_page_shadows_no_core_file_and_imports_only_served_files() {
        assert_eq!(web::assets::check_page(PAGE), Ok(()));
    }

    #[test]
    fn the_occluder_sees_the_near_side_and_not_the_far_side() {
        let surface = ColorMesh::new(&crate::shapes::blob(1)).unwrap();
        let o = SurfaceOccluder::new(&surface);
        let (lo, hi) = surface.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &x| (lo.min(x), hi.max(x)),
        );
        let eye = Vec3::new(0.0, 0.0, 10.0 * hi.z.abs().max(1.0));
        // The vertex nearest the eye is seen; the farthest is hidden.
        let by_z = |best: fn(f32, f32) -> bool| {
            surface
                .positions
                .iter()
                .copied()
                .reduce(|a, b| if best(b.z, a.z) { b } else { a })
                .unwrap()
        };
        let (near, far) = (by_z(|b, a| b > a), by_z(|b, a| b < a));
        assert!(far.z <= lo.z + 1e-6);
        assert!(!o.blocked(eye, near));
        assert!(o.blocked(eye, far));
    }
}
