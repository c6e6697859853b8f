//! The sections of a binary Gmsh 4.1 file (Gmsh reference manual, Sec.
//! 10.1): after each `$Section` line the data is raw, `int` 4 bytes,
//! `size_t` 8 bytes (the header's data size), `double` 8 bytes, in the
//! byte order the header's `int 1` shows. `$Entities` gives the physical
//! tags of volumes, `$Nodes` and `$Elements` come in entity blocks. Each
//! count is checked against the bytes left (at the smallest record size)
//! before anything is allocated for it.

use glam::DVec3;

use super::gmsh::{NODES_PER_TYPE, Parts, physical_tag, skip_section};
use crate::error::{ErrorKind, Result};
use crate::text::Cursor;

/// Reads raw values in one byte order.
struct Bin<'c, 'a> {
    c: &'c mut Cursor<'a>,
    big_endian: bool,
}

impl Bin<'_, '_> {
    fn bytes<const N: usize>(&mut self, what: &str) -> Result<[u8; N]> {
        let raw = self.c.take(N, what)?;
        let mut b = [0u8; N];
        b.copy_from_slice(raw);
        if self.big_endian {
            b.reverse();
        }
        Ok(b)
    }

    fn int(&mut self, what: &str) -> Result<i32> {
        Ok(i32::from_le_bytes(self.bytes(what)?))
    }

    fn size(&mut self, what: &str) -> Result<u64> {
        Ok(u64::from_le_bytes(self.bytes(what)?))
    }

    fn double(&mut self, what: &str) -> Result<f64> {
        Ok(f64::from_le_bytes(self.bytes(what)?))
    }

    /// A count of records of at least `min_bytes` each, checked against
    /// the bytes left.
    fn count(&mut self, what: &'static str, min_bytes: usize) -> Result<usize> {
        let declared = self.size(what)?;
        self.c.check_count(what, declared, min_bytes)
    }
}

/// Reads every section of a binary 4.1 file after `$EndMeshFormat`.
pub(super) fn sections(c: &mut Cursor<'_>, parts: &mut Parts, big_endian: bool) -> Result<()> {
    while let Some((at, section)) = c.token() {
        match section {
            b"$Entities" => {
                c.skip_line();
                entities(&mut Bin { c, big_endian }, parts)?;
                c.keyword("$EndEntities")?;
            }
            b"$Nodes" => {
                c.skip_line();
                nodes(&mut Bin { c, big_endian }, parts)?;
                c.keyword("$EndNodes")?;
            }
            b"$Elements" => {
                c.skip_line();
                elements(&mut Bin { c, big_endian }, parts)?;
                c.keyword("$EndElements")?;
            }
            name if name.starts_with(b"$") => skip_section(c, name)?,
            other => return Err(c.syntax(at, "a section such as $Nodes", other)),
        }
    }
    Ok(())
}

fn entities(b: &mut Bin<'_, '_>, parts: &mut Parts) -> Result<()> {
    let counts = [
        b.size("the number of point entities")?,
        b.size("the number of curve entities")?,
        b.size("the number of surface entities")?,
        b.size("the number of volume entities")?,
    ];
    for (dim, &n) in counts.iter().enumerate() {
        // A point: int tag, 3 doubles, size_t count; the others 6 doubles
        // and a bounding count as well.
        let min_bytes = if dim == 0 { 4 + 24 + 8 } else { 4 + 48 + 16 };
        let n = b.c.check_count("entities", n, min_bytes)?;
        for _ in 0..n {
            let tag = b.int("an entity tag")?;
            for _ in 0..if dim == 0 { 3 } else { 6 } {
                b.double("an entity coordinate")?;
            }
            let physical = b.count("physical tags", 4)?;
            for p in 0..physical {
                let at = b.c.offset();
                let value = b.int("a physical tag")?;
                if dim == 3 && p == 0 {
                    let value = physical_tag(b.c, at, i64::from(value))?;
                    parts.volume_physical.insert(i64::from(tag), value);
                }
            }
            if dim > 0 {
                let bounding = b.count("bounding entities", 4)?;
                b.c.take(4 * bounding, "bounding entity tags")?;
            }
        }
    }
    Ok(())
}

fn nodes(b: &mut Bin<'_, '_>, parts: &mut Parts) -> Result<()> {
    let blocks = b.size("the number of node blocks")?;
    // Each node: a size_t tag and three doubles.
    let total = b.count("nodes", 32)?;
    b.size("the smallest node tag")?;
    b.size("the largest node tag")?;
    // A block header: three ints and a size_t.
    let blocks = b.c.check_count("node blocks", blocks, 20)?;
    parts.tags.reserve(total);
    parts.positions.reserve(total);
    for _ in 0..blocks {
        let dim = b.int("an entity dimension")?;
        b.int("an entity tag")?;
        let at = b.c.offset();
        let parametric = b.int("the parametric flag")?;
        if parametric != 0 {
            return Err(b
                .c
                .error_at_byte(at, ErrorKind::Unsupported("parametric nodes".into())));
        }
        let _ = dim;
        let n = b.count("nodes", 32)?;
        if parts.tags.len() + n > total {
            return Err(b.c.error_at_byte(
                at,
                ErrorKind::Syntax {
                    expected: format!("at most {total} nodes in all"),
                    found: format!("{} or more", parts.tags.len() + n),
                },
            ));
        }
        for _ in 0..n {
            parts.tags.push(b.size("a node tag")?);
        }
        for _ in 0..n {
            let at = b.c.offset();
            let p = DVec3::new(
                b.double("a node coordinate")?,
                b.double("a node coordinate")?,
                b.double("a node coordinate")?,
            );
            let index = parts.positions.len();
            if let Some(value) = p.to_array().into_iter().find(|v| !v.is_finite()) {
                return Err(b.c.error_at_byte(at, ErrorKind::NonFinite { index, value }));
            }
            parts.positions.push(p);
        }
    }
    if parts.tags.len() != total {
        let at = b.c.offset();
        return Err(b.c.error_at_byte(
            at,
            ErrorKind::Truncated(format!(
                "{total} nodes, the blocks hold {}",
                parts.tags.len()
            )),
        ));
    }
    parts.nodes_seen = true;
    Ok(())
}

fn elements(b: &mut Bin<'_, '_>, parts: &mut Parts) -> Result<()> {
    let blocks = b.size("the number of element blocks")?;
    // Each element: a size_t tag and at least one size_t node.
    let total = b.count("elements", 16)?;
    b.size("the smallest element tag")?;
    b.size("the largest element tag")?;
    let blocks = b.c.check_count("element blocks", blocks, 20)?;
    let mut read = 0usize;
    for _ in 0..blocks {
        b.int("an entity dimension")?;
        let entity = b.int("an entity tag")?;
        let at = b.c.offset();
        let kind = b.int("an element type")?;
        let nodes = usize::try_from(kind)
            .ok()
            .and_then(|k| NODES_PER_TYPE.get(k).copied())
            .filter(|&n| n > 0)
            .ok_or_else(|| {
                b.c.error_at_byte(at, ErrorKind::Unsupported(format!("element type {kind}")))
            })?;
        let record = 8 * (1 + nodes);
        let n = b.count("elements", record)?;
        if n > total - read {
            return Err(b.c.error_at_byte(
                at,
                ErrorKind::Syntax {
                    expected: format!("at most {} more elements", total - read),
                    found: n.to_string(),
                },
            ));
        }
        read += n;
        let block_at = b.c.offset();
        if kind != 4 && kind != 11 {
            parts.skip(kind as u64, n as u64);
            b.c.take(n * record, "element records")?;
            continue;
        }
        let region = parts.region_41(i64::from(entity));
        parts.tets.reserve(n);
        for k in 0..n {
            b.size("an element tag")?;
            let mut corners = [0i64; 4];
            for slot in &mut corners {
                // Tags beyond i64 cannot name a node; the lookup refuses them.
                *slot = i64::try_from(b.size("a node tag")?).unwrap_or(-1);
            }
            // A 10-node tetrahedron's edge nodes.
            b.c.take(8 * (nodes - 4), "edge node tags")?;
            parts.tets.push((corners, region, block_at + k * record));
        }
    }
    Ok(())
}
