//! The peers in issue #48's table: TetGen, Gmsh and fTetWild, each run
//! through its Python package in a venv the example sets up, measured with
//! trilux's own yardsticks so that the columns compare like with like.
//!
//! A peer runs in a child process (`peers.py`, one run per process) that
//! is killed when it passes the time cap, so a mesher that takes an hour
//! (fTetWild on the Stanford bunny did) costs the table `cap` seconds and
//! its row says so. Its tetrahedra come back as raw files; the boundary
//! triangles (faces of one tetrahedron only) are measured against the
//! input by [`stuffing::surface_distance`] with the sample count trilux's
//! own report uses, and the dihedral angles by [`stuffing::quality`].

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use tet_stuffing::glam::DVec3;
use tet_stuffing::{self as stuffing, Options, SurfaceDistance};

use super::field;

/// The script that runs one peer once (see its docstring for the files).
const SCRIPT: &str = include_str!("peers.py");

/// A peer mesher.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Peer {
    /// TetGen 1.6 (`tetgen` package), `-pq1.2a<volume>`: the input
    /// triangles kept, radius-edge ratio ≤ 1.2, a volume cap.
    TetGen,
    /// Gmsh (`gmsh` package, its own API): the input triangles kept as a
    /// classified discrete surface, one volume, a largest element size.
    Gmsh,
    /// fTetWild (`pytetwild` package): its default envelope, 10⁻³ of the
    /// diagonal, and an ideal edge length.
    FTetWild,
}

impl Peer {
    /// Every peer, in the table's order.
    pub(crate) const ALL: [Peer; 3] = [Peer::TetGen, Peer::Gmsh, Peer::FTetWild];

    /// The name the table gives it.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Peer::TetGen => "TetGen",
            Peer::Gmsh => "Gmsh",
            Peer::FTetWild => "fTetWild",
        }
    }

    /// The name `peers.py` takes and the output files carry.
    fn tool(self) -> &'static str {
        match self {
            Peer::TetGen => "tetgen",
            Peer::Gmsh => "gmsh",
            Peer::FTetWild => "ftetwild",
        }
    }

    /// The Python module that must import.
    fn module(self) -> &'static str {
        match self {
            Peer::TetGen => "tetgen",
            Peer::Gmsh => "gmsh",
            Peer::FTetWild => "pytetwild",
        }
    }

    /// What pip installs for it: pytetwild 0.4 imports pyvista in its
    /// `__init__` but lists it only under its `all` extra.
    fn packages(self) -> &'static [&'static str] {
        match self {
            Peer::TetGen => &["tetgen"],
            Peer::Gmsh => &["gmsh"],
            Peer::FTetWild => &["pytetwild[all]"],
        }
    }

    /// How the row names it, with the parameter it ran with.
    pub(crate) fn label(self, param: f64) -> String {
        match self {
            Peer::TetGen => format!("TetGen -pq1.2a{param:.2e}"),
            Peer::Gmsh => format!("Gmsh, size ≤ {param:.3e}"),
            Peer::FTetWild => format!("fTetWild, ε 1e-3, edge {param:.3e}"),
        }
    }

    /// The first parameter for a count of `target` tetrahedra filling
    /// `volume` (both from trilux's plain stuffing of the same surface).
    /// TetGen's cap is the mean volume; Gmsh's size and fTetWild's edge
    /// length are the edge of a regular tetrahedron of that volume,
    /// `(6√2 V)^(1/3)`.
    fn first_param(self, target: usize, volume: f64) -> f64 {
        let mean = volume / target.max(1) as f64;
        match self {
            Peer::TetGen => mean,
            Peer::Gmsh | Peer::FTetWild => (6.0 * 2f64.sqrt() * mean).cbrt(),
        }
    }

    /// The parameter that scales the count by `1 / ratio`: the volume cap
    /// goes with the count, a length with its cube root. fTetWild is not
    /// calibrated (one run costs seconds to minutes), so `None`.
    fn recalibrate(self, param: f64, ratio: f64) -> Option<f64> {
        match self {
            Peer::TetGen => Some(param * ratio),
            Peer::Gmsh => Some(param * ratio.cbrt()),
            Peer::FTetWild => None,
        }
    }
}

/// Whether a peer imports, or why not (one line).
pub(crate) type Installed = (Peer, Result<(), String>);

/// The Python of the peers' venv (`target/peers-venv`, shared with the
/// other examples' peers), created when missing, with the packages of
/// `wanted` installed where they do not import yet; per peer, whether it
/// imports now.
fn set_up(wanted: &[Peer]) -> (PathBuf, Vec<Installed>) {
    let venv = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/peers-venv");
    let python = venv.join("bin/python");
    let imports = |peer: Peer| -> Result<(), String> {
        let out = Command::new(&python)
            .args(["-c", &format!("import {}", peer.module())])
            .output()
            .map_err(|e| format!("could not run {}: {e}", python.display()))?;
        if out.status.success() {
            Ok(())
        } else {
            Err(last_line(&out.stderr))
        }
    };
    let missing: Vec<Peer> = wanted
        .iter()
        .copied()
        .filter(|&p| imports(p).is_err())
        .collect();
    if !missing.is_empty() {
        let mut packages = vec!["numpy"];
        packages.extend(missing.iter().flat_map(|p| p.packages()));
        eprintln!(
            "setting up the peers: python3 -m venv {} && pip install {}",
            venv.display(),
            packages.join(" ")
        );
        let run = |cmd: &mut Command| cmd.status().is_ok_and(|s| s.success());
        if !python.exists() && !run(Command::new("python3").arg("-m").arg("venv").arg(&venv)) {
            eprintln!("could not create the venv");
        } else if !run(Command::new(&python)
            .args(["-m", "pip", "install", "--quiet"])
            .args(&packages))
        {
            eprintln!("pip install failed; the peers that do not import are left out");
        }
    }
    let status = wanted.iter().map(|&p| (p, imports(p))).collect();
    (python, status)
}

/// What a peer made of one surface.
pub(crate) struct Measured {
    /// The parameter of the timed runs (see [`Peer::label`]).
    pub(crate) param: f64,
    pub(crate) tets: usize,
    /// Median meshing time of the runs, milliseconds.
    pub(crate) ms: f64,
    pub(crate) min_dihedral_deg: f64,
    pub(crate) max_dihedral_deg: f64,
    /// The boundary triangles against the input, as trilux's report.
    pub(crate) distance: SurfaceDistance,
}

/// Runs peers on surfaces.
pub(crate) struct Runner {
    python: PathBuf,
    /// The peers asked for, each installed or why not.
    pub(crate) installed: Vec<Installed>,
    /// A folder for the raw files.
    work: PathBuf,
    /// Timed runs per surface (the median is reported).
    runs: usize,
    /// The time one run may take before it is stopped.
    cap: Duration,
}

impl Runner {
    /// Sets up the venv for `wanted` (see [`set_up`]); the raw files go
    /// to `work`.
    pub(crate) fn new(wanted: &[Peer], work: PathBuf, runs: usize, cap: Duration) -> Runner {
        let (python, installed) = set_up(wanted);
        Runner {
            python,
            installed,
            work,
            runs,
            cap,
        }
    }

    /// `peer` on the surface `(p, t)` named `name`, aiming at `target`
    /// tetrahedra in `volume` (TetGen and Gmsh recalibrate up to twice for
    /// a count within 20 %; the calibrating run counts as the first timed
    /// one). `Err` is the row's one-line reason: the peer's own error, a
    /// crash, or the time cap passed.
    pub(crate) fn run(
        &self,
        peer: Peer,
        name: &str,
        p: &[DVec3],
        t: &[[u32; 3]],
        target: usize,
        volume: f64,
    ) -> Result<Measured, String> {
        let prefix = self.work.join(name.replace(' ', "_"));
        write_surface(&prefix, p, t).map_err(|e| format!("could not write the surface: {e}"))?;
        let script = self.work.join("peers.py");
        std::fs::write(&script, SCRIPT).map_err(|e| format!("could not write the script: {e}"))?;
        let mut param = peer.first_param(target, volume);
        let mut first = self.once(peer, &script, &prefix, param)?;
        for _ in 0..2 {
            let ratio = first.1 as f64 / target.max(1) as f64;
            if (0.8..=1.2).contains(&ratio) {
                break;
            }
            let Some(next) = peer.recalibrate(param, ratio) else {
                break;
            };
            param = next;
            first = self.once(peer, &script, &prefix, param)?;
        }
        let mut ms = vec![first.0];
        for _ in 1..self.runs.max(1) {
            ms.push(self.once(peer, &script, &prefix, param)?.0);
        }
        ms.sort_by(f64::total_cmp);
        let (nodes, tets) = read_tets(&prefix, peer)?;
        let faces = boundary(&tets);
        let samples = Options::new(1.0).distance_samples;
        let distance = stuffing::surface_distance(p, t, &nodes, &faces, samples)
            .map_err(|e| format!("measuring its boundary: {e}"))?;
        let q = stuffing::quality(&nodes, &tets);
        Ok(Measured {
            param,
            tets: tets.len(),
            ms: ms[ms.len() / 2],
            min_dihedral_deg: q.min_dihedral_deg,
            max_dihedral_deg: q.max_dihedral_deg,
            distance,
        })
    }

    /// One run in a child process, killed at the cap: (ms, tetrahedra).
    fn once(
        &self,
        peer: Peer,
        script: &Path,
        prefix: &Path,
        param: f64,
    ) -> Result<(f64, usize), String> {
        let out_path = prefix.with_extension(format!("{}.out", peer.tool()));
        let err_path = prefix.with_extension(format!("{}.err", peer.tool()));
        let file = |p: &Path| std::fs::File::create(p).map_err(|e| format!("{}: {e}", p.display()));
        // In the work folder: TetGen leaves debug files where it fails.
        let mut child = Command::new(&self.python)
            .current_dir(&self.work)
            .arg(script)
            .arg(peer.tool())
            .arg(prefix)
            .arg(format!("{param:e}"))
            .stdout(Stdio::from(file(&out_path)?))
            .stderr(Stdio::from(file(&err_path)?))
            .spawn()
            .map_err(|e| format!("could not run {}: {e}", self.python.display()))?;
        let start = Instant::now();
        let status = loop {
            match child.try_wait() {
                Ok(Some(status)) => break status,
                Ok(None) if start.elapsed() > self.cap => {
                    // Our own child, by its handle.
                    let _ = child.kill();
                    let _ = child.wait();
                    return Err(format!("> {} s (stopped)", self.cap.as_secs()));
                }
                Ok(None) => std::thread::sleep(Duration::from_millis(50)),
                Err(e) => return Err(format!("waiting for it: {e}")),
            }
        };
        let stdout = std::fs::read_to_string(&out_path).unwrap_or_default();
        let line = stdout.lines().last().unwrap_or("");
        if !status.success() || line.is_empty() {
            let stderr = std::fs::read(&err_path).unwrap_or_default();
            return Err(format!("crashed ({status}): {}", last_line(&stderr)));
        }
        if let Some(e) = field(line, "error") {
            return Err(format!("refused: {e}"));
        }
        let ms = field(line, "ms").and_then(|s| s.parse().ok());
        let tets = field(line, "tets").and_then(|s| s.parse().ok());
        match (ms, tets) {
            (Some(ms), Some(tets)) if tets > 0 => Ok((ms, tets)),
            _ => Err(format!("no tetrahedra ({line})")),
        }
    }
}

/// The last non-blank line of a tool's output, trimmed.
fn last_line(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes)
        .lines()
        .rev()
        .find(|l| !l.trim().is_empty())
        .unwrap_or("no output")
        .trim()
        .to_string()
}

/// The surface as `peers.py` and TetGen's script read it: `.pos`
/// (f64 × 3) and `.tri` (u32 × 3).
pub(super) fn write_surface(prefix: &Path, p: &[DVec3], t: &[[u32; 3]]) -> std::io::Result<()> {
    let pos: Vec<u8> = p
        .iter()
        .flat_map(|v| v.to_array())
        .flat_map(f64::to_le_bytes)
        .collect();
    std::fs::write(prefix.with_extension("pos"), pos)?;
    let tri: Vec<u8> = t.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(prefix.with_extension("tri"), tri)
}

/// A peer's nodes and tetrahedra, every index checked against the nodes.
fn read_tets(prefix: &Path, peer: Peer) -> Result<(Vec<DVec3>, Vec<[u32; 4]>), String> {
    let read = |ext: &str| {
        let path = prefix.with_extension(format!("{}.{ext}", peer.tool()));
        std::fs::read(&path).map_err(|e| format!("its output {}: {e}", path.display()))
    };
    let node = read("node.raw")?;
    let ele = read("ele.raw")?;
    let nodes: Vec<DVec3> = node
        .chunks_exact(24)
        .map(|c| {
            let x: [f64; 3] = std::array::from_fn(|i| {
                f64::from_le_bytes(c[8 * i..8 * i + 8].try_into().unwrap_or([0; 8]))
            });
            DVec3::from(x)
        })
        .collect();
    let tets: Vec<[u32; 4]> = ele
        .chunks_exact(16)
        .map(|c| {
            std::array::from_fn(|i| {
                u32::from_le_bytes(c[4 * i..4 * i + 4].try_into().unwrap_or([0; 4]))
            })
        })
        .collect();
    if let Some(bad) = tets.iter().flatten().find(|&&v| v as usize >= nodes.len()) {
        return Err(format!("its output names node {bad} of {}", nodes.len()));
    }
    Ok((nodes, tets))
}

/// The faces that belong to one tetrahedron only, as (unoriented for the
/// distance) triangles: sorted, so the same tetrahedra give the same list.
fn boundary(tets: &[[u32; 4]]) -> Vec<[u32; 3]> {
    let mut faces: Vec<[u32; 3]> = tets
        .iter()
        .flat_map(|&[a, b, c, d]| [[a, b, c], [a, b, d], [a, c, d], [b, c, d]])
        .map(|mut f| {
            f.sort_unstable();
            f
        })
        .collect();
    faces.sort_unstable();
    let mut out = Vec::new();
    let mut i = 0;
    while i < faces.len() {
        let mut j = i + 1;
        while j < faces.len() && faces[j] == faces[i] {
            j += 1;
        }
        if j - i == 1 {
            out.push(faces[i]);
        }
        i = j;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boundary_of_two_tets_sharing_a_face_is_six_triangles() {
        let faces = boundary(&[[0, 1, 2, 3], [1, 2, 3, 4]]);
        assert_eq!(faces.len(), 6);
        assert!(!faces.contains(&[1, 2, 3]));
    }

    #[test]
    fn field_reads_numbers_and_errors() {
        let line = r#"{"ms": 12.5, "tets": 40}"#;
        assert_eq!(field(line, "ms"), Some("12.5"));
        assert_eq!(field(line, "tets"), Some("40"));
        let line = r#"{"error": "surface is not closed"}"#;
        assert_eq!(field(line, "error"), Some("surface is not closed"));
        // An escaped quote inside the message does not end it.
        let line = r#"{"error": "no \"volume\" here", "ms": 3}"#;
        assert_eq!(field(line, "error"), Some(r#"no \"volume\" here"#));
        assert_eq!(field(line, "ms"), Some("3"));
    }
}
