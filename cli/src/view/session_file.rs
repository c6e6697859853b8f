//! The session file: the object's source and the edit log as JSON, which
//! `trilux view --replay` turns back into exactly the same session
//! (numbers are written with the shortest text that reads back to the
//! same `f64`, media as their coefficients).
//!
//! ```json
//! {"format": "trilux-session", "version": 1,
//!  "source": {"mesh": null, "material": "marble", "unit_mm": 1},
//!  "refined_initially": true,
//!  "edits": [{"refined": true, "op": "lights",
//!             "lights": [{"kind": "dir", "dir": [0.3, 1, 0.6], "rgb": [1, 1, 1]}]}]}
//! ```

use std::path::Path;

use serde_json::{Value, json};
use tet_diffusion::glam::DVec3;
use tet_diffusion::{Cut, Edit, Light, Log, Logged, Medium, Stroke};

/// The `format` field.
pub const FORMAT: &str = "trilux-session";

fn v3(v: DVec3) -> Value {
    json!([v.x, v.y, v.z])
}

fn medium(m: &Medium) -> Value {
    json!({"sigma_a": m.sigma_a, "sigma_s_prime": m.sigma_s_prime})
}

fn light(l: &Light) -> Result<Value, String> {
    match l {
        Light::Directional {
            to_light,
            irradiance,
        } => Ok(json!({"kind": "dir", "dir": v3(*to_light), "rgb": irradiance})),
        Light::Point {
            position,
            intensity,
        } => Ok(json!({"kind": "point", "pos": v3(*position), "rgb": intensity})),
        Light::Environment(_) => Err("environment-map lights are not saved in sessions".into()),
    }
}

/// One edit as JSON.
///
/// # Errors
/// For an environment-map light, which the file cannot hold.
pub fn encode(e: &Edit) -> Result<Value, String> {
    Ok(match e {
        Edit::Paint(dabs) => json!({"op": "paint", "dabs": dabs.iter().map(|d| json!({
            "points": d.points.iter().map(|&p| v3(p)).collect::<Vec<_>>(),
            "radius": d.radius, "strength": d.strength, "medium": medium(&d.medium),
        })).collect::<Vec<_>>()}),
        Edit::Lights(l) => {
            json!({"op": "lights", "lights": l.iter().map(light).collect::<Result<Vec<_>, _>>()?})
        }
        Edit::Material(m) => json!({"op": "material", "medium": medium(m)}),
        Edit::Cut(Cut::Plane { point, normal }) => {
            json!({"op": "cut", "plane": {"point": v3(*point), "normal": v3(*normal)}})
        }
        Edit::Cut(Cut::Stroke { points, view }) => json!({"op": "cut", "stroke": {
            "points": points.iter().map(|&p| v3(p)).collect::<Vec<_>>(), "view": v3(*view)}}),
        Edit::Fracture {
            piece,
            point,
            normal,
        } => json!({"op": "fracture", "piece": piece, "point": v3(*point), "normal": v3(*normal)}),
        Edit::Move { piece, offset } => {
            json!({"op": "move", "piece": piece, "offset": v3(*offset)})
        }
        Edit::Recombine { a, b } => json!({"op": "recombine", "a": a, "b": b}),
    })
}

fn num(v: &Value, at: &str) -> Result<f64, String> {
    v.as_f64().ok_or_else(|| format!("{at}: expected a number"))
}

fn vec3(v: &Value, at: &str) -> Result<DVec3, String> {
    match v.as_array().map(Vec::as_slice) {
        Some([x, y, z]) => Ok(DVec3::new(num(x, at)?, num(y, at)?, num(z, at)?)),
        _ => Err(format!("{at}: expected [x, y, z]")),
    }
}

fn rgb(v: &Value, at: &str) -> Result<[f64; 3], String> {
    vec3(v, at).map(|v| v.to_array())
}

fn field<'a>(v: &'a Value, key: &str, at: &str) -> Result<&'a Value, String> {
    v.get(key).ok_or_else(|| format!("{at}.{key}: missing"))
}

fn index(v: &Value, key: &str, at: &str) -> Result<usize, String> {
    field(v, key, at)?
        .as_u64()
        .map(|i| i as usize)
        .ok_or_else(|| format!("{at}.{key}: expected an index"))
}

fn decode_medium(v: &Value, at: &str) -> Result<Medium, String> {
    Ok(Medium {
        sigma_a: rgb(field(v, "sigma_a", at)?, &format!("{at}.sigma_a"))?,
        sigma_s_prime: rgb(
            field(v, "sigma_s_prime", at)?,
            &format!("{at}.sigma_s_prime"),
        )?,
    })
}

fn points(v: &Value, at: &str) -> Result<Vec<DVec3>, String> {
    v.as_array()
        .ok_or_else(|| format!("{at}: expected an array"))?
        .iter()
        .enumerate()
        .map(|(k, p)| vec3(p, &format!("{at}[{k}]")))
        .collect()
}

/// One edit from JSON; `at` names it in errors (`edits[3]`).
///
/// # Errors
/// A message naming the field.
pub fn decode(v: &Value, at: &str) -> Result<Edit, String> {
    let op = field(v, "op", at)?.as_str().unwrap_or_default();
    Ok(match op {
        "paint" => {
            let dabs = field(v, "dabs", at)?
                .as_array()
                .ok_or_else(|| format!("{at}.dabs: expected an array"))?;
            Edit::Paint(
                dabs.iter()
                    .enumerate()
                    .map(|(k, d)| {
                        let at = format!("{at}.dabs[{k}]");
                        Ok(Stroke {
                            points: points(field(d, "points", &at)?, &format!("{at}.points"))?,
                            radius: num(field(d, "radius", &at)?, &format!("{at}.radius"))?,
                            strength: num(field(d, "strength", &at)?, &format!("{at}.strength"))?,
                            medium: decode_medium(
                                field(d, "medium", &at)?,
                                &format!("{at}.medium"),
                            )?,
                        })
                    })
                    .collect::<Result<_, String>>()?,
            )
        }
        "lights" => {
            let l = field(v, "lights", at)?
                .as_array()
                .ok_or_else(|| format!("{at}.lights: expected an array"))?;
            Edit::Lights(
                l.iter()
                    .enumerate()
                    .map(|(k, l)| {
                        let at = format!("{at}.lights[{k}]");
                        let color = rgb(field(l, "rgb", &at)?, &format!("{at}.rgb"))?;
                        match field(l, "kind", &at)?.as_str() {
                            Some("dir") => Ok(Light::Directional {
                                to_light: vec3(field(l, "dir", &at)?, &format!("{at}.dir"))?,
                                irradiance: color,
                            }),
                            Some("point") => Ok(Light::Point {
                                position: vec3(field(l, "pos", &at)?, &format!("{at}.pos"))?,
                                intensity: color,
                            }),
                            _ => Err(format!("{at}.kind: expected dir or point")),
                        }
                    })
                    .collect::<Result<_, String>>()?,
            )
        }
        "material" => Edit::Material(decode_medium(
            field(v, "medium", at)?,
            &format!("{at}.medium"),
        )?),
        "cut" => {
            if let Some(p) = v.get("plane") {
                let at = format!("{at}.plane");
                Edit::Cut(Cut::Plane {
                    point: vec3(field(p, "point", &at)?, &format!("{at}.point"))?,
                    normal: vec3(field(p, "normal", &at)?, &format!("{at}.normal"))?,
                })
            } else {
                let s = field(v, "stroke", at)?;
                let at = format!("{at}.stroke");
                Edit::Cut(Cut::Stroke {
                    points: points(field(s, "points", &at)?, &format!("{at}.points"))?,
                    view: vec3(field(s, "view", &at)?, &format!("{at}.view"))?,
                })
            }
        }
        "fracture" => Edit::Fracture {
            piece: index(v, "piece", at)?,
            point: vec3(field(v, "point", at)?, &format!("{at}.point"))?,
            normal: vec3(field(v, "normal", at)?, &format!("{at}.normal"))?,
        },
        "move" => Edit::Move {
            piece: index(v, "piece", at)?,
            offset: vec3(field(v, "offset", at)?, &format!("{at}.offset"))?,
        },
        "recombine" => Edit::Recombine {
            a: index(v, "a", at)?,
            b: index(v, "b", at)?,
        },
        other => return Err(format!("{at}.op: unknown edit {other:?}")),
    })
}

/// The whole file as JSON.
///
/// # Errors
/// As [`encode`].
pub fn to_json(source: &Value, log: &Log) -> Result<Value, String> {
    let edits = log
        .edits
        .iter()
        .map(|l| {
            let mut v = encode(&l.edit)?;
            v["refined"] = json!(l.refined);
            Ok(v)
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(json!({
        "format": FORMAT, "version": 1, "source": source,
        "refined_initially": log.refined_initially, "edits": edits,
    }))
}

/// The source and log of a session file's text.
///
/// # Errors
/// A message naming the field.
pub fn from_json(text: &str) -> Result<(Value, Log), String> {
    let v: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    if v.get("format").and_then(Value::as_str) != Some(FORMAT) {
        return Err(format!("format: expected \"{FORMAT}\""));
    }
    if v.get("version").and_then(Value::as_u64) != Some(1) {
        return Err("version: expected 1".into());
    }
    let edits = field(&v, "edits", "(file)")?
        .as_array()
        .ok_or("edits: expected an array")?
        .iter()
        .enumerate()
        .map(|(k, e)| {
            let at = format!("edits[{k}]");
            Ok(Logged {
                edit: decode(e, &at)?,
                refined: e.get("refined").and_then(Value::as_bool).unwrap_or(true),
            })
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok((
        v.get("source").cloned().unwrap_or(Value::Null),
        Log {
            refined_initially: v
                .get("refined_initially")
                .and_then(Value::as_bool)
                .unwrap_or(true),
            edits,
        },
    ))
}

/// Writes the file atomically; an existing file only with `overwrite`.
///
/// # Errors
/// A message saying what failed.
pub fn write(path: &Path, source: &Value, log: &Log, overwrite: bool) -> Result<(), String> {
    let v = to_json(source, log)?;
    crate::output::write_atomic(path, overwrite, |tmp| {
        std::fs::write(tmp, format!("{v:#}\n")).map_err(|source| crate::Error::File {
            path: tmp.to_path_buf(),
            source,
        })
    })
    .map_err(|e| e.to_string())
}
