//! A `trilux paint` session as a file: how the surface and its starting
//! colours were made (`source`) and every edit, in the shapes of the
//! protocol's messages. `trilux paint --replay FILE` replays it to the
//! same colours, bit for bit.
//!
//! ```json
//! {"format": "trilux-paint-session", "version": 1,
//!  "source": {"mesh": "spot.obj", "colors": null, "texture": null, "resolution": 8},
//!  "edits": [{"op": "stroke", "brush": {…}, "dabs": [[x, y, z, r, p], …]},
//!            {"op": "detail", "center": [x, y, z], "radius": r, "levels": 1},
//!            {"op": "undo"}, …]}
//! ```

use mesh_colors::session::{Brush, BrushMode, Edit};
use serde_json::{Value, json};

use super::protocol::{self, BrushSpec};
use crate::web::json::{Parsed, get};

/// The `format` field.
pub const FORMAT: &str = "trilux-paint-session";
/// The `version` field.
pub const VERSION: u64 = 1;

/// The file's JSON: `source` and the edits, brushes named by `scalars`
/// (the scalar channels' names).
pub fn to_json(source: &Value, edits: &[Edit], scalars: &[String]) -> Value {
    json!({
        "format": FORMAT,
        "version": VERSION,
        "source": source,
        "edits": edits.iter().map(|e| edit(e, scalars)).collect::<Vec<_>>(),
    })
}

fn edit(e: &Edit, scalars: &[String]) -> Value {
    match e {
        Edit::Stroke { brush: b, dabs } => json!({
            "op": "stroke",
            "brush": brush(b, scalars),
            "dabs": dabs
                .iter()
                .map(|d| [d.center.x, d.center.y, d.center.z, d.radius, d.pressure])
                .collect::<Vec<_>>(),
        }),
        Edit::Fill { face, brush: b } => {
            json!({"op": "fill", "face": face, "brush": brush(b, scalars)})
        }
        Edit::Detail {
            center,
            radius,
            levels,
        } => {
            json!({"op": "detail", "center": center.to_array(), "radius": radius, "levels": levels})
        }
        Edit::Resolution { level } => json!({"op": "resolution", "level": level}),
        Edit::Undo => json!({"op": "undo"}),
        Edit::Redo => json!({"op": "redo"}),
    }
}

fn brush(b: &Brush, scalars: &[String]) -> Value {
    let channel = match b.first_channel {
        0 => "color".to_string(),
        k => scalars.get(k - 3).cloned().unwrap_or_default(),
    };
    json!({
        "mode": match b.mode {
            BrushMode::Mix => "mix",
            BrushMode::Add => "add",
            BrushMode::Multiply => "multiply",
            BrushMode::Erase => "erase",
        },
        "channel": channel,
        "color": b.color,
        "strength": b.strength,
        "hardness": b.hardness,
        "mirror": b.mirror_x.is_some(),
        "eye": b.eye.map(|e| e.to_array()),
    })
}

/// Reads a session file's text: its `source` and edits, brushes resolved
/// against `scalars` and the mirror plane `mirror_x`.
///
/// # Errors
/// `FIELD: problem`, the field named from the file's top (`edits[3].brush.mode`).
pub fn from_json(
    text: &str,
    scalars: &[String],
    mirror_x: f32,
) -> Result<(Value, Vec<Edit>), String> {
    let v: Value = serde_json::from_str(text).map_err(|e| format!("not JSON ({e})"))?;
    let at = |field: &str, problem: &str| format!("{field}: {problem}");
    if v.get("format").and_then(Value::as_str) != Some(FORMAT) {
        return Err(at("format", &format!("expected {FORMAT:?}")));
    }
    if v.get("version").and_then(Value::as_u64) != Some(VERSION) {
        return Err(at("version", &format!("expected {VERSION}")));
    }
    let source = v.get("source").cloned().unwrap_or(Value::Null);
    let edits = v
        .get("edits")
        .and_then(Value::as_array)
        .ok_or_else(|| at("edits", "expected a list"))?;
    let edits = edits
        .iter()
        .enumerate()
        .map(|(k, e)| {
            logged(e, scalars, mirror_x)
                .map_err(|b| at(&format!("edits[{k}].{}", b.field), &b.problem))
        })
        .collect::<Result<_, _>>()?;
    Ok((source, edits))
}

/// One logged edit (a protocol message's shape; `stroke` holds its brush
/// and dabs together).
fn logged(v: &Value, scalars: &[String], mirror_x: f32) -> Parsed<Edit> {
    let o = v
        .as_object()
        .ok_or_else(|| crate::web::BadField::new("op", "expected an object"))?;
    let op = get(o, "op")?
        .as_str()
        .ok_or_else(|| crate::web::BadField::new("op", "expected a string"))?;
    let resolve = |spec: BrushSpec| spec.resolve(scalars, mirror_x);
    if op == "stroke" {
        let spec = protocol::brush(get(o, "brush")?)?;
        return Ok(Edit::Stroke {
            brush: resolve(spec)?,
            dabs: protocol::dabs(get(o, "dabs")?)?,
        });
    }
    let incoming = crate::web::Incoming {
        seq: 0,
        op,
        fields: o,
    };
    match protocol::parse(&incoming)? {
        protocol::Request::Edit(e) => Ok(e),
        protocol::Request::Fill(face, spec) => Ok(Edit::Fill {
            face,
            brush: resolve(spec)?,
        }),
        _ => Err(crate::web::BadField::new(
            "op",
            format!("{op:?} is not an edit (stroke, fill, detail, resolution, undo, redo)"),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use mesh_colors::session::Dab;

    #[test]
    fn every_edit_round_trips() {
        let scalars = vec!["density".to_string()];
        let b = |first_channel: usize, color: Vec<f32>| Brush {
            mode: BrushMode::Multiply,
            color,
            first_channel,
            strength: 0.75,
            hardness: 0.3,
            mirror_x: Some(0.5),
            eye: Some(Vec3::new(0.1, 2.0, -3.0)),
        };
        let edits = vec![
            Edit::Stroke {
                brush: b(0, vec![0.1, 0.2, 0.3]),
                dabs: vec![Dab {
                    center: Vec3::new(0.25, 1.0 / 3.0, -7.5),
                    radius: 0.1,
                    pressure: 0.6,
                }],
            },
            Edit::Fill {
                face: 7,
                brush: Brush {
                    mirror_x: None,
                    eye: None,
                    ..b(3, vec![0.9])
                },
            },
            Edit::Detail {
                center: Vec3::new(1.0, 2.0, 3.0),
                radius: 0.25,
                levels: -2,
            },
            Edit::Resolution { level: 4 },
            Edit::Undo,
            Edit::Redo,
        ];
        let source = json!({"mesh": "spot.obj"});
        let text = to_json(&source, &edits, &scalars).to_string();
        let (s, back) = from_json(&text, &scalars, 0.5).unwrap();
        assert_eq!(s, source);
        assert_eq!(back, edits);
    }

    #[test]
    fn a_bad_file_names_the_entry() {
        let scalars: Vec<String> = Vec::new();
        let cases = [
            ("{", "not JSON"),
            (r#"{"format":"x"}"#, "format:"),
            (
                r#"{"format":"trilux-paint-session","version":9}"#,
                "version:",
            ),
            (
                r#"{"format":"trilux-paint-session","version":1,"edits":[{"op":"undo"},{"op":"detail","center":[0,0,0],"radius":-1,"levels":1}]}"#,
                "edits[1].radius:",
            ),
            (
                r#"{"format":"trilux-paint-session","version":1,"edits":[{"op":"stroke","brush":{"mode":"mix","channel":"density","color":[1],"strength":1,"hardness":1},"dabs":[]}]}"#,
                "edits[0].brush.channel:",
            ),
            (
                r#"{"format":"trilux-paint-session","version":1,"edits":[{"op":"save","name":"a.meshcolors"}]}"#,
                "edits[0].op:",
            ),
        ];
        for (text, needle) in cases {
            let e = from_json(text, &scalars, 0.0).unwrap_err();
            assert!(e.contains(needle), "{text}: {e}");
        }
    }
}
