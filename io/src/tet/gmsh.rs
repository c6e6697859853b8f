//! Gmsh `.msh` files: version 2.2 ASCII and binary (what TetWild and
//! fTetWild write) and version 4.1 ASCII and binary (what Gmsh and meshio
//! write; meshio's default is binary). Binary files are read in the byte
//! order their header's `int 1` shows, little- or big-endian (Gmsh
//! reference manual, Sec. 10.1, "MSH file format").
//!
//! Tetrahedra (element types 4 and, by their corners, 11) are kept with
//! their physical tag as region (4.1: the physical tag of their volume
//! entity, or the entity tag itself when no volume has a physical tag);
//! other elements are skipped and counted in [`TetMesh::warnings`]. Node
//! tags may be any positive numbers; nodes are indexed in file order.
//! Every count is checked against the bytes left before allocating.

use std::collections::HashMap;
use std::path::Path;

use glam::DVec3;

use super::TetMesh;
use crate::error::{Error, ErrorKind, Result};
use crate::text::Cursor;

/// Nodes per element for Gmsh's element types 1..=19 (index 0 unused),
/// needed to skip elements of binary files.
pub(super) const NODES_PER_TYPE: [usize; 20] = [
    0, 2, 3, 4, 4, 8, 6, 5, 3, 6, 9, 10, 27, 18, 14, 1, 8, 20, 15, 13,
];

/// Node tags to indices: a table when tags are compact, a map otherwise.
enum TagMap {
    Dense(Vec<u32>),
    Sparse(HashMap<u64, u32>),
}

impl TagMap {
    fn new(tags: &[u64]) -> Self {
        let max = tags.iter().copied().max().unwrap_or(0);
        if max <= 2 * tags.len() as u64 + 1024 {
            let mut table = vec![u32::MAX; max as usize + 1];
            for (i, &t) in tags.iter().enumerate() {
                table[t as usize] = i as u32;
            }
            TagMap::Dense(table)
        } else {
            TagMap::Sparse(
                tags.iter()
                    .enumerate()
                    .map(|(i, &t)| (t, i as u32))
                    .collect(),
            )
        }
    }

    #[inline]
    fn get(&self, tag: i64) -> Option<u32> {
        let tag = u64::try_from(tag).ok()?;
        match self {
            TagMap::Dense(table) => table
                .get(usize::try_from(tag).ok()?)
                .copied()
                .filter(|&i| i != u32::MAX),
            TagMap::Sparse(map) => map.get(&tag).copied(),
        }
    }
}

/// What the sections read so far hold.
#[derive(Default)]
pub(super) struct Parts {
    pub(super) tags: Vec<u64>,
    pub(super) positions: Vec<DVec3>,
    /// Tetrahedra as node tags, with their region, until nodes are known.
    pub(super) tets: Vec<([i64; 4], i32, usize)>,
    /// 4.1: volume entity tag to its first physical tag.
    pub(super) volume_physical: HashMap<i64, i32>,
    pub(super) nodes_seen: bool,
    /// Elements other than tetrahedra, skipped: (type, count).
    pub(super) skipped: Vec<(u64, u64)>,
}

impl Parts {
    /// The region of a 4.1 tetrahedron of volume entity `entity`: its
    /// physical tag, 0 for an entity without one, or the entity tag when
    /// no volume has a physical tag (meshio without `gmsh:physical`).
    pub(super) fn region_41(&self, entity: i64) -> i32 {
        if self.volume_physical.is_empty() {
            i32::try_from(entity).unwrap_or(0)
        } else {
            self.volume_physical.get(&entity).copied().unwrap_or(0)
        }
    }

    /// Counts `count` skipped elements of `kind`.
    pub(super) fn skip(&mut self, kind: u64, count: u64) {
        if count == 0 {
            return;
        }
        match self.skipped.iter_mut().find(|(k, _)| *k == kind) {
            Some((_, n)) => *n += count,
            None => self.skipped.push((kind, count)),
        }
    }
}

/// Reads a `.msh` file.
///
/// # Errors
/// [`Error`] with the file and line (or byte offset in binary sections): an
/// unsupported version, a malformed, truncated or out-of-range record, a
/// non-finite coordinate, or a tetrahedron that references a missing node.
pub fn read(path: impl AsRef<Path>) -> Result<TetMesh> {
    let path = path.as_ref();
    let data = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    from_bytes(&data, path)
}

/// Parses the contents of a `.msh` file, for data that is not in a file
/// (archives, network, fuzzing). `path` names it in errors.
///
/// # Errors
/// As for [`read`].
pub fn from_bytes(data: &[u8], path: impl AsRef<Path>) -> Result<TetMesh> {
    let path = path.as_ref();
    let mut c = Cursor::new(data, path, None);
    c.keyword("$MeshFormat")?;
    let (at, version) = c.expect_token("the format version")?;
    let (at_type, file_type) = c.expect_token("the file type")?;
    let (at_size, size) = c.expect_token("the data size")?;
    if size != b"8" {
        return Err(c.syntax(at_size, "data size 8", size));
    }
    let binary = match file_type {
        b"0" => false,
        b"1" => true,
        _ => return Err(c.syntax(at_type, "file type 0 (ASCII) or 1 (binary)", file_type)),
    };
    let v41 = match version {
        b"2.2" | b"2.1" | b"2" | b"2.0" => false,
        b"4.1" => true,
        _ => {
            return Err(c.error_at(
                at,
                ErrorKind::Unsupported(format!(
                    "Gmsh format version {} (2.2 and 4.1 are read)",
                    String::from_utf8_lossy(version)
                )),
            ));
        }
    };
    let mut big_endian = false;
    if binary {
        // One int 1 in the writer's byte order follows the header line.
        c.skip_line();
        let at = c.offset();
        let one = c.take(4, "the binary endianness check")?;
        let one = [one[0], one[1], one[2], one[3]];
        big_endian = match (i32::from_le_bytes(one), i32::from_be_bytes(one)) {
            (1, _) => false,
            (_, 1) if v41 => true,
            (_, 1) => {
                return Err(c.error_at_byte(
                    at,
                    ErrorKind::Unsupported("big-endian binary Gmsh 2.2 files".into()),
                ));
            }
            _ => return Err(c.syntax(at, "the int 1 of a binary header", &one)),
        };
    }
    c.keyword("$EndMeshFormat")?;

    let mut parts = Parts::default();
    if binary && v41 {
        return super::gmsh_binary::sections(&mut c, &mut parts, big_endian)
            .and_then(|()| finish(parts, &c));
    }
    while let Some((at, section)) = c.token() {
        match section {
            b"$Nodes" if v41 => nodes_41(&mut c, &mut parts)?,
            b"$Nodes" if binary => nodes_22_binary(&mut c, &mut parts)?,
            b"$Nodes" => nodes_22(&mut c, &mut parts)?,
            b"$Elements" if v41 => elements_41(&mut c, &mut parts)?,
            b"$Elements" if binary => elements_22_binary(&mut c, &mut parts)?,
            b"$Elements" => elements_22(&mut c, &mut parts)?,
            b"$Entities" if v41 => entities_41(&mut c, &mut parts)?,
            name if name.starts_with(b"$") => skip_section(&mut c, name)?,
            other => return Err(c.syntax(at, "a section such as $Nodes", other)),
        }
    }
    finish(parts, &c)
}

/// One warning listing the elements other than tetrahedra that were
/// skipped (triangles, lines, points: a tet mesh's boundary and
/// annotations, which the tetrahedra define again).
fn skipped_warnings(path: &Path, skipped: &[(u64, u64)]) -> Vec<crate::Warning> {
    if skipped.is_empty() {
        return Vec::new();
    }
    let list: Vec<String> = skipped
        .iter()
        .map(|(kind, n)| format!("{n} of type {kind}"))
        .collect();
    vec![crate::Warning::new(
        path,
        None,
        format!(
            "elements other than tetrahedra are not read: {} (Gmsh element types; 2 is a \
             triangle, 1 a line, 15 a point)",
            list.join(", ")
        ),
    )]
}

/// Skips an unknown section up to its `$End…` line.
pub(super) fn skip_section(c: &mut Cursor<'_>, name: &[u8]) -> Result<()> {
    let mut end = b"$End".to_vec();
    end.extend_from_slice(&name[1..]);
    loop {
        let (_, tok) = c.expect_token(&format!("{}", String::from_utf8_lossy(&end)))?;
        if tok == end.as_slice() {
            return Ok(());
        }
    }
}

/// Converts tag-addressed tetrahedra to indices.
fn finish(parts: Parts, c: &Cursor<'_>) -> Result<TetMesh> {
    if !parts.nodes_seen {
        return Err(Error::new(
            c.path(),
            ErrorKind::Truncated("a $Nodes section".into()),
        ));
    }
    let warnings = skipped_warnings(c.path(), &parts.skipped);
    let map = TagMap::new(&parts.tags);
    let count = parts.positions.len();
    let mut tets = Vec::with_capacity(parts.tets.len());
    let any_region = parts.tets.iter().any(|t| t.1 != 0);
    let mut regions = Vec::with_capacity(if any_region { parts.tets.len() } else { 0 });
    for (index, (tags, region, at)) in parts.tets.into_iter().enumerate() {
        let mut tet = [0u32; 4];
        for (slot, &tag) in tet.iter_mut().zip(&tags) {
            *slot = map.get(tag).ok_or_else(|| {
                c.error_at(
                    at,
                    ErrorKind::IndexOutOfRange {
                        element: "tetrahedron",
                        index,
                        node: tag,
                        count,
                    },
                )
            })?;
        }
        tets.push(tet);
        if any_region {
            regions.push(region);
        }
    }
    Ok(TetMesh {
        positions: parts.positions,
        tets,
        regions,
        attributes: Vec::new(),
        warnings,
    })
}

/// A physical tag, which must fit 32 bits.
pub(super) fn physical_tag(c: &Cursor<'_>, at: usize, value: i64) -> Result<i32> {
    i32::try_from(value).map_err(|_| {
        c.syntax(
            at,
            "a physical tag that fits 32 bits",
            value.to_string().as_bytes(),
        )
    })
}

fn nodes_22(c: &mut Cursor<'_>, parts: &mut Parts) -> Result<()> {
    let declared = c.u64("the number of nodes")?;
    let n = c.check_count("nodes", declared, 8)?;
    parts.tags.reserve(n);
    parts.positions.reserve(n);
    for _ in 0..n {
        parts.tags.push(c.u64("a node tag")?);
        let index = parts.positions.len();
        let p = c.point(index)?;
        parts.positions.push(p);
    }
    parts.nodes_seen = true;
    c.keyword("$EndNodes")
}

fn elements_22(c: &mut Cursor<'_>, parts: &mut Parts) -> Result<()> {
    let declared = c.u64("the number of elements")?;
    let n = c.check_count("elements", declared, 8)?;
    for _ in 0..n {
        c.skip_space();
        let at = c.offset();
        c.u64("an element tag")?;
        let kind = c.u64("an element type")?;
        if kind != 4 && kind != 11 {
            parts.skip(kind, 1);
            c.skip_line();
            continue;
        }
        let ntags = c.u64("the number of element tags")?;
        let mut region = 0;
        for t in 0..ntags {
            let tag = c.i64("an element tag")?;
            if t == 0 {
                region = physical_tag(c, at, tag)?;
            }
        }
        parts.tets.push((corner_tags(c, kind)?, region, at));
    }
    c.keyword("$EndElements")
}

/// The four corner node tags of an ASCII tetrahedron record, skipping a
/// 10-node tetrahedron's edge nodes.
fn corner_tags(c: &mut Cursor<'_>, kind: u64) -> Result<[i64; 4]> {
    let mut tags = [0i64; 4];
    for slot in &mut tags {
        *slot = c.i64("a node tag")?;
    }
    if kind == 11 {
        c.skip_line();
    }
    Ok(tags)
}

fn i32_at(bytes: &[u8], k: usize) -> i32 {
    i32::from_le_bytes([
        bytes[4 * k],
        bytes[4 * k + 1],
        bytes[4 * k + 2],
        bytes[4 * k + 3],
    ])
}

fn f64_at(bytes: &[u8], offset: usize) -> f64 {
    let mut b = [0u8; 8];
    b.copy_from_slice(&bytes[offset..offset + 8]);
    f64::from_le_bytes(b)
}

fn nodes_22_binary(c: &mut Cursor<'_>, parts: &mut Parts) -> Result<()> {
    let declared = c.u64("the number of nodes")?;
    let n = c.check_count("nodes", declared, 28)?;
    c.skip_line();
    let at = c.offset();
    let block = c.take(28 * n, "node records")?;
    parts.tags.reserve(n);
    parts.positions.reserve(n);
    for (k, record) in block.chunks_exact(28).enumerate() {
        let tag = i32_at(record, 0);
        let tag = u64::try_from(tag).map_err(|_| {
            c.syntax(
                at + 28 * k,
                "a positive node tag",
                tag.to_string().as_bytes(),
            )
        })?;
        let p = DVec3::new(f64_at(record, 4), f64_at(record, 12), f64_at(record, 20));
        if !p.is_finite() {
            let value = p
                .to_array()
                .into_iter()
                .find(|v| !v.is_finite())
                .unwrap_or(f64::NAN);
            return Err(c.error_at_byte(at + 28 * k, ErrorKind::NonFinite { index: k, value }));
        }
        parts.tags.push(tag);
        parts.positions.push(p);
    }
    parts.nodes_seen = true;
    c.keyword("$EndNodes")
}

fn elements_22_binary(c: &mut Cursor<'_>, parts: &mut Parts) -> Result<()> {
    let declared = c.u64("the number of elements")?;
    let total = c.check_count("elements", declared, 8)?;
    c.skip_line();
    let mut read = 0usize;
    while read < total {
        let at = c.offset();
        let header = c.take(12, "an element block header")?;
        let (kind, count, ntags) = (i32_at(header, 0), i32_at(header, 1), i32_at(header, 2));
        let nodes = usize::try_from(kind)
            .ok()
            .and_then(|k| NODES_PER_TYPE.get(k).copied())
            .filter(|&n| n > 0)
            .ok_or_else(|| {
                c.error_at_byte(at, ErrorKind::Unsupported(format!("element type {kind}")))
            })?;
        let (Ok(count), Ok(ntags)) = (usize::try_from(count), usize::try_from(ntags)) else {
            return Err(c.syntax(
                at,
                "a non-negative element count and tag count",
                b"negative",
            ));
        };
        if count == 0 || count > total - read {
            return Err(c.error_at_byte(
                at,
                ErrorKind::Syntax {
                    expected: format!("between 1 and {} elements in the block", total - read),
                    found: count.to_string(),
                },
            ));
        }
        let ints = 1 + ntags + nodes;
        let bytes_needed = count.saturating_mul(4 * ints);
        let block_at = c.offset();
        let block = c.take(bytes_needed, "element records")?;
        if kind != 4 && kind != 11 {
            parts.skip(kind as u64, count as u64);
        } else {
            for (k, record) in block.chunks_exact(4 * ints).enumerate() {
                let region = if ntags > 0 { i32_at(record, 1) } else { 0 };
                let tags = [0, 1, 2, 3].map(|j| i64::from(i32_at(record, 1 + ntags + j)));
                parts.tets.push((tags, region, block_at + k * 4 * ints));
            }
        }
        read += count;
    }
    c.keyword("$EndElements")
}

fn entities_41(c: &mut Cursor<'_>, parts: &mut Parts) -> Result<()> {
    let counts = [
        c.u64("the number of point entities")?,
        c.u64("the number of curve entities")?,
        c.u64("the number of surface entities")?,
        c.u64("the number of volume entities")?,
    ];
    for (dim, &n) in counts.iter().enumerate() {
        let n = c.check_count("entities", n, 8)?;
        for _ in 0..n {
            let tag = c.i64("an entity tag")?;
            // Points have a position, the others a bounding box.
            let reals = if dim == 0 { 3 } else { 6 };
            for _ in 0..reals {
                c.f64("an entity coordinate")?;
            }
            let physical = c.u64("the number of physical tags")?;
            for p in 0..physical {
                let at = {
                    c.skip_space();
                    c.offset()
                };
                let value = c.i64("a physical tag")?;
                if dim == 3 && p == 0 {
                    parts
                        .volume_physical
                        .insert(tag, physical_tag(c, at, value)?);
                }
            }
            if dim > 0 {
                let bounding = c.u64("the number of bounding entities")?;
                for _ in 0..bounding {
                    c.i64("a bounding entity tag")?;
                }
            }
        }
    }
    c.keyword("$EndEntities")
}

fn nodes_41(c: &mut Cursor<'_>, parts: &mut Parts) -> Result<()> {
    let blocks = c.u64("the number of node blocks")?;
    let declared = c.u64("the number of nodes")?;
    c.u64("the smallest node tag")?;
    c.u64("the largest node tag")?;
    let total = c.check_count("nodes", declared, 8)?;
    parts.tags.reserve(total);
    parts.positions.reserve(total);
    for _ in 0..c.check_count("node blocks", blocks, 8)? {
        c.u64("an entity dimension")?;
        c.i64("an entity tag")?;
        let (at, parametric) = c.expect_token("the parametric flag")?;
        if parametric != b"0" {
            return Err(c.error_at(at, ErrorKind::Unsupported("parametric nodes".into())));
        }
        let in_block = c.u64("the number of nodes in the block")?;
        let n = c.check_count("nodes", in_block, 8)?;
        if parts.tags.len() + n > total {
            return Err(c.syntax(at, &format!("at most {total} nodes in all"), b"more"));
        }
        for _ in 0..n {
            parts.tags.push(c.u64("a node tag")?);
        }
        for _ in 0..n {
            let index = parts.positions.len();
            let p = c.point(index)?;
            parts.positions.push(p);
        }
    }
    if parts.tags.len() != total {
        let at = c.offset();
        return Err(c.error_at(
            at,
            ErrorKind::Truncated(format!(
                "{total} nodes, the blocks hold {}",
                parts.tags.len()
            )),
        ));
    }
    parts.nodes_seen = true;
    c.keyword("$EndNodes")
}

fn elements_41(c: &mut Cursor<'_>, parts: &mut Parts) -> Result<()> {
    let blocks = c.u64("the number of element blocks")?;
    let declared = c.u64("the number of elements")?;
    c.u64("the smallest element tag")?;
    c.u64("the largest element tag")?;
    c.check_count("elements", declared, 4)?;
    for _ in 0..c.check_count("element blocks", blocks, 8)? {
        c.u64("an entity dimension")?;
        let entity = c.i64("an entity tag")?;
        let kind = c.u64("an element type")?;
        let in_block = c.u64("the number of elements in the block")?;
        let n = c.check_count("elements", in_block, 4)?;
        let region = parts.region_41(entity);
        c.skip_line();
        if kind != 4 && kind != 11 {
            parts.skip(kind, n as u64);
            for _ in 0..n {
                c.skip_line();
            }
            continue;
        }
        parts.tets.reserve(n);
        for _ in 0..n {
            c.skip_space();
            let at = c.offset();
            c.u64("an element tag")?;
            parts.tets.push((corner_tags(c, kind)?, region, at));
        }
    }
    c.keyword("$EndElements")
}
