//! The JSON every app's messages share: the `{"seq": N, "op": "...", …}`
//! envelope, [`BadField`] (what a refused message's error names), the
//! error message, and validators for the common field types.

use serde_json::{Map, Value, json};
use tet_diffusion::glam::DVec3;

/// A bad message: the field (JSON path) and what is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct BadField {
    /// The field, as a JSON path (`dabs[3].radius`), or a whole-message
    /// problem in parentheses (`(message)`, `(rate)`, `(upload)`).
    pub field: String,
    /// What is wrong with it.
    pub problem: String,
}

impl BadField {
    /// `field` is wrong: `problem`.
    pub fn new(field: impl Into<String>, problem: impl Into<String>) -> Self {
        Self {
            field: field.into(),
            problem: problem.into(),
        }
    }
}

/// A parsed result, or the first bad field.
pub type Parsed<T> = Result<T, BadField>;

/// One text message from the page: its `seq`, `op` and all its fields
/// (`seq` and `op` included).
#[derive(Debug, Clone, Copy)]
pub struct Incoming<'a> {
    /// The page's sequence number, echoed in every answer to it.
    pub seq: u64,
    /// The operation.
    pub op: &'a str,
    /// The message's fields.
    pub fields: &'a Map<String, Value>,
}

/// The envelope of a text message already read as JSON: an object with
/// a non-negative integer `seq` and a string `op`.
///
/// # Errors
/// `(message)` when it is not an object; `seq` or `op` when missing or
/// of the wrong type.
pub fn incoming(v: &Value) -> Parsed<Incoming<'_>> {
    let fields = v
        .as_object()
        .ok_or_else(|| BadField::new("(message)", "expected a JSON object"))?;
    let seq = get(fields, "seq")?
        .as_u64()
        .ok_or_else(|| BadField::new("seq", "expected a non-negative integer"))?;
    let op = get(fields, "op")?
        .as_str()
        .ok_or_else(|| BadField::new("op", "expected a string"))?;
    Ok(Incoming { seq, op, fields })
}

/// Reads `text` as JSON.
///
/// # Errors
/// `(message)`: not JSON.
pub fn read(text: &str) -> Parsed<Value> {
    serde_json::from_str(text).map_err(|e| BadField::new("(message)", format!("not JSON: {e}")))
}

/// Parses a text message: the envelope, then its op by `op`.
///
/// # Errors
/// The first bad field.
pub fn parse<R>(text: &str, op: impl FnOnce(&Incoming<'_>) -> Parsed<R>) -> Parsed<(u64, R)> {
    let v = read(text)?;
    let m = incoming(&v)?;
    Ok((m.seq, op(&m)?))
}

/// The `seq` of a message, if it has a usable one (echoed in errors).
pub fn seq_of(v: &Value) -> Option<u64> {
    v.get("seq").and_then(Value::as_u64)
}

/// The error message answering `seq` (`null` when the message had none):
/// `{"type": "error", "seq", "field", "message"}`. Every error a page
/// gets is made here or by [`error_with`].
pub fn error(seq: Option<u64>, field: &str, message: &str) -> String {
    error_with(seq, field, message, &[])
}

/// [`error`] with more fields (view's `exists`); they cannot replace the
/// four every error has.
pub fn error_with(seq: Option<u64>, field: &str, message: &str, extra: &[(&str, Value)]) -> String {
    let mut e = Map::new();
    for (k, v) in extra {
        e.insert((*k).to_string(), v.clone());
    }
    e.insert("type".into(), json!("error"));
    e.insert("seq".into(), json!(seq));
    e.insert("field".into(), json!(field));
    e.insert("message".into(), json!(message));
    Value::Object(e).to_string()
}

/// The field `key` of `o`.
///
/// # Errors
/// `key`: missing.
pub fn get<'a>(o: &'a Map<String, Value>, key: &str) -> Parsed<&'a Value> {
    o.get(key).ok_or_else(|| BadField::new(key, "missing"))
}

/// A finite number.
///
/// # Errors
/// `field`: not a finite number.
pub fn number(v: &Value, field: &str) -> Parsed<f64> {
    v.as_f64()
        .filter(|x| x.is_finite())
        .ok_or_else(|| BadField::new(field, "expected a finite number"))
}

/// `[x, y, z]` of finite numbers.
///
/// # Errors
/// `field` (or `field[i]` for a bad element).
pub fn vec3(v: &Value, field: &str) -> Parsed<DVec3> {
    let a = v
        .as_array()
        .filter(|a| a.len() == 3)
        .ok_or_else(|| BadField::new(field, "expected [x, y, z]"))?;
    Ok(DVec3::new(
        number(&a[0], &format!("{field}[0]"))?,
        number(&a[1], &format!("{field}[1]"))?,
        number(&a[2], &format!("{field}[2]"))?,
    ))
}

/// `v`, refused when it is the zero vector.
///
/// # Errors
/// `field`: must not be zero.
pub fn nonzero(v: DVec3, field: &str) -> Parsed<DVec3> {
    if v.length_squared() == 0.0 {
        return Err(BadField::new(field, "must not be zero"));
    }
    Ok(v)
}

/// A plain file name ending in `.ext` (any case): letters of any script,
/// digits, inner spaces and `- _ . ( ) + ,`, at most 128 bytes, no folder
/// and no hidden file, so a page can only name files inside the export
/// folder.
///
/// # Errors
/// `name`: what is wrong with it.
pub fn file_name(name: &str, ext: &str) -> Parsed<()> {
    // Any letters (`kráva.glb`) and inner spaces (`my cow.glb`); never a
    // folder, a hidden or reserved name, or a character some file system
    // refuses.
    let plain = !name.is_empty()
        && name.len() <= 128
        && !name.starts_with(['.', ' '])
        && !name.ends_with(' ')
        && name.chars().all(|c| {
            c.is_alphanumeric() || matches!(c, '-' | '_' | '.' | ' ' | '(' | ')' | '+' | ',')
        });
    if !plain {
        return Err(BadField::new(
            "name",
            "expected a plain file name (letters, digits, spaces, - _ . ( ) + ,), no folder",
        ));
    }
    if !name.to_ascii_lowercase().ends_with(&format!(".{ext}")) {
        return Err(BadField::new("name", format!("must end in .{ext}")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_name_may_have_any_letters_and_spaces_but_no_folder() {
        for good in [
            "cow.glb",
            "my cow.glb",
            "kráva.GLB",
            "cow (2).glb",
            "a+b,c_d-e.f.glb",
        ] {
            assert!(file_name(good, "glb").is_ok(), "{good}");
        }
        for bad in [
            "",
            "a/b.glb",
            "a\\b.glb",
            "../b.glb",
            ".hidden.glb",
            " cow.glb",
            "a:b.glb",
            "a\u{0}b.glb",
            "tab\tname.glb",
            "cow.png",
            "cow.glb ",
            "*.glb",
        ] {
            assert_eq!(file_name(bad, "glb").unwrap_err().field, "name", "{bad:?}");
        }
        assert!(file_name(&format!("{}.glb", "x".repeat(125)), "glb").is_err());
    }

    #[test]
    fn the_envelope_names_what_is_wrong() {
        let bad = |t: &str| parse(t, |_| Ok(())).unwrap_err().field;
        assert_eq!(bad("{"), "(message)");
        assert_eq!(bad("[1]"), "(message)");
        assert_eq!(bad(r#"{"op":"x"}"#), "seq");
        assert_eq!(bad(r#"{"seq":-1,"op":"x"}"#), "seq");
        assert_eq!(bad(r#"{"seq":1}"#), "op");
        assert_eq!(bad(r#"{"seq":1,"op":2}"#), "op");
        let (seq, op) = parse(r#"{"seq":7,"op":"go","x":1}"#, |m| {
            Ok((m.op.to_string(), m.fields.len()))
        })
        .unwrap();
        assert_eq!((seq, op), (7, ("go".to_string(), 3)));
    }

    #[test]
    fn validators_name_the_element() {
        let v: Value = serde_json::from_str(r#"[1, "a", 3]"#).unwrap();
        assert_eq!(vec3(&v, "p").unwrap_err().field, "p[1]");
        let v: Value = serde_json::from_str("[0, 0, 0]").unwrap();
        assert_eq!(
            nonzero(vec3(&v, "n").unwrap(), "n").unwrap_err().problem,
            "must not be zero"
        );
        let e: Value = serde_json::from_str(&error(None, "(rate)", "slow down")).unwrap();
        assert_eq!(e["seq"], Value::Null);
        assert_eq!(e["field"], "(rate)");
    }

    #[test]
    fn one_error_shape_with_or_without_extra_fields() {
        let plain: Value = serde_json::from_str(&error(Some(0), "op", "no")).unwrap();
        assert_eq!(
            plain,
            json!({"type": "error", "seq": 0, "field": "op", "message": "no"})
        );
        let extra = [("exists", json!(true)), ("type", json!("export"))];
        let e: Value =
            serde_json::from_str(&error_with(Some(3), "name", "x: the file exists", &extra))
                .unwrap();
        assert_eq!(
            e,
            json!({"type": "error", "seq": 3, "field": "name", "message": "x: the file exists", "exists": true})
        );
    }
}
