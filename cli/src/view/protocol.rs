//! The wire protocol of `trilux view`.
//!
//! **Up** (page → server): one JSON object per WebSocket text message,
//! `{"seq": N, "op": "...", ...}`; `seq` is the page's sequence number,
//! echoed in every answer to it. Ops: `paint`, `lights`, `material`,
//! `cut`, `fracture`, `move`, `recombine`, `undo`, `redo`, `probe`,
//! `export`, `hello` (see [`parse`]). Points are in the display frame,
//! mesh units. An edit may carry `"gesture": N`, an id the page gives
//! every message of one drag (a paint stroke, a light or piece drag): the
//! session undoes those as one step. One binary message uploads an environment map
//! ([`parse_upload`]): a 16-byte header — magic `TLXU`, version 1, kind 1
//! (environment), two zero bytes, the `seq` as u64 — then the Radiance
//! `.hdr` file's bytes, at most [`MAX_UPLOAD`]; no bytes remove the map.
//! A `lights` edit keeps the environment map loaded.
//!
//! **Down**: JSON text messages (`status`, `error`, `probe`, `export`,
//! `hello`) and binary frames: a fixed 16-byte header, then raw
//! little-endian arrays. The answers to one message (`error`, `probe`,
//! `export`) go to the page that sent it; `hello`, `status` and the
//! frames (the shared state) go to every page.
//!
//! | bytes | field |
//! |---|---|
//! | 0..4 | magic `TLXF` |
//! | 4 | version (1) |
//! | 5 | kind: 1 surface, 2 radiance |
//! | 6 | flags: bit 0 final (refined), bit 1 last piece of the set |
//! | 7 | piece index |
//! | 8..12 | `a`: vertices |
//! | 12..16 | `b`: triangles (surface) or the edit's `seq` (radiance) |
//!
//! A surface frame (sent only when the topology changed) holds `a × 3`
//! f32 positions, `a × 3` f32 normals, `b × 3` u32 indices; a radiance
//! frame `a × 3` f32 linear RGB radiance per surface vertex at normal
//! exitance (Eq. 3 with `F_t(η, 0°)`; the page applies the view-dependent
//! `F_t(ω_o)/F_t(0°)` per fragment).

use serde_json::{Map, Value};
use tet_diffusion::glam::DVec3;
use tet_diffusion::{Cut, Edit, Light, Medium, Stroke};

use crate::web::frame::Header;
pub use crate::web::frame::{HEADER, put_f32, put_u32};
pub use crate::web::json::{BadField, seq_of};
use crate::web::json::{Incoming, Parsed, get, nonzero, number, vec3};

/// Magic of binary frames.
pub const MAGIC: &[u8; 4] = b"TLXF";
/// Version of the binary frames.
pub const VERSION: u8 = 1;
/// Kind of a surface frame.
pub const SURFACE: u8 = 1;
/// Kind of a radiance frame.
pub const RADIANCE: u8 = 2;
/// Flag: the radiance is the refined (final) solution.
pub const FINAL: u8 = 1;
/// Flag: the last piece of this set of frames.
pub const LAST: u8 = 2;

/// Most points in one stroke, dabs in one paint message, lights.
pub const MAX_POINTS: usize = 4096;
/// Most lights.
pub const MAX_LIGHTS: usize = 16;
/// Magic of an upload (page → server binary message).
pub const UPLOAD_MAGIC: &[u8; 4] = b"TLXU";
/// Kind of an environment-map upload.
pub const UPLOAD_ENVIRONMENT: u8 = 1;
/// Largest upload (header included): a 4096 × 2048 RGBE map is 32 MiB
/// uncompressed.
pub const MAX_UPLOAD: usize = 40 << 20;

/// A message from the page, parsed and checked.
#[derive(Debug, Clone)]
pub enum Request {
    /// An edit of the session, and the gesture it belongs to (the
    /// message's optional `gesture`: one paint stroke or light or piece
    /// drag, undone as one step).
    Edit(Edit, Option<u64>),
    /// Undo the last edit.
    Undo,
    /// Redo the last undone edit.
    Redo,
    /// What is under a point: material and radiance of the nearest
    /// surface vertex of a piece.
    Probe {
        /// The piece.
        piece: usize,
        /// The point, display frame.
        point: DVec3,
    },
    /// Write a file into the export folder.
    Export {
        /// `png`, `exr`, `vtu`, `glb`, `tet` (TetGen .node/.ele) or
        /// `session`.
        kind: ExportKind,
        /// A plain file name (no folder).
        name: String,
        /// Picture size for png/exr (and the picture whose exposure a
        /// glb's vertex colours take).
        size: u32,
        /// Replace an existing file (the page asked the user).
        overwrite: bool,
        /// Direction from the object toward the camera, for pictures.
        view: Option<DVec3>,
    },
    /// The page (re)connected: send everything.
    Hello,
    /// Light the object by this environment map (a Radiance `.hdr`
    /// file's bytes, not yet decoded), in addition to the other lights;
    /// empty: remove the environment map.
    Environment {
        /// The file's bytes.
        hdr: Vec<u8>,
    },
}

/// What an export writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportKind {
    /// The picture as the CLI renders it, tone-mapped PNG.
    Png,
    /// The same picture, linear EXR.
    Exr,
    /// φ and radiance per node, ParaView.
    Vtu,
    /// The boundary surface with its radiance as vertex colours (at the
    /// PNG's exposure), the radiance and φ as attributes: binary glTF,
    /// written by the server ([`crate::tet::write_radiance_gltf`]).
    Glb,
    /// The tet mesh, TetGen .node (+ .ele beside it).
    Tet,
    /// The session file (`trilux view --replay`).
    Session,
}

impl ExportKind {
    /// The file extension.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Png => "png",
            Self::Exr => "exr",
            Self::Vtu => "vtu",
            Self::Glb => "glb",
            Self::Tet => "node",
            Self::Session => "json",
        }
    }

    /// The files an export to `path` writes: `path`, and for a tet mesh
    /// the `.ele` beside the `.node`.
    pub fn files(self, path: &std::path::Path) -> Vec<std::path::PathBuf> {
        match self {
            Self::Tet => vec![path.to_path_buf(), path.with_extension("ele")],
            _ => vec![path.to_path_buf()],
        }
    }
}

fn rgb(v: Option<&Value>, field: &str) -> Parsed<[f64; 3]> {
    match v {
        None => Ok([1.0; 3]),
        Some(v) => {
            let c = vec3(v, field)?;
            if c.min_element() < 0.0 || c.max_element() > 1e6 {
                return Err(BadField::new(field, "each channel must be in [0, 1e6]"));
            }
            Ok(c.to_array())
        }
    }
}

fn index(v: &Value, field: &str) -> Parsed<usize> {
    v.as_u64()
        .filter(|&i| i < 256)
        .map(|i| i as usize)
        .ok_or_else(|| BadField::new(field, "expected a piece index 0..255"))
}

fn points(v: &Value, field: &str, least: usize) -> Parsed<Vec<DVec3>> {
    let a = v
        .as_array()
        .ok_or_else(|| BadField::new(field, "expected an array of [x, y, z]"))?;
    if a.len() < least || a.len() > MAX_POINTS {
        return Err(BadField::new(
            field,
            format!("expected {least} to {MAX_POINTS} points, found {}", a.len()),
        ));
    }
    a.iter()
        .enumerate()
        .map(|(k, p)| vec3(p, &format!("{field}[{k}]")))
        .collect()
}

/// A measured medium by name.
pub fn medium(v: &Value, field: &str) -> Parsed<Medium> {
    let name = v
        .as_str()
        .ok_or_else(|| BadField::new(field, "expected a material name"))?;
    Medium::measured(name).map_err(|_| {
        let names: Vec<&str> = tet_diffusion::MEASURED.iter().map(|m| m.0).collect();
        BadField::new(
            field,
            format!("unknown material {name:?} (one of {})", names.join(", ")),
        )
    })
}

/// Parses one binary message (an upload, see the [module docs](self)).
///
/// # Errors
/// A [`BadField`] naming `(upload)`: too short, another magic, version or
/// kind, or larger than [`MAX_UPLOAD`].
pub fn parse_upload(bytes: &[u8]) -> Result<(u64, Request), BadField> {
    let bad = |problem: String| BadField::new("(upload)", problem);
    if bytes.len() > MAX_UPLOAD {
        return Err(bad(format!(
            "{} bytes: at most {MAX_UPLOAD} bytes may be uploaded",
            bytes.len()
        )));
    }
    if bytes.len() < HEADER || &bytes[..4] != UPLOAD_MAGIC {
        return Err(bad(format!(
            "expected a {HEADER}-byte header starting with {:?}",
            std::str::from_utf8(UPLOAD_MAGIC).unwrap_or_default()
        )));
    }
    if bytes[4] != VERSION {
        return Err(bad(format!("version {}: expected {VERSION}", bytes[4])));
    }
    if bytes[5] != UPLOAD_ENVIRONMENT {
        return Err(bad(format!(
            "kind {}: expected {UPLOAD_ENVIRONMENT} (an environment map)",
            bytes[5]
        )));
    }
    let mut seq = [0u8; 8];
    seq.copy_from_slice(&bytes[8..16]);
    Ok((
        u64::from_le_bytes(seq),
        Request::Environment {
            hdr: bytes[HEADER..].to_vec(),
        },
    ))
}

/// The header of an environment-map upload of `seq` (what the page
/// writes before the file's bytes).
pub fn upload_header(seq: u64) -> [u8; HEADER] {
    let mut h = [0u8; HEADER];
    h[..4].copy_from_slice(UPLOAD_MAGIC);
    h[4] = VERSION;
    h[5] = UPLOAD_ENVIRONMENT;
    h[8..].copy_from_slice(&seq.to_le_bytes());
    h
}

/// Parses one message.
///
/// # Errors
/// A [`BadField`] naming the first bad field.
pub fn parse(text: &str) -> Result<(u64, Request), BadField> {
    crate::web::json::parse(text, parse_incoming)
}

/// Parses one message's op and fields (its envelope read by the core).
///
/// # Errors
/// A [`BadField`] naming the first bad field.
pub fn parse_incoming(m: &Incoming<'_>) -> Result<Request, BadField> {
    let o = m.fields;
    let request = match m.op {
        "hello" => Request::Hello,
        "undo" => Request::Undo,
        "redo" => Request::Redo,
        "paint" => paint(o)?,
        "material" => Request::Edit(
            Edit::Material(medium(get(o, "material")?, "material")?),
            None,
        ),
        "lights" => lights(o)?,
        "cut" => cut(o)?,
        "fracture" => Request::Edit(
            Edit::Fracture {
                piece: index(get(o, "piece")?, "piece")?,
                point: vec3(get(o, "point")?, "point")?,
                normal: nonzero(vec3(get(o, "normal")?, "normal")?, "normal")?,
            },
            None,
        ),
        "move" => Request::Edit(
            Edit::Move {
                piece: index(get(o, "piece")?, "piece")?,
                offset: vec3(get(o, "offset")?, "offset")?,
            },
            None,
        ),
        "recombine" => {
            let a = index(get(o, "a")?, "a")?;
            let b = index(get(o, "b")?, "b")?;
            if a == b {
                return Err(BadField::new("b", "must differ from a"));
            }
            Request::Edit(Edit::Recombine { a, b }, None)
        }
        "probe" => Request::Probe {
            piece: index(get(o, "piece")?, "piece")?,
            point: vec3(get(o, "point")?, "point")?,
        },
        "export" => export(o)?,
        other => {
            return Err(BadField::new("op", format!("unknown op {other:?}")));
        }
    };
    Ok(match request {
        Request::Edit(edit, _) => Request::Edit(edit, gesture(o)?),
        other => other,
    })
}

/// The optional `gesture` of an edit message: an id the page gives all
/// the messages of one drag.
fn gesture(o: &Map<String, Value>) -> Result<Option<u64>, BadField> {
    match o.get("gesture") {
        None | Some(Value::Null) => Ok(None),
        Some(g) => g
            .as_u64()
            .map(Some)
            .ok_or_else(|| BadField::new("gesture", "expected a non-negative integer")),
    }
}

/// A paint stroke of one or more points.
fn paint(o: &Map<String, Value>) -> Result<Request, BadField> {
    let m = medium(get(o, "material")?, "material")?;
    let radius = number(get(o, "radius")?, "radius")?;
    if radius <= 0.0 {
        return Err(BadField::new("radius", "must be positive"));
    }
    let strength = number(get(o, "strength")?, "strength")?;
    if !(0.0..=1.0).contains(&strength) {
        return Err(BadField::new("strength", "must be in [0, 1]"));
    }
    let pts = points(get(o, "points")?, "points", 1)?;
    Ok(Request::Edit(
        Edit::Paint(vec![Stroke {
            points: pts,
            radius,
            medium: m,
            strength,
        }]),
        None,
    ))
}

/// The scene's lights (replacing all of them).
fn lights(o: &Map<String, Value>) -> Result<Request, BadField> {
    let a = get(o, "lights")?
        .as_array()
        .ok_or_else(|| BadField::new("lights", "expected an array"))?;
    if a.len() > MAX_LIGHTS {
        return Err(BadField::new(
            "lights",
            format!("at most {MAX_LIGHTS} lights"),
        ));
    }
    let mut lights = Vec::with_capacity(a.len());
    for (k, l) in a.iter().enumerate() {
        let f = |name: &str| format!("lights[{k}].{name}");
        let lo = l
            .as_object()
            .ok_or_else(|| BadField::new(format!("lights[{k}]"), "expected an object"))?;
        let kind = lo
            .get("kind")
            .and_then(Value::as_str)
            .ok_or_else(|| BadField::new(f("kind"), "expected \"dir\" or \"point\""))?;
        let color = rgb(lo.get("rgb"), &f("rgb"))?;
        lights.push(match kind {
            "dir" => Light::Directional {
                to_light: nonzero(
                    vec3(
                        lo.get("dir")
                            .ok_or_else(|| BadField::new(f("dir"), "missing"))?,
                        &f("dir"),
                    )?,
                    &f("dir"),
                )?,
                irradiance: color,
            },
            "point" => Light::Point {
                position: vec3(
                    lo.get("pos")
                        .ok_or_else(|| BadField::new(f("pos"), "missing"))?,
                    &f("pos"),
                )?,
                intensity: color,
            },
            other => {
                return Err(BadField::new(
                    f("kind"),
                    format!("unknown kind {other:?} (dir or point)"),
                ));
            }
        });
    }
    Ok(Request::Edit(Edit::Lights(lights), None))
}

/// A cut by a plane or a screen stroke.
fn cut(o: &Map<String, Value>) -> Result<Request, BadField> {
    Ok(if let Some(p) = o.get("plane") {
        let po = p
            .as_object()
            .ok_or_else(|| BadField::new("plane", "expected {point, normal}"))?;
        Request::Edit(
            Edit::Cut(Cut::Plane {
                point: vec3(
                    get(po, "point").map_err(|_| missing("plane.point"))?,
                    "plane.point",
                )?,
                normal: nonzero(
                    vec3(
                        get(po, "normal").map_err(|_| missing("plane.normal"))?,
                        "plane.normal",
                    )?,
                    "plane.normal",
                )?,
            }),
            None,
        )
    } else if let Some(s) = o.get("stroke") {
        let so = s
            .as_object()
            .ok_or_else(|| BadField::new("stroke", "expected {points, view}"))?;
        Request::Edit(
            Edit::Cut(Cut::Stroke {
                points: points(
                    get(so, "points").map_err(|_| missing("stroke.points"))?,
                    "stroke.points",
                    2,
                )?,
                view: nonzero(
                    vec3(
                        get(so, "view").map_err(|_| missing("stroke.view"))?,
                        "stroke.view",
                    )?,
                    "stroke.view",
                )?,
            }),
            None,
        )
    } else {
        return Err(BadField::new("plane", "a cut needs plane or stroke"));
    })
}

/// An export: its kind, file name, size, overwrite flag and view.
fn export(o: &Map<String, Value>) -> Result<Request, BadField> {
    let kind = match get(o, "kind")?.as_str() {
        Some("png") => ExportKind::Png,
        Some("exr") => ExportKind::Exr,
        Some("vtu") => ExportKind::Vtu,
        Some("glb") => ExportKind::Glb,
        Some("tet") => ExportKind::Tet,
        Some("session") => ExportKind::Session,
        _ => {
            return Err(BadField::new(
                "kind",
                "expected png, exr, vtu, glb, tet or session",
            ));
        }
    };
    let name = get(o, "name")?
        .as_str()
        .ok_or_else(|| BadField::new("name", "expected a file name"))?
        .to_string();
    check_name(&name, kind)?;
    let size = match o.get("size") {
        None => 1024,
        Some(v) => v
            .as_u64()
            .filter(|s| (16..=8192).contains(s))
            .ok_or_else(|| BadField::new("size", "expected 16 to 8192 pixels"))?
            as u32,
    };
    let overwrite = match o.get("overwrite") {
        None => false,
        Some(v) => v
            .as_bool()
            .ok_or_else(|| BadField::new("overwrite", "expected true or false"))?,
    };
    let view = match o.get("view") {
        None => None,
        Some(v) => Some(nonzero(vec3(v, "view")?, "view")?),
    };
    Ok(Request::Export {
        kind,
        name,
        size,
        overwrite,
        view,
    })
}

fn missing(field: &str) -> BadField {
    BadField::new(field, "missing")
}

/// A plain file name with the kind's extension: no folder, no leading
/// dot, at most 128 characters of letters, digits, `-`, `_`, `.`.
fn check_name(name: &str, kind: ExportKind) -> Parsed<()> {
    crate::web::json::file_name(name, kind.extension())
}

/// A binary frame: the header, then `payload`.
pub fn frame(kind: u8, flags: u8, piece: u8, a: u32, b: u32, payload: &[u8]) -> Vec<u8> {
    Header {
        magic: *MAGIC,
        version: VERSION,
        kind,
        flags,
        tag: piece,
        a,
        b,
    }
    .frame(payload)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_op_parses_and_bad_fields_are_named() {
        let ok = [
            r#"{"seq":1,"op":"paint","material":"ketchup","radius":0.1,"strength":1,"points":[[0,0,0]]}"#,
            r#"{"seq":2,"op":"lights","lights":[{"kind":"dir","dir":[0,1,0]},{"kind":"point","pos":[0,2,0],"rgb":[5,5,5]}]}"#,
            r#"{"seq":3,"op":"cut","plane":{"point":[0,0,0],"normal":[1,0,0]}}"#,
            r#"{"seq":4,"op":"cut","stroke":{"points":[[0,0,0],[1,0,0]],"view":[0,0,-1]}}"#,
            r#"{"seq":5,"op":"fracture","piece":0,"point":[0,0,0],"normal":[0,1,0]}"#,
            r#"{"seq":6,"op":"move","piece":1,"offset":[0,0.5,0]}"#,
            r#"{"seq":7,"op":"recombine","a":0,"b":1}"#,
            r#"{"seq":8,"op":"undo"}"#,
            r#"{"seq":9,"op":"redo"}"#,
            r#"{"seq":10,"op":"material","material":"apple"}"#,
            r#"{"seq":11,"op":"probe","piece":0,"point":[0,0,0]}"#,
            r#"{"seq":12,"op":"export","kind":"png","name":"a.png","size":256}"#,
            r#"{"seq":12,"op":"export","kind":"glb","name":"a.GLB","size":256}"#,
            r#"{"seq":13,"op":"hello"}"#,
        ];
        for m in ok {
            assert!(parse(m).is_ok(), "{m}: {:?}", parse(m));
        }
        let bad = [
            ("{", "(message)"),
            ("[1]", "(message)"),
            (r#"{"op":"undo"}"#, "seq"),
            (r#"{"seq":1,"op":"nope"}"#, "op"),
            (
                r#"{"seq":1,"op":"paint","material":"ketchup","radius":-1,"strength":1,"points":[[0,0,0]]}"#,
                "radius",
            ),
            (
                r#"{"seq":1,"op":"paint","material":"tar","radius":1,"strength":1,"points":[[0,0,0]]}"#,
                "material",
            ),
            (
                r#"{"seq":1,"op":"paint","material":"apple","radius":1,"strength":1,"points":[[0,"x",0]]}"#,
                "points[0][1]",
            ),
            (
                r#"{"seq":1,"op":"lights","lights":[{"kind":"dir","dir":[0,0,0]}]}"#,
                "lights[0].dir",
            ),
            (
                r#"{"seq":1,"op":"cut","stroke":{"points":[[0,0,0]],"view":[0,0,1]}}"#,
                "stroke.points",
            ),
            (
                r#"{"seq":1,"op":"export","kind":"png","name":"../x.png"}"#,
                "name",
            ),
            (
                r#"{"seq":1,"op":"export","kind":"png","name":"x.exr"}"#,
                "name",
            ),
            (
                r#"{"seq":1,"op":"export","kind":"glb","name":"x.gltf"}"#,
                "name",
            ),
            (
                r#"{"seq":1,"op":"export","kind":"gltf","name":"x.gltf"}"#,
                "kind",
            ),
            (r#"{"seq":1,"op":"recombine","a":1,"b":1}"#, "b"),
            (
                r#"{"seq":1,"op":"move","piece":1,"offset":[0,0,0],"gesture":-3}"#,
                "gesture",
            ),
            (
                r#"{"seq":1,"op":"move","piece":1,"offset":[1e999,0,0]}"#,
                "(message)",
            ),
        ];
        for (m, field) in bad {
            let e = parse(m).unwrap_err();
            assert_eq!(e.field, field, "{m}: {e:?}");
        }
    }

    #[test]
    fn an_edit_carries_its_gesture() {
        let m = r#"{"seq":1,"op":"lights","gesture":77,"lights":[{"kind":"dir","dir":[0,1,0]}]}"#;
        assert!(matches!(
            parse(m),
            Ok((1, Request::Edit(Edit::Lights(_), Some(77))))
        ));
        let m = r#"{"seq":2,"op":"material","material":"apple"}"#;
        assert!(matches!(parse(m), Ok((2, Request::Edit(_, None)))));
    }

    #[test]
    fn frames_have_the_fixed_header() {
        let mut p = Vec::new();
        put_f32(&mut p, [1.0, 2.0]);
        let f = frame(RADIANCE, FINAL | LAST, 3, 7, 9, &p);
        assert_eq!(&f[..4], MAGIC);
        assert_eq!(f[4..8], [VERSION, RADIANCE, 3, 3]);
        assert_eq!(u32::from_le_bytes(f[8..12].try_into().unwrap()), 7);
        assert_eq!(u32::from_le_bytes(f[12..16].try_into().unwrap()), 9);
        assert_eq!(f32::from_le_bytes(f[20..24].try_into().unwrap()), 2.0);
    }
}
