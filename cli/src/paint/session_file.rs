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

/// The file's JSON: the document's source, stamped with what its edits
/// replay on ([`stamp`]), and the edits, brushes named by the document's
/// scalar channels.
pub fn to_json(doc: &super::Document, edits: &[Edit]) -> Value {
    let mut source = doc.source.clone();
    if let Some(o) = source.as_object_mut() {
        o.insert("replays_on".into(), stamp(doc));
    }
    json!({
        "format": FORMAT,
        "version": VERSION,
        "source": source,
        "edits": edits.iter().map(|e| edit(e, &doc.scalars)).collect::<Vec<_>>(),
    })
}

/// What a log replays on, bit for bit: the surface's connectivity (its
/// fingerprint) and the starting colours (their layout and a hash of
/// their bits).
pub fn stamp(doc: &super::Document) -> Value {
    let f = doc.colors.topology().fingerprint();
    // FNV-1a over the sample bits: the same start, the same hash.
    let hash = doc
        .colors
        .samples()
        .iter()
        .fold(0xcbf2_9ce4_8422_2325u64, |h, x| {
            (h ^ u64::from(x.to_bits())).wrapping_mul(0x0100_0000_01b3)
        });
    json!({
        "vertices": f.vertices, "faces": f.faces,
        "topology_hash": format!("{:016x}", f.topology_hash),
        "samples": doc.colors.sample_count(), "channels": doc.colors.channels(),
        "colors_hash": format!("{hash:016x}"),
    })
}

/// Checks that a session file's `source` was stamped for `doc`: the log
/// replays to the same colours only on the surface and starting colours
/// it was made on.
///
/// # Errors
/// What differs, in words.
pub fn check_replays_on(source: &Value, doc: &super::Document) -> Result<(), String> {
    let Some(theirs) = source.get("replays_on") else {
        return Err("source.replays_on: missing (not a session trilux paint wrote)".into());
    };
    let ours = stamp(doc);
    let same = |keys: &[&str]| keys.iter().all(|k| theirs.get(*k) == ours.get(*k));
    if !same(&["vertices", "faces", "topology_hash"]) {
        return Err(format!(
            "the session was painted on a surface of {} vertices and {} faces, not this one ({} and {}, or the same counts with other faces): replay it on the mesh it was made on",
            theirs["vertices"], theirs["faces"], ours["vertices"], ours["faces"]
        ));
    }
    if !same(&["samples", "channels", "colors_hash"]) {
        return Err(format!(
            "the session started from other colours ({} samples of {} channels, hash {}; here {} of {}, hash {}): start from the same --colors, --texture, --resolution and --channels",
            theirs["samples"],
            theirs["channels"],
            theirs["colors_hash"],
            ours["samples"],
            ours["channels"],
            ours["colors_hash"]
        ));
    }
    Ok(())
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
        let surface = crate::ColorMesh::new(&crate::shapes::blob(1)).unwrap();
        let colors = mesh_colors::MeshColors::uniform(surface.topology().unwrap(), 2, 4).unwrap();
        let doc = super::super::Document {
            surface,
            colors,
            base: vec![0.0; 4],
            scalars: scalars.clone(),
            source: json!({"mesh": "spot.obj"}),
        };
        let text = to_json(&doc, &edits).to_string();
        let (s, back) = from_json(&text, &scalars, 0.5).unwrap();
        assert_eq!(s["mesh"], "spot.obj");
        assert_eq!(back, edits);
        assert_eq!(check_replays_on(&s, &doc), Ok(()));
        // Other starting colours, another surface: refused, in words.
        let mut other = doc.clone();
        other.colors.samples_mut()[5] = 1.0;
        assert!(
            check_replays_on(&s, &other)
                .unwrap_err()
                .contains("other colours")
        );
        other.surface = crate::ColorMesh::new(&crate::shapes::blob(2)).unwrap();
        other.colors =
            mesh_colors::MeshColors::uniform(other.surface.topology().unwrap(), 2, 4).unwrap();
        assert!(
            check_replays_on(&s, &other)
                .unwrap_err()
                .contains("not this one")
        );
        assert!(check_replays_on(&json!({}), &doc).is_err());
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
