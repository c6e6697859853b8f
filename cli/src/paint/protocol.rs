//! What the paint page sends, parsed and checked before the session sees
//! it. Every message is `{"seq": N, "op": …, …}` ([`crate::web::json`]);
//! a bad one gets an error naming the field and changes nothing.
//!
//! | op | fields | what |
//! |---|---|---|
//! | `begin` | `brush` | starts a stroke |
//! | `dabs` | `dabs`: `[[x, y, z, radius, pressure], …]` | paints them with the stroke's brush |
//! | `end` | | ends the stroke: one undo step |
//! | `fill` | `face`, `brush` | the connected part containing `face` |
//! | `detail` | `center`, `radius`, `levels` (±1..±4) | raises or lowers the faces under it |
//! | `resolution` | `level` (0..=7) | every face at resolution 2^level |
//! | `undo`, `redo` | | one step |
//! | `pick` | `face`, `barycentric` | the eyedropper: answers `{"type": "pick", "color"}` |
//! | `save` | `name` (`.meshcolors`), `overwrite` | writes the colours |
//! | `export` | `kind` (`glb`, `obj`, `session`, `points`, `strands`), `name`, `overwrite` | bakes an atlas (GLB, or OBJ + MTL + PNG), writes the session log, the scatter's points (`.glb` or `.ply`) or its strands (`.usda`, `.glb` or `.hair`) |
//! | `scatter` | see [`ScatterSpec`](super::scatter::ScatterSpec) | points (and strands) where a channel is painted, following every stroke |
//!
//! A `brush` is `{"mode": "mix" | "add" | "multiply" | "erase", "channel":
//! "color" | a scalar channel's name, "color": [r, g, b] or [v], "strength",
//! "hardness" (0–1), "mirror": bool, "eye": [x, y, z] or null}`.

use glam::Vec3;
use mesh_colors::session::{Brush, BrushMode, Dab, Edit};
use serde_json::{Map, Value};

use crate::web::json::{Parsed, get, number, vec3};
use crate::web::{BadField, Incoming};

/// Most dabs in one message (a fast drag at 60 events/s sends a few).
pub const MAX_DABS: usize = 1024;

/// A parsed request.
#[derive(Debug, Clone, PartialEq)]
pub enum Request {
    /// Start a stroke.
    Begin(BrushSpec),
    /// Paint these dabs with the open stroke's brush.
    Dabs(Vec<Dab>),
    /// End the stroke.
    End,
    /// A fill: the face and the brush.
    Fill(usize, BrushSpec),
    /// Any other edit (detail, resolution, undo, redo).
    Edit(Edit),
    /// The eyedropper at a face's barycentrics.
    Pick(usize, [f32; 3]),
    /// Write the colours to a `.meshcolors` file.
    Save {
        /// The file name (no folder).
        name: String,
        /// Replace an existing file.
        overwrite: bool,
    },
    /// Scatter points by a channel (and grow strands), or stop.
    Scatter(super::scatter::ScatterSpec),
    /// Write an export.
    Export {
        /// What.
        kind: ExportKind,
        /// The file name (no folder).
        name: String,
        /// Replace an existing file.
        overwrite: bool,
    },
}

/// A brush as the page names it: the channel by name, the mirror as a
/// switch (the server knows the mesh's plane).
#[derive(Debug, Clone, PartialEq)]
pub struct BrushSpec {
    /// How the colour is combined.
    pub mode: BrushMode,
    /// `"color"` or a scalar channel's name.
    pub channel: String,
    /// The values (3 for colour, 1 for a scalar channel).
    pub color: Vec<f32>,
    /// 0 to 1.
    pub strength: f32,
    /// 0 to 1.
    pub hardness: f32,
    /// Mirror across the mesh's X plane.
    pub mirror: bool,
    /// The camera's position, for painting only what it sees.
    pub eye: Option<Vec3>,
}

impl BrushSpec {
    /// The session's brush: `channels` names every channel in order
    /// (colour's three first, as `"color"`), `mirror_x` is the plane.
    ///
    /// # Errors
    /// `brush.channel` when no channel has the name, `brush.color` when
    /// its length does not fit the channel.
    pub fn resolve(&self, scalars: &[String], mirror_x: f32) -> Parsed<Brush> {
        let (first, width) = if self.channel == "color" {
            (0, 3)
        } else {
            let k = scalars
                .iter()
                .position(|s| *s == self.channel)
                .ok_or_else(|| {
                    BadField::new(
                        "brush.channel",
                        format!("no channel named {:?} (color or {scalars:?})", self.channel),
                    )
                })?;
            (3 + k, 1)
        };
        if self.color.len() != width {
            return Err(BadField::new(
                "brush.color",
                format!("expected {width} values for channel {:?}", self.channel),
            ));
        }
        Ok(Brush {
            mode: self.mode,
            color: self.color.clone(),
            first_channel: first,
            strength: self.strength,
            hardness: self.hardness,
            mirror_x: self.mirror.then_some(mirror_x),
            eye: self.eye,
        })
    }
}

/// What `export` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportKind {
    /// The surface with the colours baked into a texture atlas, glTF
    /// binary.
    Glb,
    /// The same as OBJ + MTL + PNG.
    Obj,
    /// The session: source and edit log (replays with `--replay`).
    Session,
    /// The scatter's points (`.glb` or `.ply`).
    Points,
    /// The scatter's strands (`.usda`, `.glb` or `.hair`).
    Strands,
}

impl ExportKind {
    /// The file extensions it writes.
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            ExportKind::Glb => &["glb"],
            ExportKind::Obj => &["obj"],
            ExportKind::Session => &["json"],
            ExportKind::Points => &["glb", "ply"],
            ExportKind::Strands => &["usda", "glb", "hair"],
        }
    }
}

/// Parses one message's op and fields.
///
/// # Errors
/// The first bad field.
pub fn parse(m: &Incoming<'_>) -> Parsed<Request> {
    let o = m.fields;
    Ok(match m.op {
        "begin" => Request::Begin(brush(get(o, "brush")?)?),
        "dabs" => Request::Dabs(dabs(get(o, "dabs")?)?),
        "end" => Request::End,
        "fill" => Request::Fill(face(o)?, brush(get(o, "brush")?)?),
        "detail" => Request::Edit(Edit::Detail {
            center: vec3(get(o, "center")?, "center")?.as_vec3(),
            radius: positive(get(o, "radius")?, "radius")?,
            levels: levels(get(o, "levels")?)?,
        }),
        "resolution" => Request::Edit(Edit::Resolution {
            level: level(get(o, "level")?)?,
        }),
        "undo" => Request::Edit(Edit::Undo),
        "redo" => Request::Edit(Edit::Redo),
        "pick" => Request::Pick(face(o)?, barycentric(get(o, "barycentric")?)?),
        "scatter" => Request::Scatter(super::scatter::parse(o)?),
        "save" => Request::Save {
            name: file_name(get(o, "name")?, "meshcolors")?,
            overwrite: overwrite(o)?,
        },
        "export" => {
            let kind = match get(o, "kind")?.as_str() {
                Some("glb") => ExportKind::Glb,
                Some("obj") => ExportKind::Obj,
                Some("session") => ExportKind::Session,
                Some("points") => ExportKind::Points,
                Some("strands") => ExportKind::Strands,
                _ => {
                    return Err(BadField::new(
                        "kind",
                        "expected glb, obj, session, points or strands",
                    ));
                }
            };
            Request::Export {
                kind,
                name: file_name_of(get(o, "name")?, kind.extensions())?,
                overwrite: overwrite(o)?,
            }
        }
        _ => {
            return Err(BadField::new(
                "op",
                format!(
                    "unknown op {:?} (begin, dabs, end, fill, detail, resolution, undo, redo, pick, scatter, save, export)",
                    m.op
                ),
            ));
        }
    })
}

pub(crate) fn brush(v: &Value) -> Parsed<BrushSpec> {
    let o = v
        .as_object()
        .ok_or_else(|| BadField::new("brush", "expected an object"))?;
    let mode = match get(o, "mode").map_err(|_| missing("brush.mode"))?.as_str() {
        Some("mix") => BrushMode::Mix,
        Some("add") => BrushMode::Add,
        Some("multiply") => BrushMode::Multiply,
        Some("erase") => BrushMode::Erase,
        _ => {
            return Err(BadField::new(
                "brush.mode",
                "expected mix, add, multiply or erase",
            ));
        }
    };
    let channel = get(o, "channel")
        .map_err(|_| missing("brush.channel"))?
        .as_str()
        .ok_or_else(|| BadField::new("brush.channel", "expected a channel name"))?
        .to_string();
    let color = get(o, "color")
        .map_err(|_| missing("brush.color"))?
        .as_array()
        .filter(|a| (1..=4).contains(&a.len()))
        .ok_or_else(|| BadField::new("brush.color", "expected 1 to 4 numbers"))?
        .iter()
        .enumerate()
        .map(|(k, x)| finite_f32(x, &format!("brush.color[{k}]")))
        .collect::<Parsed<Vec<f32>>>()?;
    let unit = |key: &str| -> Parsed<f32> {
        let field = format!("brush.{key}");
        let x = number(get(o, key).map_err(|_| missing(&field))?, &field)?;
        if !(0.0..=1.0).contains(&x) {
            return Err(BadField::new(field, "expected 0 to 1"));
        }
        Ok(x as f32)
    };
    let mirror = match o.get("mirror") {
        None => false,
        Some(v) => v
            .as_bool()
            .ok_or_else(|| BadField::new("brush.mirror", "expected true or false"))?,
    };
    let eye = match o.get("eye") {
        None | Some(Value::Null) => None,
        Some(v) => Some(f32_vec3(v, "brush.eye")?),
    };
    Ok(BrushSpec {
        mode,
        channel,
        color,
        strength: unit("strength")?,
        hardness: unit("hardness")?,
        mirror,
        eye,
    })
}

fn missing(field: &str) -> BadField {
    BadField::new(field, "missing")
}

pub(crate) fn dabs(v: &Value) -> Parsed<Vec<Dab>> {
    let a = v
        .as_array()
        .ok_or_else(|| BadField::new("dabs", "expected [[x, y, z, radius, pressure], …]"))?;
    if a.len() > MAX_DABS {
        return Err(BadField::new(
            "dabs",
            format!("{} dabs, more than {MAX_DABS} in one message", a.len()),
        ));
    }
    a.iter()
        .enumerate()
        .map(|(k, d)| {
            let field = format!("dabs[{k}]");
            let x = d
                .as_array()
                .filter(|x| x.len() == 5)
                .ok_or_else(|| BadField::new(&field, "expected [x, y, z, radius, pressure]"))?;
            let n = |i: usize| finite_f32(&x[i], &format!("{field}[{i}]"));
            let (radius, pressure) = (n(3)?, n(4)?);
            if radius <= 0.0 {
                return Err(BadField::new(
                    format!("{field}[3]"),
                    "the radius must be positive",
                ));
            }
            if !(0.0..=1.0).contains(&pressure) {
                return Err(BadField::new(
                    format!("{field}[4]"),
                    "the pressure must be 0 to 1",
                ));
            }
            Ok(Dab {
                center: Vec3::new(n(0)?, n(1)?, n(2)?),
                radius,
                pressure,
            })
        })
        .collect()
}

/// A number finite in f32 (a huge f64 is not).
fn finite_f32(v: &Value, field: &str) -> Parsed<f32> {
    let x = number(v, field)? as f32;
    if !x.is_finite() {
        return Err(BadField::new(field, "beyond f32's range"));
    }
    Ok(x)
}

fn f32_vec3(v: &Value, field: &str) -> Parsed<Vec3> {
    let p = vec3(v, field)?.as_vec3();
    if !p.is_finite() {
        return Err(BadField::new(field, "beyond f32's range"));
    }
    Ok(p)
}

fn positive(v: &Value, field: &str) -> Parsed<f32> {
    let x = finite_f32(v, field)?;
    if x <= 0.0 {
        return Err(BadField::new(field, "must be positive"));
    }
    Ok(x)
}

fn face(o: &Map<String, Value>) -> Parsed<usize> {
    get(o, "face")?
        .as_u64()
        .and_then(|f| usize::try_from(f).ok())
        .ok_or_else(|| BadField::new("face", "expected a face index"))
}

fn barycentric(v: &Value) -> Parsed<[f32; 3]> {
    let p = f32_vec3(v, "barycentric")?;
    if p.min_element() < 0.0 || (p.element_sum() - 1.0).abs() > 1e-3 {
        return Err(BadField::new(
            "barycentric",
            "expected three weights ≥ 0 that sum to 1",
        ));
    }
    Ok(p.to_array())
}

fn levels(v: &Value) -> Parsed<i8> {
    v.as_i64()
        .filter(|l| *l != 0 && l.abs() <= 4)
        .map(|l| l as i8)
        .ok_or_else(|| BadField::new("levels", "expected ±1 to ±4"))
}

fn level(v: &Value) -> Parsed<u8> {
    v.as_u64()
        .filter(|l| *l <= u64::from(mesh_colors::MAX_LEVEL))
        .map(|l| l as u8)
        .ok_or_else(|| BadField::new("level", format!("expected 0 to {}", mesh_colors::MAX_LEVEL)))
}

fn overwrite(o: &Map<String, Value>) -> Parsed<bool> {
    match o.get("overwrite") {
        None => Ok(false),
        Some(v) => v
            .as_bool()
            .ok_or_else(|| BadField::new("overwrite", "expected true or false")),
    }
}

/// A plain file name ending in `.ext`: no folder, no hidden file.
fn file_name(v: &Value, ext: &str) -> Parsed<String> {
    let name = v
        .as_str()
        .ok_or_else(|| BadField::new("name", "expected a file name"))?;
    crate::web::json::file_name(name, ext)?;
    Ok(name.to_string())
}

/// A plain file name ending in one of `extensions` (the first one's
/// error when none fits).
fn file_name_of(v: &Value, extensions: &[&str]) -> Parsed<String> {
    let name = v
        .as_str()
        .ok_or_else(|| BadField::new("name", "expected a file name"))?;
    let lower = name.to_ascii_lowercase();
    let ext = extensions
        .iter()
        .find(|e| lower.ends_with(&format!(".{e}")))
        .unwrap_or(&extensions[0]);
    if extensions.len() > 1 && !lower.ends_with(&format!(".{ext}")) {
        return Err(BadField::new(
            "name",
            format!(
                "{name:?}: expected a name ending in .{}",
                extensions.join(", .")
            ),
        ));
    }
    file_name(v, ext)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parsed(text: &str) -> Parsed<Request> {
        crate::web::json::parse(text, parse).map(|(_, r)| r)
    }

    #[test]
    fn every_op_parses() {
        let b = r#"{"mode":"mix","channel":"color","color":[1,0,0],"strength":1,"hardness":0.5,"mirror":true,"eye":[0,0,5]}"#;
        let ok = [
            format!(r#"{{"seq":1,"op":"begin","brush":{b}}}"#),
            r#"{"seq":2,"op":"dabs","dabs":[[0,0,1,0.1,1],[0.1,0,1,0.1,0.5]]}"#.into(),
            r#"{"seq":3,"op":"end"}"#.into(),
            format!(r#"{{"seq":4,"op":"fill","face":3,"brush":{b}}}"#),
            r#"{"seq":5,"op":"detail","center":[0,0,1],"radius":0.2,"levels":1}"#.into(),
            r#"{"seq":6,"op":"resolution","level":3}"#.into(),
            r#"{"seq":7,"op":"undo"}"#.into(),
            r#"{"seq":8,"op":"pick","face":0,"barycentric":[0.2,0.3,0.5]}"#.into(),
            r#"{"seq":9,"op":"save","name":"cow.meshcolors"}"#.into(),
            r#"{"seq":10,"op":"export","kind":"glb","name":"cow.glb","overwrite":true}"#.into(),
        ];
        for t in ok {
            assert!(parsed(&t).is_ok(), "{t}: {:?}", parsed(&t));
        }
        let Ok(Request::Begin(spec)) = parsed(&format!(r#"{{"seq":1,"op":"begin","brush":{b}}}"#))
        else {
            unreachable!()
        };
        let brush = spec.resolve(&[], 0.25).unwrap();
        assert_eq!(brush.mirror_x, Some(0.25));
        assert_eq!(brush.eye, Some(Vec3::new(0.0, 0.0, 5.0)));
    }

    #[test]
    fn bad_fields_are_named() {
        let b = r#""mode":"mix","channel":"color","color":[1,0,0],"strength":1,"hardness":0.5"#;
        let cases = [
            (
                format!(r#"{{"seq":1,"op":"begin","brush":{{{b},"mode":"smear"}}}}"#),
                "brush.mode",
            ),
            (
                format!(r#"{{"seq":1,"op":"begin","brush":{{{b},"strength":2}}}}"#),
                "brush.strength",
            ),
            (
                format!(r#"{{"seq":1,"op":"begin","brush":{{{b},"color":[1,"x",0]}}}}"#),
                "brush.color[1]",
            ),
            (
                format!(r#"{{"seq":1,"op":"begin","brush":{{{b},"eye":[0,1e300,0]}}}}"#),
                "brush.eye",
            ),
            (
                r#"{"seq":1,"op":"dabs","dabs":[[0,0,1,0.1,1],[0,0,1,-1,1]]}"#.into(),
                "dabs[1][3]",
            ),
            (
                r#"{"seq":1,"op":"dabs","dabs":[[0,0,1,0.1,7]]}"#.into(),
                "dabs[0][4]",
            ),
            (
                r#"{"seq":1,"op":"dabs","dabs":[[0,0,1]]}"#.into(),
                "dabs[0]",
            ),
            (
                r#"{"seq":1,"op":"detail","center":[0,0,1],"radius":0.2,"levels":9}"#.into(),
                "levels",
            ),
            (r#"{"seq":1,"op":"resolution","level":99}"#.into(), "level"),
            (
                r#"{"seq":1,"op":"pick","face":0,"barycentric":[0.9,0.9,0.9]}"#.into(),
                "barycentric",
            ),
            (
                r#"{"seq":1,"op":"save","name":"../x.meshcolors"}"#.into(),
                "name",
            ),
            (r#"{"seq":1,"op":"save","name":"x.png"}"#.into(), "name"),
            (
                r#"{"seq":1,"op":"export","kind":"exe","name":"x.exe"}"#.into(),
                "kind",
            ),
            (r#"{"seq":1,"op":"smudge"}"#.into(), "op"),
        ];
        for (t, field) in cases {
            assert_eq!(parsed(&t).unwrap_err().field, field, "{t}");
        }
        let many = format!(
            r#"{{"seq":1,"op":"dabs","dabs":[{}]}}"#,
            vec!["[0,0,0,1,1]"; MAX_DABS + 1].join(",")
        );
        assert_eq!(parsed(&many).unwrap_err().field, "dabs");
    }

    #[test]
    fn a_brush_names_its_channel() {
        let spec = BrushSpec {
            mode: BrushMode::Add,
            channel: "density".into(),
            color: vec![0.5],
            strength: 1.0,
            hardness: 0.0,
            mirror: false,
            eye: None,
        };
        let scalars = ["roughness".to_string(), "density".to_string()];
        assert_eq!(spec.resolve(&scalars, 0.0).unwrap().first_channel, 4);
        assert_eq!(
            spec.resolve(&scalars[..1], 0.0).unwrap_err().field,
            "brush.channel"
        );
        let wide = BrushSpec {
            color: vec![1.0, 2.0],
            ..spec
        };
        assert_eq!(
            wide.resolve(&scalars, 0.0).unwrap_err().field,
            "brush.color"
        );
    }
}
