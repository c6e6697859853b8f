//! Property tests of the readers the second set of fixes touched, over
//! random data: Gmsh 4.1 binary (both byte orders) against 4.1 ASCII of
//! the same random mesh; PLY `tristrips` and per-corner `texcoord` lists
//! in ASCII and both binary byte orders against the triangles they
//! encode; and random bytes after valid headers, which must never panic
//! (an `Err`, or a consistent mesh).

use std::fmt::Write as _;
use std::io::Write as _;

use glam::{DVec3, Vec2};
use trilux_io::mesh::ply;
use trilux_io::tet::{TetMesh, gmsh};

use test_support::SplitMix64 as Rng;

/// A coordinate of a random mesh, uniform in `[-100, 100)`.
trait Coordinate {
    fn real(&mut self) -> f64;
}

impl Coordinate for Rng {
    fn real(&mut self) -> f64 {
        self.f64() * 200.0 - 100.0
    }
}

/// A random mesh: node tags sparse and shuffled, tetrahedra in two volume
/// entities, and triangles (skipped) in between.
struct RandomMsh {
    tags: Vec<u64>,
    positions: Vec<DVec3>,
    /// (entity, node tags).
    tets: Vec<(i32, [u64; 4])>,
    triangles: Vec<[u64; 3]>,
    physical: bool,
}

impl RandomMsh {
    fn new(rng: &mut Rng) -> Self {
        let n = 4 + rng.below(40) as usize;
        let mut tags: Vec<u64> = (0..n as u64).map(|i| 1 + 3 * i + rng.below(3)).collect();
        for i in (1..n).rev() {
            tags.swap(i, rng.below(i as u64 + 1) as usize);
        }
        let positions = (0..n)
            .map(|_| DVec3::new(rng.real(), rng.real(), rng.real()))
            .collect();
        let pick = |rng: &mut Rng| tags[rng.below(n as u64) as usize];
        let tets = (0..rng.below(30))
            .map(|_| {
                (
                    1 + rng.below(2) as i32,
                    [pick(rng), pick(rng), pick(rng), pick(rng)],
                )
            })
            .collect();
        let triangles = (0..rng.below(5))
            .map(|_| [pick(rng), pick(rng), pick(rng)])
            .collect();
        Self {
            tags,
            positions,
            tets,
            triangles,
            physical: rng.below(2) == 0,
        }
    }

    /// The mesh the reader must return: nodes in file order, regions
    /// the physical tags (10 × entity) or the entity tags.
    fn expected(&self) -> TetMesh {
        let index = |tag: u64| self.tags.iter().position(|&t| t == tag).unwrap() as u32;
        let regions: Vec<i32> = self
            .tets
            .iter()
            .map(|(e, _)| if self.physical { 10 * e } else { *e })
            .collect();
        TetMesh {
            positions: self.positions.clone(),
            tets: self.tets.iter().map(|(_, t)| t.map(index)).collect(),
            regions: if self.tets.is_empty() {
                Vec::new()
            } else {
                regions
            },
            ..TetMesh::default()
        }
    }

    fn ascii(&self) -> Vec<u8> {
        let mut s = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 1 2\n");
        let _ = writeln!(s, "5 0 0 0 1 1 1 0 0");
        for e in 1..=2 {
            let physical = if self.physical {
                format!("1 {}", 10 * e)
            } else {
                "0".into()
            };
            let _ = writeln!(s, "{e} 0 0 0 1 1 1 {physical} 0");
        }
        s.push_str("$EndEntities\n$Nodes\n");
        let n = self.tags.len();
        let _ = writeln!(s, "1 {n} 1 {}", 3 * n + 3);
        let _ = writeln!(s, "3 1 0 {n}");
        for t in &self.tags {
            let _ = writeln!(s, "{t}");
        }
        for p in &self.positions {
            let _ = writeln!(s, "{:?} {:?} {:?}", p.x, p.y, p.z);
        }
        s.push_str("$EndNodes\n$Elements\n");
        let _ = writeln!(s, "3 {} 1 {}", self.tets.len() + self.triangles.len(), 1000);
        for entity in 1..=2 {
            let mine: Vec<_> = self.tets.iter().filter(|(e, _)| *e == entity).collect();
            let _ = writeln!(s, "3 {entity} 4 {}", mine.len());
            for (k, (_, t)) in mine.iter().enumerate() {
                let _ = writeln!(s, "{} {} {} {} {}", k + 1, t[0], t[1], t[2], t[3]);
            }
            if entity == 1 {
                let _ = writeln!(s, "2 5 2 {}", self.triangles.len());
                for (k, t) in self.triangles.iter().enumerate() {
                    let _ = writeln!(s, "{} {} {} {}", k + 1, t[0], t[1], t[2]);
                }
            }
        }
        s.push_str("$EndElements\n");
        s.into_bytes()
    }

    fn binary(&self, big_endian: bool) -> Vec<u8> {
        let mut out = b"$MeshFormat\n4.1 1 8\n".to_vec();
        let int = |out: &mut Vec<u8>, v: i32| {
            out.extend_from_slice(&if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        let size = |out: &mut Vec<u8>, v: u64| {
            out.extend_from_slice(&if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        let double = |out: &mut Vec<u8>, v: f64| {
            out.extend_from_slice(&if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        int(&mut out, 1);
        out.extend_from_slice(b"\n$EndMeshFormat\n$Entities\n");
        for count in [0, 0, 1, 2] {
            size(&mut out, count);
        }
        for (tag, physical) in [(5, None), (1, Some(10)), (2, Some(20))] {
            int(&mut out, tag);
            for _ in 0..6 {
                double(&mut out, 0.5);
            }
            match physical.filter(|_| self.physical) {
                Some(p) => {
                    size(&mut out, 1);
                    int(&mut out, p);
                }
                None => size(&mut out, 0),
            }
            size(&mut out, 0);
        }
        out.extend_from_slice(b"\n$EndEntities\n$Nodes\n");
        let n = self.tags.len() as u64;
        for v in [1, n, 1, 3 * n + 3] {
            size(&mut out, v);
        }
        int(&mut out, 3);
        int(&mut out, 1);
        int(&mut out, 0);
        size(&mut out, n);
        for &t in &self.tags {
            size(&mut out, t);
        }
        for p in &self.positions {
            for v in p.to_array() {
                double(&mut out, v);
            }
        }
        out.extend_from_slice(b"\n$EndNodes\n$Elements\n");
        for v in [3, (self.tets.len() + self.triangles.len()) as u64, 1, 1000] {
            size(&mut out, v);
        }
        for entity in 1..=2 {
            let mine: Vec<_> = self.tets.iter().filter(|(e, _)| *e == entity).collect();
            int(&mut out, 3);
            int(&mut out, entity);
            int(&mut out, 4);
            size(&mut out, mine.len() as u64);
            for (k, (_, t)) in mine.iter().enumerate() {
                size(&mut out, k as u64 + 1);
                t.iter().for_each(|&v| size(&mut out, v));
            }
            if entity == 1 {
                int(&mut out, 2);
                int(&mut out, 5);
                int(&mut out, 2);
                size(&mut out, self.triangles.len() as u64);
                for (k, t) in self.triangles.iter().enumerate() {
                    size(&mut out, k as u64 + 1);
                    t.iter().for_each(|&v| size(&mut out, v));
                }
            }
        }
        out.extend_from_slice(b"\n$EndElements\n");
        out
    }
}

/// Tetrahedra grouped by entity block, as the files list them.
fn by_block(mut mesh: TetMesh, msh: &RandomMsh) -> TetMesh {
    let mut order: Vec<usize> = (0..msh.tets.len()).collect();
    order.sort_by_key(|&t| msh.tets[t].0);
    mesh.tets = order.iter().map(|&t| mesh.tets[t]).collect();
    if !mesh.regions.is_empty() {
        mesh.regions = order.iter().map(|&t| mesh.regions[t]).collect();
    }
    mesh
}

#[test]
fn gmsh_41_binary_reads_as_ascii_in_both_byte_orders() {
    let mut rng = Rng(41);
    for case in 0..200 {
        let msh = RandomMsh::new(&mut rng);
        let expected = by_block(msh.expected(), &msh);
        let ascii =
            gmsh::from_bytes(&msh.ascii(), "m.msh").unwrap_or_else(|e| panic!("{case}: {e}"));
        for big_endian in [false, true] {
            let binary = gmsh::from_bytes(&msh.binary(big_endian), "m.msh")
                .unwrap_or_else(|e| panic!("{case} {big_endian}: {e}"));
            assert_eq!(binary, ascii, "{case} {big_endian}");
            let mut plain = binary.clone();
            plain.warnings.clear();
            assert_eq!(plain, expected, "{case} {big_endian}");
            // Skipped triangles are said.
            assert_eq!(
                binary.warnings.is_empty(),
                msh.triangles.is_empty(),
                "{case}"
            );
        }
    }
}

/// Every prefix of a binary file is refused with an `Err` (never a
/// panic, never a half-read mesh), and random bytes after a valid header
/// or in place of a section never panic.
#[test]
fn gmsh_41_binary_truncated_or_random_never_panics() {
    let mut rng = Rng(7);
    let msh = RandomMsh::new(&mut rng);
    let whole = msh.binary(false);
    for cut in 0..whole.len() - 1 {
        let prefix = &whole[..cut];
        if let Ok(mesh) = gmsh::from_bytes(prefix, "cut.msh") {
            // Only a file cut right after a whole section can be read.
            let end = prefix.trim_ascii_end();
            assert!(
                end.ends_with(b"$EndNodes") || end.ends_with(b"$EndElements"),
                "{cut}: {mesh:?}"
            );
        }
    }
    let header = b"$MeshFormat\n4.1 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n$Nodes\n";
    for _ in 0..3000 {
        let mut data = header.to_vec();
        let len = rng.below(200) as usize;
        data.extend((0..len).map(|_| rng.next_u64() as u8));
        // Also random bytes in place of a valid file's bytes.
        let mut flipped = whole.clone();
        for _ in 0..1 + rng.below(4) {
            let at = rng.below(flipped.len() as u64) as usize;
            flipped[at] = rng.next_u64() as u8;
        }
        for bytes in [data, flipped] {
            if let Ok(mesh) = gmsh::from_bytes(&bytes, "r.msh") {
                let n = mesh.positions.len();
                assert!(mesh.tets.iter().flatten().all(|&i| (i as usize) < n));
                assert!(mesh.positions.iter().all(|p| p.is_finite()));
                let _ = mesh.boundary();
            }
        }
    }
}

/// The three PLY encodings.
#[derive(Clone, Copy, Debug)]
enum Enc {
    Ascii,
    Le,
    Be,
}

impl Enc {
    fn name(self) -> &'static str {
        match self {
            Enc::Ascii => "ascii",
            Enc::Le => "binary_little_endian",
            Enc::Be => "binary_big_endian",
        }
    }

    fn int(self, out: &mut Vec<u8>, v: i32) {
        match self {
            Enc::Ascii => out.extend_from_slice(format!("{v} ").as_bytes()),
            Enc::Le => out.extend_from_slice(&v.to_le_bytes()),
            Enc::Be => out.extend_from_slice(&v.to_be_bytes()),
        }
    }

    fn float(self, out: &mut Vec<u8>, v: f32) {
        match self {
            Enc::Ascii => out.extend_from_slice(format!("{v:?} ").as_bytes()),
            Enc::Le => out.extend_from_slice(&v.to_le_bytes()),
            Enc::Be => out.extend_from_slice(&v.to_be_bytes()),
        }
    }

    fn end(self, out: &mut Vec<u8>) {
        if let Enc::Ascii = self {
            out.push(b'\n');
        }
    }
}

/// Random strips (with restarts and degenerate joints) and random faces
/// with per-corner UVs, in every encoding: the triangles are those of the
/// OpenGL strip rule and the fans, and every corner has its UV.
#[test]
fn ply_strips_and_corner_uvs_read_back_in_every_encoding() {
    let mut rng = Rng(2026);
    for case in 0..150 {
        let n = 3 + rng.below(12) as i32;
        let strips: Vec<Vec<i32>> = (0..rng.below(3))
            .map(|_| {
                (0..rng.below(12))
                    .map(|_| {
                        if rng.below(6) == 0 {
                            -1
                        } else {
                            rng.below(n as u64) as i32
                        }
                    })
                    .collect()
            })
            .collect();
        let faces: Vec<Vec<(i32, [f32; 2])>> = (0..rng.below(4))
            .map(|_| {
                (0..3 + rng.below(3))
                    .map(|_| {
                        let uv = [rng.below(4) as f32 * 0.25, rng.below(4) as f32 * 0.25];
                        (rng.below(n as u64) as i32, uv)
                    })
                    .collect()
            })
            .collect();
        // The triangles expected, and the corner UVs (v flipped down).
        let mut expected: Vec<([u32; 3], Option<[Vec2; 3]>)> = Vec::new();
        for f in &faces {
            for k in 1..f.len() - 1 {
                let c = [f[0], f[k], f[k + 1]];
                let uv = c.map(|(_, uv)| Vec2::new(uv[0], 1.0 - uv[1]));
                expected.push((c.map(|(v, _)| v as u32), Some(uv)));
            }
        }
        for s in &strips {
            for run in s.split(|&v| v == -1) {
                for k in 0..run.len().saturating_sub(2) {
                    let (a, b, c) = (run[k] as u32, run[k + 1] as u32, run[k + 2] as u32);
                    if a != b && b != c && a != c {
                        expected.push((if k % 2 == 0 { [a, b, c] } else { [b, a, c] }, None));
                    }
                }
            }
        }
        for enc in [Enc::Ascii, Enc::Le, Enc::Be] {
            let mut out = format!(
                "ply\nformat {} 1.0\nelement vertex {n}\nproperty float x\nproperty float y\n\
                 property float z\nelement face {}\nproperty list uchar int vertex_indices\n\
                 property list uchar float texcoord\nelement tristrips {}\n\
                 property list int int vertex_indices\nend_header\n",
                enc.name(),
                faces.len(),
                strips.len()
            )
            .into_bytes();
            for v in 0..n {
                for c in [v as f32, (v * v) as f32, 1.0] {
                    enc.float(&mut out, c);
                }
                enc.end(&mut out);
            }
            let count = |out: &mut Vec<u8>, k: usize| match enc {
                Enc::Ascii => out.extend_from_slice(format!("{k} ").as_bytes()),
                _ => out.push(k as u8),
            };
            for f in &faces {
                count(&mut out, f.len());
                f.iter().for_each(|(v, _)| enc.int(&mut out, *v));
                count(&mut out, 2 * f.len());
                f.iter()
                    .for_each(|(_, uv)| uv.iter().for_each(|&c| enc.float(&mut out, c)));
                enc.end(&mut out);
            }
            for s in &strips {
                enc.int(&mut out, s.len() as i32);
                s.iter().for_each(|&v| enc.int(&mut out, v));
                enc.end(&mut out);
            }
            let data =
                ply::from_bytes(&out, "r.ply").unwrap_or_else(|e| panic!("{case} {enc:?}: {e}"));
            assert_eq!(data.triangles.len(), expected.len(), "{case} {enc:?}");
            let positions = &data.positions;
            for (t, (want, uv)) in data.triangles.iter().zip(&expected) {
                // Split vertices keep their position: compare positions.
                let got = t.map(|i| positions[i as usize].x as u32);
                assert_eq!(got, *want, "{case} {enc:?}");
                if let Some(uv) = uv {
                    let uvs = data.uvs.as_ref().unwrap();
                    assert_eq!(t.map(|i| uvs[i as usize]), *uv, "{case} {enc:?}");
                }
            }
        }
    }
}

/// Random bytes after PLY headers with the new elements and properties
/// never panic.
#[test]
fn ply_strips_and_texcoords_random_bodies_never_panic() {
    let mut rng = Rng(99);
    let headers = [
        "ply\nformat binary_little_endian 1.0\ncomment TextureFile t.png\nelement vertex 4\n\
         property float x\nproperty float y\nproperty float z\nelement tristrips 2\n\
         property list int int vertex_indices\nend_header\n",
        "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\n\
         property float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\n\
         property list uchar float texcoord\nproperty uchar red\nend_header\n",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n",
    ];
    for _ in 0..5000 {
        let header = headers[rng.below(3) as usize];
        let mut data = header.as_bytes().to_vec();
        let len = rng.below(120) as usize;
        if header.contains("ascii") {
            for _ in 0..len / 3 {
                let _ = write!(data, "{} ", rng.below(12) as i64 - 2);
            }
        } else {
            data.extend((0..len).map(|_| rng.next_u64() as u8));
        }
        if let Ok(ply) = ply::from_bytes(&data, "r.ply") {
            let n = ply.positions.len();
            assert!(ply.triangles.iter().flatten().all(|&i| (i as usize) < n));
            assert!(ply.uvs.as_ref().is_none_or(|u| u.len() == n));
        }
    }
}
