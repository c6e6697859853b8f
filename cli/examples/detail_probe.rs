//! Scratch: where the detail brush's time goes (not committed).
use std::time::Instant;
use trilux::mesh_colors::MipMap;
use trilux::mesh_colors::gpu::GpuLayout;
use trilux::mesh_colors::session::{Changed, Edit, PaintSession};

fn main() {
    let d = std::path::PathBuf::from(std::env::var("TRILUX_DATA").unwrap());
    let mesh = trilux_io::mesh::TriMesh::read(d.join("meshes/spot.obj")).unwrap();
    let image = trilux_io::image::read(d.join("textures/spot_texture.png")).unwrap();
    let (surface, colors) =
        trilux::to_mesh_colors(&mesh, Some(&image), &Default::default()).unwrap();
    let positions = surface.positions.clone();
    let faces = colors.topology().faces().to_vec();
    let mut s = PaintSession::new(positions.clone(), colors, vec![0.8; 3], 64, None).unwrap();
    let mut mip = MipMap::new(s.colors().clone());
    let mut gpu = GpuLayout::new(&mip, 2048).unwrap();
    let centre = positions[0];
    let mut dd: Vec<f32> = faces
        .iter()
        .map(|f| {
            f.iter()
                .map(|&v| positions[v as usize].distance(centre))
                .fold(f32::INFINITY, f32::min)
        })
        .collect();
    dd.sort_by(f32::total_cmp);
    let reach = dd[999];
    for round in 0..40 {
        for (what, edit) in [
            (
                "detail",
                Edit::Detail {
                    center: centre,
                    radius: reach,
                    levels: 1,
                },
            ),
            ("undo", Edit::Undo),
        ] {
            let n0 = s.colors().sample_count();
            let t0 = Instant::now();
            let changed = s.apply(edit).unwrap();
            if round == 0 {
                println!("samples {n0} -> {}", s.colors().sample_count());
            }
            let t1 = Instant::now();
            let Changed::Layout(fs) = changed else {
                panic!()
            };
            let spans = mip.refresh_resolutions(s.colors(), &fs).unwrap();
            let t2 = Instant::now();
            let ch = gpu.refresh_resolutions(&mip, &spans).unwrap();
            let t3 = Instant::now();
            println!(
                "{round} {what}: faces {} apply {:.1} mip {:.1} gpu {:.1} resized {}",
                fs.len(),
                (t1 - t0).as_secs_f64() * 1e3,
                (t2 - t1).as_secs_f64() * 1e3,
                (t3 - t2).as_secs_f64() * 1e3,
                ch.resized
            );
        }
    }
}
