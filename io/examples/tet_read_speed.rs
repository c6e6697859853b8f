//! Parsing speed of the ASCII tetrahedral mesh readers on the largest tet
//! mesh of `$TRILUX_DATA/tets` (bunny_500k), in MB of input per second on
//! one core: parsing from memory (the reader's own cost) and end to end
//! from the file; then the triangle-mesh readers on nefertiti.obj and the
//! same mesh written as ASCII and binary PLY, with their ratio to the OBJ
//! reader in the same run. Medians of 7 runs. Markdown on stdout.
//!
//! ```text
//! TRILUX_DATA=../shared/data cargo run --release -p trilux-io --example tet_read_speed
//! ```

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use trilux_io::mesh::{obj, ply};
use trilux_io::tet::{TetMesh, gmsh, medit, tetgen};

const RUNS: usize = 7;

fn median_seconds(mut f: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..RUNS)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[RUNS / 2]
}

fn data_dir() -> Option<PathBuf> {
    let given = PathBuf::from(std::env::var_os("TRILUX_DATA")?);
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    [given.clone(), workspace.join(&given)]
        .into_iter()
        .find(|p| p.is_dir())
}

fn main() -> ExitCode {
    let Some(data) = data_dir() else {
        eprintln!(
            "tet_read_speed: set TRILUX_DATA to the data folder (it holds tets/bunny_500k.*)"
        );
        return ExitCode::from(2);
    };
    let tets = data.join("tets");
    let read = |name: &str| match std::fs::read(tets.join(name)) {
        Ok(bytes) => Ok(bytes),
        Err(e) => Err(format!("{}: {e}", tets.join(name).display())),
    };
    let (node, ele, msh) = match (
        read("bunny_500k.node"),
        read("bunny_500k.ele"),
        read("bunny_500k.msh"),
    ) {
        (Ok(n), Ok(e), Ok(m)) => (n, e, m),
        (Err(e), _, _) | (_, Err(e), _) | (_, _, Err(e)) => {
            eprintln!("tet_read_speed: {e}");
            return ExitCode::FAILURE;
        }
    };
    let base = tets.join("bunny_500k.node");
    let msh_path = tets.join("bunny_500k.msh");
    // No MEDIT file in the data set: write the same mesh as one.
    let medit_path = std::env::temp_dir().join(format!("trilux-bunny-{}.mesh", std::process::id()));
    let bunny = TetMesh::read(&base).expect("valid");
    if let Err(e) = medit::write(&medit_path, &bunny) {
        eprintln!("tet_read_speed: {e}");
        return ExitCode::FAILURE;
    }
    let mesh_bytes = std::fs::read(&medit_path).unwrap_or_default();

    let rows: Vec<(&str, usize, f64, f64)> = vec![
        (
            "TetGen .node + .ele",
            node.len() + ele.len(),
            median_seconds(|| {
                black_box(tetgen::from_bytes(&node, &ele, &base).expect("valid"));
            }),
            median_seconds(|| {
                black_box(TetMesh::read(&base).expect("valid"));
            }),
        ),
        (
            "MEDIT .mesh (written from the same mesh)",
            mesh_bytes.len(),
            median_seconds(|| {
                black_box(medit::from_bytes(&mesh_bytes, &medit_path).expect("valid"));
            }),
            median_seconds(|| {
                black_box(TetMesh::read(&medit_path).expect("valid"));
            }),
        ),
        (
            "Gmsh 4.1 ASCII .msh",
            msh.len(),
            median_seconds(|| {
                black_box(gmsh::from_bytes(&msh, &msh_path).expect("valid"));
            }),
            median_seconds(|| {
                black_box(TetMesh::read(&msh_path).expect("valid"));
            }),
        ),
    ];
    let boundary_s = median_seconds(|| {
        black_box(bunny.boundary());
    });
    let _ = std::fs::remove_file(&medit_path);

    println!(
        "## trilux-io: ASCII tet readers on bunny_500k (93,375 nodes, 507,125 tets), one core\n"
    );
    println!("| reader | input MB | parse ms | parse MB/s | file→mesh ms | file→mesh MB/s |");
    println!("|---|---:|---:|---:|---:|---:|");
    for (name, bytes, parse, whole) in rows {
        let mb = bytes as f64 / 1e6;
        println!(
            "| {name} | {mb:.1} | {:.1} | {:.0} | {:.1} | {:.0} |",
            parse * 1e3,
            mb / parse,
            whole * 1e3,
            mb / whole
        );
    }
    println!(
        "\nBoundary derivation (43,188 triangles from 507,125 tets): {:.1} ms",
        boundary_s * 1e3
    );
    match mesh_rows(&data) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("tet_read_speed: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The triangle-mesh readers on one mesh in three encodings.
fn mesh_rows(data: &Path) -> Result<(), trilux_io::Error> {
    let path = data.join("meshes/nefertiti.obj");
    let obj_bytes = std::fs::read(&path).map_err(|e| trilux_io::Error {
        path: path.clone(),
        location: None,
        kind: trilux_io::ErrorKind::Io(e),
    })?;
    let mesh = obj::from_bytes(&obj_bytes, &path)?;
    let cloud = ply::PlyData {
        positions: mesh.positions.clone(),
        triangles: mesh.indices.clone(),
        normals: mesh.normals.clone(),
        ..ply::PlyData::default()
    };
    let ascii = ply::to_bytes("n.ply", &cloud, ply::Format::Ascii)?;
    let binary = ply::to_bytes("n.ply", &cloud, ply::Format::BinaryLittleEndian)?;
    let obj_s = median_seconds(|| {
        black_box(obj::from_bytes(&obj_bytes, &path).expect("valid"));
    });
    let ascii_s = median_seconds(|| {
        black_box(ply::from_bytes(&ascii, "n.ply").expect("valid"));
    });
    let binary_s = median_seconds(|| {
        black_box(ply::from_bytes(&binary, "n.ply").expect("valid"));
    });
    println!(
        "\n## trilux-io: triangle-mesh readers on nefertiti ({} vertices, {} triangles), one core\n",
        mesh.positions.len(),
        mesh.indices.len()
    );
    println!("| reader | input MB | parse ms | parse MB/s | time vs. OBJ |");
    println!("|---|---:|---:|---:|---:|");
    for (name, bytes, seconds) in [
        ("OBJ (line pre-pass, f64 parse)", obj_bytes.len(), obj_s),
        ("PLY ASCII", ascii.len(), ascii_s),
        ("PLY binary little-endian", binary.len(), binary_s),
    ] {
        let mb = bytes as f64 / 1e6;
        println!(
            "| {name} | {mb:.1} | {:.1} | {:.0} | {:.2} |",
            seconds * 1e3,
            mb / seconds,
            seconds / obj_s
        );
    }
    Ok(())
}
