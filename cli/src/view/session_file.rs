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
//!
//! `source` keeps `"envelope"` when the surface was stuffed with its
//! boundary fitted (`trilux view --envelope`), and also `"view"`, the direction from the object toward the
//! camera when the page saved the file: `trilux view --replay` starts
//! there and `trilux diffuse --session` renders from there unless given
//! `--view`.
//!
//! Edits of one gesture (a paint stroke, a light drag) carry its id as
//! `"gesture": N`, so a replayed session undoes them as one step.
//!
//! An environment-map light is saved as the name of its `.hdr` file
//! (`{"kind": "env", "file": "env-….hdr", "samples": 256}`), which the
//! server wrote beside the exports when the page uploaded it; a replay
//! reads it from the session file's folder.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use serde_json::{Value, json};
use tet_diffusion::glam::DVec3;
use tet_diffusion::{Cut, Edit, Environment, Light, Log, Logged, Medium, Stroke};

/// Environment maps and the `.hdr` file each was read from (a plain
/// file name, beside the session file).
pub type EnvFiles = Vec<(Arc<Environment>, String)>;

/// Directions an uploaded or replayed environment map is reduced to.
pub const ENV_SAMPLES: usize = 256;

/// The `format` field.
pub const FORMAT: &str = "trilux-session";

fn v3(v: DVec3) -> Value {
    json!([v.x, v.y, v.z])
}

fn medium(m: &Medium) -> Value {
    json!({"sigma_a": m.sigma_a, "sigma_s_prime": m.sigma_s_prime})
}

fn light(l: &Light, envs: &EnvFiles) -> Result<Value, String> {
    match l {
        Light::Directional {
            to_light,
            irradiance,
        } => Ok(json!({"kind": "dir", "dir": v3(*to_light), "rgb": irradiance})),
        Light::Point {
            position,
            intensity,
        } => Ok(json!({"kind": "point", "pos": v3(*position), "rgb": intensity})),
        Light::Environment(env) => envs
            .iter()
            .find(|(e, _)| Arc::ptr_eq(e, env))
            .map(|(_, file)| json!({"kind": "env", "file": file, "samples": ENV_SAMPLES}))
            .ok_or_else(|| {
                "an environment-map light not loaded from a file cannot be saved".into()
            }),
    }
}

/// One edit as JSON; `envs` names the environment maps' files.
///
/// # Errors
/// For an environment-map light not in `envs`.
pub fn encode(e: &Edit, envs: &EnvFiles) -> Result<Value, String> {
    Ok(match e {
        Edit::Paint(dabs) => json!({"op": "paint", "dabs": dabs.iter().map(|d| json!({
            "points": d.points.iter().map(|&p| v3(p)).collect::<Vec<_>>(),
            "radius": d.radius, "strength": d.strength, "medium": medium(&d.medium),
        })).collect::<Vec<_>>()}),
        Edit::Lights(l) => {
            json!({"op": "lights", "lights": l.iter().map(|l| light(l, envs)).collect::<Result<Vec<_>, _>>()?})
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
    decode_in(v, at, &mut Maps::default())
}

/// Environment maps a decoding read (by file name), and the folder it
/// reads them from.
#[derive(Default)]
struct Maps<'a> {
    dir: Option<&'a Path>,
    read: HashMap<String, Arc<Environment>>,
}

impl Maps<'_> {
    fn get(&mut self, file: &str, at: &str) -> Result<Arc<Environment>, String> {
        if let Some(e) = self.read.get(file) {
            return Ok(e.clone());
        }
        let plain = !file.is_empty()
            && !file.starts_with('.')
            && !file.contains(['/', '\\'])
            && file.ends_with(".hdr");
        if !plain {
            return Err(format!(
                "{at}: expected a plain .hdr file name, not {file:?}"
            ));
        }
        let dir = self
            .dir
            .ok_or_else(|| format!("{at}: environment maps are read beside a session file"))?;
        let bytes = std::fs::read(dir.join(file)).map_err(|e| format!("{at}: {file}: {e}"))?;
        let env = environment(&bytes, file).map_err(|e| format!("{at}: {e}"))?;
        self.read.insert(file.to_string(), env.clone());
        Ok(env)
    }
}

/// An environment map from a Radiance `.hdr` file's bytes (`name` labels
/// errors), reduced to [`ENV_SAMPLES`] directions.
///
/// # Errors
/// A message saying what is wrong (not an image, a black map, …).
pub fn environment(bytes: &[u8], name: &str) -> Result<Arc<Environment>, String> {
    let image = trilux_io::image::decode(bytes, name, trilux_io::image::ReadOptions::default())
        .map_err(|e| e.to_string())?;
    let rgb: Vec<[f32; 3]> = image.pixels.iter().map(|p| [p[0], p[1], p[2]]).collect();
    Environment::new(
        &rgb,
        image.width as usize,
        image.height as usize,
        ENV_SAMPLES,
    )
    .map(Arc::new)
    .map_err(|e| format!("{name}: {e}"))
}

fn decode_in(v: &Value, at: &str, maps: &mut Maps<'_>) -> Result<Edit, String> {
    let op = field(v, "op", at)?.as_str().unwrap_or_default();
    Ok(match op {
        "paint" => decode_paint(v, at)?,
        "lights" => decode_lights(v, at, maps)?,
        "material" => Edit::Material(decode_medium(
            field(v, "medium", at)?,
            &format!("{at}.medium"),
        )?),
        "cut" => decode_cut(v, at)?,
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

fn array<'a>(v: &'a Value, key: &str, at: &str) -> Result<&'a Vec<Value>, String> {
    field(v, key, at)?
        .as_array()
        .ok_or_else(|| format!("{at}.{key}: expected an array"))
}

fn decode_paint(v: &Value, at: &str) -> Result<Edit, String> {
    let dabs = array(v, "dabs", at)?
        .iter()
        .enumerate()
        .map(|(k, d)| {
            let at = format!("{at}.dabs[{k}]");
            Ok(Stroke {
                points: points(field(d, "points", &at)?, &format!("{at}.points"))?,
                radius: num(field(d, "radius", &at)?, &format!("{at}.radius"))?,
                strength: num(field(d, "strength", &at)?, &format!("{at}.strength"))?,
                medium: decode_medium(field(d, "medium", &at)?, &format!("{at}.medium"))?,
            })
        })
        .collect::<Result<_, String>>()?;
    Ok(Edit::Paint(dabs))
}

fn decode_lights(v: &Value, at: &str, maps: &mut Maps<'_>) -> Result<Edit, String> {
    let lights = array(v, "lights", at)?
        .iter()
        .enumerate()
        .map(|(k, l)| {
            let at = format!("{at}.lights[{k}]");
            if field(l, "kind", &at)?.as_str() == Some("env") {
                let file = field(l, "file", &at)?
                    .as_str()
                    .ok_or_else(|| format!("{at}.file: expected a file name"))?;
                return Ok(Light::Environment(maps.get(file, &format!("{at}.file"))?));
            }
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
                _ => Err(format!("{at}.kind: expected dir, point or env")),
            }
        })
        .collect::<Result<_, String>>()?;
    Ok(Edit::Lights(lights))
}

fn decode_cut(v: &Value, at: &str) -> Result<Edit, String> {
    Ok(Edit::Cut(if let Some(p) = v.get("plane") {
        let at = format!("{at}.plane");
        Cut::Plane {
            point: vec3(field(p, "point", &at)?, &format!("{at}.point"))?,
            normal: vec3(field(p, "normal", &at)?, &format!("{at}.normal"))?,
        }
    } else {
        let s = field(v, "stroke", at)?;
        let at = format!("{at}.stroke");
        Cut::Stroke {
            points: points(field(s, "points", &at)?, &format!("{at}.points"))?,
            view: vec3(field(s, "view", &at)?, &format!("{at}.view"))?,
        }
    }))
}

/// The whole file as JSON.
///
/// # Errors
/// As [`encode`].
pub fn to_json(source: &Value, log: &Log, envs: &EnvFiles) -> Result<Value, String> {
    let edits = log
        .edits
        .iter()
        .map(|l| {
            let mut v = encode(&l.edit, envs)?;
            v["refined"] = json!(l.refined);
            if let Some(g) = l.gesture {
                v["gesture"] = json!(g);
            }
            Ok(v)
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(json!({
        "format": FORMAT, "version": 1, "source": source,
        "refined_initially": log.refined_initially, "edits": edits,
    }))
}

/// The source and log of a session file's text (without environment
/// maps: see [`from_json_in`]).
///
/// # Errors
/// A message naming the field.
pub fn from_json(text: &str) -> Result<(Value, Log), String> {
    from_json_in(text, None).map(|(source, log, _)| (source, log))
}

/// The source, log and environment maps of a session file's text, the
/// maps' `.hdr` files read from `dir` (the session file's folder).
///
/// # Errors
/// A message naming the field (and the map's file when it cannot be
/// read).
pub fn from_json_in(text: &str, dir: Option<&Path>) -> Result<(Value, Log, EnvFiles), String> {
    let mut maps = Maps {
        dir,
        read: HashMap::new(),
    };
    let v: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    if v.get("format").and_then(Value::as_str) != Some(FORMAT) {
        return Err(format!("format: expected \"{FORMAT}\""));
    }
    if v.get("version").and_then(Value::as_u64) != Some(1) {
        return Err("version: expected 1".into());
    }
    let edits =
        field(&v, "edits", "(file)")?
            .as_array()
            .ok_or("edits: expected an array")?
            .iter()
            .enumerate()
            .map(|(k, e)| {
                let at = format!("edits[{k}]");
                Ok(Logged {
                    edit: decode_in(e, &at, &mut maps)?,
                    refined: e.get("refined").and_then(Value::as_bool).unwrap_or(true),
                    gesture: match e.get("gesture") {
                        None | Some(Value::Null) => None,
                        Some(g) => Some(g.as_u64().ok_or_else(|| {
                            format!("{at}.gesture: expected a non-negative integer")
                        })?),
                    },
                })
            })
            .collect::<Result<Vec<_>, String>>()?;
    let envs = maps.read.into_iter().map(|(file, e)| (e, file)).collect();
    Ok((
        v.get("source").cloned().unwrap_or(Value::Null),
        Log {
            refined_initially: v
                .get("refined_initially")
                .and_then(Value::as_bool)
                .unwrap_or(true),
            edits,
        },
        envs,
    ))
}

/// The camera direction a session file's `source` keeps (`"view"`, from
/// the object toward the camera), if any: exactly as saved, not
/// normalized, so that a replay frames the picture with the very vector
/// the page's export used (normalizing twice moves the eye by an ulp,
/// enough to change a pixel of the PNG).
///
/// # Errors
/// A message naming `source.view` when it is not three finite numbers
/// with a non-zero length.
pub fn saved_view(source: &Value) -> Result<Option<DVec3>, String> {
    let Some(v) = source.get("view").filter(|v| !v.is_null()) else {
        return Ok(None);
    };
    let bad = || {
        "source.view: expected three finite numbers, not all zero, within f32's range".to_string()
    };
    let a = v.as_array().filter(|a| a.len() == 3).ok_or_else(bad)?;
    let x: Vec<f64> = a
        .iter()
        .map(|x| x.as_f64().ok_or_else(bad))
        .collect::<Result<_, _>>()?;
    let d = DVec3::new(x[0], x[1], x[2]);
    // The camera works in f32: the direction must keep a length there.
    let f = d.as_vec3();
    if !d.is_finite() || !f.length_recip().is_finite() || f.length_recip() == 0.0 {
        return Err(bad());
    }
    Ok(Some(d))
}

/// Writes the file atomically; an existing file only with `overwrite`.
///
/// # Errors
/// A message saying what failed.
pub fn write(
    path: &Path,
    source: &Value,
    log: &Log,
    envs: &EnvFiles,
    view: Option<DVec3>,
    overwrite: bool,
) -> Result<(), String> {
    let mut source = source.clone();
    if let (Some(view), Some(o)) = (view, source.as_object_mut()) {
        o.insert("view".into(), v3(view));
    }
    let v = to_json(&source, log, envs)?;
    crate::output::write_atomic(path, overwrite, |tmp| {
        std::fs::write(tmp, format!("{v:#}\n")).map_err(|source| crate::Error::File {
            path: tmp.to_path_buf(),
            source,
        })
    })
    .map_err(|e| e.to_string())
}
