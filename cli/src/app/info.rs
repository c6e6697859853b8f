//! `trilux info`: what a file holds, as a person checks an input before a
//! long run.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::{Value, json};

use super::{Context, Result, file_cause, file_error};

#[derive(Debug, clap::Args)]
#[command(
    about = "Describe a mesh, tetrahedral mesh, TetGen .face file, image or .meshcolors file (counts, bounds, UVs, holes, quality)",
    after_help = "Example:\n  trilux info ../shared/data/meshes/stanford-bunny.obj\n  trilux info ../shared/data/tets/bunny_50k.node --json\n  trilux info ../shared/data/tets/bunny_50k.face"
)]
pub(crate) struct Args {
    /// The file: .obj .gltf .glb .ply, .node .ele .msh .mesh, .face (with
    /// its .node and .ele), .png .jpg .hdr .exr, .meshcolors.
    pub(crate) file: PathBuf,
}

pub(crate) fn run(context: &mut Context, args: Args) -> Result<()> {
    let path = &args.file;
    super::check_input(path)?;
    let (text, json) = match super::extension(path).as_str() {
        "obj" => mesh_info(context, path)?,
        "gltf" | "glb" => gltf_info(context, path)?,
        "ply" => ply_info(context, path)?,
        "node" | "ele" | "msh" | "mesh" => tet_info(context, path)?,
        "face" => face_info(context, path)?,
        "png" | "jpg" | "jpeg" | "hdr" | "exr" => image_info(context, path)?,
        "meshcolors" => meshcolors_info(context, path)?,
        other => {
            return Err(file_error(
                path,
                format!(
                    "unknown extension {other:?} (meshes .obj .gltf .glb .ply, tetrahedra .node .ele .msh .mesh, TetGen faces .face, images .png .jpg .hdr .exr, .meshcolors)"
                ),
            ));
        }
    };
    context.report(&text, json);
    Ok(())
}

/// Lists what the reader skipped or replaced (`warnings` in the JSON),
/// each naming the file, the element and what was skipped, so that a user
/// sees what the mesh lacks before a long run.
fn add_warnings(text: &mut String, json: &mut Value, warnings: &[trilux_io::Warning]) {
    if !warnings.is_empty() {
        let _ = writeln!(text, "  warnings: {}", warnings.len());
        for w in warnings {
            let _ = writeln!(text, "    {w}");
        }
    }
    if let Some(object) = json.as_object_mut() {
        let list = warnings.iter().map(ToString::to_string).collect::<Vec<_>>();
        object.insert("warnings".into(), json!(list));
    }
}

fn v3(v: glam::Vec3) -> Value {
    json!([v.x, v.y, v.z])
}

fn mesh_info(context: &mut Context, path: &Path) -> Result<(String, Value)> {
    let mesh = context.step("reading the mesh", || trilux_io::mesh::TriMesh::read(path))?;
    Ok(describe_mesh(context, path, "triangle mesh", &mesh))
}

/// A glTF file: its triangles as [`describe_mesh`] does, with their
/// vertex colours and `_NAME` attributes, and its `POINTS` primitives
/// (a point cloud, as a PLY one is reported, when there are no
/// triangles).
fn gltf_info(context: &mut Context, path: &Path) -> Result<(String, Value)> {
    use trilux_io::mesh::gltf;
    let scene = context.step("reading the glTF file", || gltf::read_scene(path))?;
    let points = &scene.points;
    if scene.mesh.indices.is_empty() && !points.positions.is_empty() {
        let mut text = format!("{}: point cloud\n", path.display());
        let mut json = json!({"file": super::shown(path), "kind": "point cloud"});
        describe_points(&mut text, &mut json, points, "");
        add_warnings(&mut text, &mut json, &scene.mesh.warnings);
        return Ok((text, json));
    }
    let mut extra = String::new();
    let mut more = json!({});
    describe_vertex_data(&mut extra, &mut more, &scene.vertex_data);
    if !points.positions.is_empty() {
        // Points beside the triangles: their own lines, and an object
        // of their own in the JSON.
        let _ = writeln!(extra, "  point cloud (POINTS primitives):");
        let mut cloud = json!({});
        describe_points(&mut extra, &mut cloud, points, "  ");
        if let Some(object) = more.as_object_mut() {
            object.insert("point_cloud".into(), cloud);
        }
    }
    let (text, json) =
        describe_mesh_with(context, path, "triangle mesh", &scene.mesh, (&extra, more));
    Ok((text, json))
}

/// The lines and JSON keys of glTF points: count, bounds, and what each
/// point carries (`attributes`, named as for a PLY point cloud, a `_NAME`
/// attribute with its components), the UVs' and face ids' ranges, and
/// the JSON keys of [`describe_vertex_data`]; `indent` goes before each
/// line's own two spaces.
fn describe_points(
    text: &mut String,
    json: &mut Value,
    points: &trilux_io::mesh::gltf::Points,
    indent: &str,
) {
    let n = points.positions.len();
    let (lo, hi) = trilux::preview::bounds(&points.positions).unwrap_or_default();
    // In the file's coordinates: the reader shifts far-away points by
    // `origin` to keep f32 precision (then shown in f64).
    let (bounds, bounds_json) = if points.origin == glam::DVec3::ZERO {
        (format!("{lo} .. {hi}"), json!([v3(lo), v3(hi)]))
    } else {
        let (lo, hi) = (lo.as_dvec3() + points.origin, hi.as_dvec3() + points.origin);
        (
            format!("{lo} .. {hi}"),
            json!([lo.to_array(), hi.to_array()]),
        )
    };
    let _ = writeln!(text, "{indent}  points: {n}");
    let _ = writeln!(text, "{indent}  bounds: {bounds}");
    let mut attributes = Vec::new();
    let mut shown = Vec::new();
    let mut add = |name: String, detail: String| {
        shown.push(format!("{name}{detail}"));
        attributes.push(name);
    };
    if points.normals.is_some() {
        add("normals".into(), String::new());
    }
    if points.uvs.is_some() {
        add("uvs".into(), String::new());
    }
    if let Some(colors) = &points.vertex_data.colors {
        add("colors".into(), format!(" ({})", color_kind(colors)));
    }
    if points.faces.is_some() {
        add("face ids".into(), " (_FACE)".into());
    }
    for a in &points.vertex_data.attributes {
        add(format!("_{}", a.name), components(a.values.components()));
    }
    let _ = writeln!(
        text,
        "{indent}  attributes: {}",
        if shown.is_empty() {
            "none".to_string()
        } else {
            shown.join(", ")
        }
    );
    let faces = points.faces.as_ref().map(|f| {
        let lo = f.iter().copied().min().unwrap_or(0);
        let hi = f.iter().copied().max().unwrap_or(0);
        let _ = writeln!(text, "{indent}  face ids: {lo} .. {hi}");
        json!([lo, hi])
    });
    let uvs = points.uvs.as_ref().map(|uvs| {
        let mut line = String::new();
        let range = describe_uvs(&mut line, Some(uvs));
        text.push_str(indent);
        text.push_str(&line);
        range
    });
    let mut data = json!({});
    describe_vertex_data(&mut String::new(), &mut data, &points.vertex_data);
    if let Some(object) = json.as_object_mut() {
        object.insert("points".into(), json!(n));
        object.insert("bounds".into(), bounds_json);
        object.insert("attributes".into(), json!(attributes));
        object.insert("normals".into(), json!(points.normals.is_some()));
        object.insert("uvs".into(), uvs.unwrap_or(Value::Null));
        object.insert("face_ids".into(), faces.unwrap_or(Value::Null));
        if let Value::Object(data) = data {
            object.extend(data);
        }
    }
}

/// ` (3 components)`, ` (1 component)`.
fn components(n: usize) -> String {
    format!(" ({n} component{})", if n == 1 { "" } else { "s" })
}

/// `RGB`, or `RGBA` when some alpha is below 1 (glTF's writer stores
/// opaque colours as `VEC3`).
fn color_kind(colors: &[[f32; 4]]) -> &'static str {
    if colors.iter().any(|c| c[3] != 1.0) {
        "RGBA"
    } else {
        "RGB"
    }
}

/// glTF's `COLOR_0` and `_NAME` attributes as lines and as the JSON keys `colors` (`"RGB"`,
/// `"RGBA"` or null) and `custom_attributes` (the name and components
/// of each, in the order of the file).
fn describe_vertex_data(
    text: &mut String,
    json: &mut Value,
    data: &trilux_io::mesh::gltf::VertexData,
) {
    let colors = data.colors.as_deref().map(color_kind);
    let _ = writeln!(
        text,
        "  vertex colours (COLOR_0): {}",
        colors.unwrap_or("none")
    );
    let custom: Vec<(String, usize)> = data
        .attributes
        .iter()
        .map(|a| (format!("_{}", a.name), a.values.components()))
        .collect();
    let _ = writeln!(
        text,
        "  custom attributes: {}",
        if custom.is_empty() {
            "none".to_string()
        } else {
            custom
                .iter()
                .map(|(name, n)| format!("{name}{}", components(*n)))
                .collect::<Vec<_>>()
                .join(", ")
        }
    );
    if let Some(object) = json.as_object_mut() {
        object.insert("colors".into(), json!(colors));
        object.insert(
            "custom_attributes".into(),
            custom
                .iter()
                .map(|(name, n)| json!({"name": name, "components": n}))
                .collect(),
        );
    }
}

fn ply_info(context: &mut Context, path: &Path) -> Result<(String, Value)> {
    let ply = context.step("reading the PLY file", || trilux_io::mesh::ply::read(path))?;
    if !ply.triangles.is_empty() {
        return mesh_info(context, path);
    }
    let (lo, hi) = trilux::preview::bounds(&ply.positions).unwrap_or_default();
    let mut text = format!(
        "{}: point cloud\n  points: {}\n  bounds: {lo} .. {hi}\n",
        path.display(),
        ply.positions.len()
    );
    let mut attributes = Vec::new();
    if ply.normals.is_some() {
        attributes.push("normals".to_string());
    }
    if ply.uvs.is_some() {
        attributes.push("uvs".to_string());
    }
    if ply.colors.is_some() {
        attributes.push("colors".to_string());
    }
    if ply.face_ids.is_some() {
        attributes.push("face ids".to_string());
    }
    attributes.extend(ply.scalars.iter().map(|(n, _)| n.clone()));
    let _ = writeln!(text, "  attributes: {}", attributes.join(", "));
    let mut json = json!({"file": super::shown(path), "kind": "point cloud", "points": ply.positions.len(),
               "bounds": [v3(lo), v3(hi)], "attributes": attributes});
    add_warnings(&mut text, &mut json, &ply.warnings);
    Ok((text, json))
}

/// What `mesh` (read from `path`, a `kind` of file) is: counts, bounds,
/// topology, attributes.
fn describe_mesh(
    context: &mut Context,
    path: &Path,
    kind: &str,
    mesh: &trilux_io::mesh::TriMesh,
) -> (String, Value) {
    describe_mesh_with(context, path, kind, mesh, ("", json!({})))
}

/// As [`describe_mesh`], with `extra` lines and JSON keys (a glTF file's
/// vertex colours and attributes) before the warnings.
fn describe_mesh_with(
    context: &mut Context,
    path: &Path,
    kind: &str,
    mesh: &trilux_io::mesh::TriMesh,
    (extra_text, extra_json): (&str, Value),
) -> (String, Value) {
    let shape = context.step("checking the topology", || trilux::mesh::shape(mesh));
    // A file without faces (empty, or points only) has no surface: no
    // bounds of triangles, and it is neither closed nor open.
    let faceless = mesh.indices.is_empty();
    // In the file's coordinates: the reader shifts far-away meshes by
    // `origin` to keep f32 precision.
    let bounds = trilux::mesh::bounds(mesh)
        .map(|(lo, hi)| (lo.as_dvec3() + mesh.origin, hi.as_dvec3() + mesh.origin));
    let (lo, hi) = bounds.unwrap_or_default();
    let diagonal = (hi - lo).length();
    let used = used_vertices(mesh);
    // `+ 0.0` turns the empty sum's -0 into 0.
    let area = mesh.area() + 0.0;
    let mut text = format!(
        "{}: {kind}{}\n",
        path.display(),
        if faceless { " with no faces" } else { "" }
    );
    let _ = writeln!(
        text,
        "  vertices: {} ({} used, {} after welding equal positions)",
        mesh.positions.len(),
        used,
        shape.welded_vertices
    );
    let closed = !faceless && shape.boundary_edges == 0 && shape.non_manifold_edges == 0;
    if faceless {
        let _ = writeln!(
            text,
            "  triangles: 0 — no faces (an empty file or points only), so no surface"
        );
    } else {
        describe_surface(&mut text, mesh, &shape, (lo, hi), (area, closed));
    }
    let _ = writeln!(
        text,
        "  normals: {}",
        if mesh.normals.is_some() { "yes" } else { "no" }
    );
    let uv_json = describe_uvs(&mut text, mesh.uvs.as_deref());
    let materials = describe_materials(&mut text, mesh);
    let _ = writeln!(text, "  objects: {}", mesh.objects.len());
    let mut json = json!({
        "file": super::shown(path),
        "kind": kind,
        "vertices": mesh.positions.len(),
        "used_vertices": used,
        "welded_vertices": shape.welded_vertices,
        "triangles": mesh.indices.len(),
        "bounds": bounds.map(|(lo, hi)| json!([lo.to_array(), hi.to_array()])),
        "diagonal": diagonal,
        "unit_guess": trilux::mesh::unit_guess(diagonal as f32),
        "area": area,
        "parts": shape.parts,
        "holes": shape.holes,
        "boundary_edges": shape.boundary_edges,
        "non_manifold_edges": shape.non_manifold_edges,
        "closed": closed,
        "normals": mesh.normals.is_some(),
        "uvs": uv_json,
        "objects": mesh.objects.len(),
        "materials": materials,
    });
    text.push_str(extra_text);
    if let (Some(object), Value::Object(extra)) = (json.as_object_mut(), extra_json) {
        object.extend(extra);
    }
    add_warnings(&mut text, &mut json, &mesh.warnings);
    (text, json)
}

/// The lines of a mesh with faces: triangles, bounds, size, area, parts,
/// holes and edges (`closed`: no boundary or non-manifold edge).
fn describe_surface(
    text: &mut String,
    mesh: &trilux_io::mesh::TriMesh,
    shape: &trilux::mesh::Shape,
    (lo, hi): (glam::DVec3, glam::DVec3),
    (area, closed): (f64, bool),
) {
    let diagonal = (hi - lo).length();
    // For people, at the precision the file's positions have (f32), not
    // 17 digits of their f64 sum; a mesh the reader shifted to keep
    // precision (`origin`) shows its f64 values.
    let far = mesh.origin != glam::DVec3::ZERO;
    let point = |p: glam::DVec3| {
        if far {
            p.to_string()
        } else {
            p.as_vec3().to_string()
        }
    };
    let length = |x: f64| {
        if far {
            x.to_string()
        } else {
            (x as f32).to_string()
        }
    };
    let _ = writeln!(text, "  triangles: {}", mesh.indices.len());
    let _ = writeln!(
        text,
        "  bounds: {} .. {} (size {})",
        point(lo),
        point(hi),
        point(hi - lo)
    );
    let _ = writeln!(
        text,
        "  diagonal: {} — units look like {}",
        length(diagonal),
        trilux::mesh::unit_guess(diagonal as f32)
    );
    let _ = writeln!(text, "  area: {area:.6}");
    let _ = writeln!(
        text,
        "  parts: {}, holes: {} ({} boundary edges), non-manifold edges: {}{}",
        shape.parts,
        shape.holes,
        shape.boundary_edges,
        shape.non_manifold_edges,
        if closed { " — closed" } else { "" }
    );
}

/// How many vertices the triangles use.
fn used_vertices(mesh: &trilux_io::mesh::TriMesh) -> usize {
    let mut used = vec![false; mesh.positions.len()];
    for &v in mesh.indices.iter().flatten() {
        if let Some(u) = used.get_mut(v as usize) {
            *u = true;
        }
    }
    used.iter().filter(|&&u| u).count()
}

/// The UVs' range (and whether they tile) as a line of `text` and JSON.
fn describe_uvs(text: &mut String, uvs: Option<&[glam::Vec2]>) -> Value {
    match uvs {
        Some(uvs) => {
            let (ulo, uhi) = uvs.iter().fold(
                (glam::Vec2::INFINITY, glam::Vec2::NEG_INFINITY),
                |(a, b), &p| (a.min(p), b.max(p)),
            );
            let tiled = ulo.x < -0.01 || ulo.y < -0.01 || uhi.x > 1.01 || uhi.y > 1.01;
            let _ = writeln!(
                text,
                "  UVs: u {:.4} .. {:.4}, v {:.4} .. {:.4}{}",
                ulo.x,
                uhi.x,
                ulo.y,
                uhi.y,
                if tiled {
                    " — outside [0, 1]: the texture tiles (repeat wrap)"
                } else {
                    ""
                }
            );
            json!({"u": [ulo.x, uhi.x], "v": [ulo.y, uhi.y], "tiled": tiled})
        }
        None => {
            let _ = writeln!(text, "  UVs: none");
            Value::Null
        }
    }
}

/// One line of `text` and one JSON object per material.
fn describe_materials(text: &mut String, mesh: &trilux_io::mesh::TriMesh) -> Vec<Value> {
    mesh.materials
        .iter()
        .map(|m| {
            let texture = m
                .diffuse_image
                .as_ref()
                .map(|i| format!("{}×{} image", i.width, i.height))
                .or_else(|| m.diffuse_texture.as_ref().map(|p| p.display().to_string()));
            let _ = writeln!(
                text,
                "  material {:?}: diffuse {:?}{}",
                m.name,
                m.diffuse,
                texture
                    .as_ref()
                    .map(|t| format!(", texture {t}"))
                    .unwrap_or_default()
            );
            json!({"name": m.name, "diffuse": m.diffuse, "texture": texture})
        })
        .collect()
}

/// The tetrahedra `trilux diffuse` refuses (flat: |6V| ≤ 1e-12 × the
/// longest edge cubed, the rule of `tet_diffusion::TetMesh::new`) and the
/// ones it re-orients (inverted: negative volume), 0-based, so that `info`
/// names them instead of only counting.
fn flat_and_inverted(mesh: &trilux_io::tet::TetMesh) -> (Vec<usize>, Vec<usize>) {
    let mut flat = Vec::new();
    let mut inverted = Vec::new();
    for (t, tet) in mesh.tets.iter().enumerate() {
        let det = mesh.signed_volume6(t);
        let p = tet.map(|v| mesh.positions.get(v as usize).copied().unwrap_or_default());
        let longest = (0..4)
            .flat_map(|a| (a + 1..4).map(move |b| (a, b)))
            .map(|(a, b)| p[a].distance(p[b]))
            .fold(0.0, f64::max);
        if det.is_nan() || det.abs() <= 1e-12 * longest.powi(3) {
            flat.push(t);
        } else if det < 0.0 {
            inverted.push(t);
        }
    }
    (flat, inverted)
}

/// The lines under "inverted or flat tetrahedra" naming the first few.
fn write_bad_tets(text: &mut String, flat: &[usize], inverted: &[usize]) {
    let first = |list: &[usize]| {
        let shown: Vec<String> = list.iter().take(5).map(usize::to_string).collect();
        let more = if list.len() > 5 { ", …" } else { "" };
        format!("{}{more}", shown.join(", "))
    };
    if !flat.is_empty() {
        let _ = writeln!(
            text,
            "    flat (zero volume; diffuse refuses them): {} — tetrahedra {} (0-based)",
            flat.len(),
            first(flat)
        );
    }
    if !inverted.is_empty() {
        let _ = writeln!(
            text,
            "    inverted (diffuse re-orients them): {} — tetrahedra {} (0-based)",
            inverted.len(),
            first(inverted)
        );
    }
}

fn tet_info(context: &mut Context, path: &Path) -> Result<(String, Value)> {
    let mesh = super::read_tets(context, path)?;
    let (lo, hi) = mesh.positions.iter().fold(
        (glam::DVec3::INFINITY, glam::DVec3::NEG_INFINITY),
        |(a, b), &p| (a.min(p), b.max(p)),
    );
    let (flat, inverted_only) = flat_and_inverted(&mesh);
    let inverted = flat.len() + inverted_only.len();
    let boundary = mesh.boundary().len();
    let dihedral = context.step("measuring dihedral angles", || {
        trilux::tet::dihedral_range(&mesh)
    });
    let volume = mesh.volume();
    let mut text = format!("{}: tetrahedral mesh\n", path.display());
    let _ = writeln!(text, "  nodes: {}", mesh.positions.len());
    let _ = writeln!(text, "  tetrahedra: {}", mesh.tets.len());
    let _ = writeln!(text, "  boundary triangles: {boundary}");
    let _ = writeln!(text, "  bounds: {lo} .. {hi}");
    let _ = writeln!(text, "  volume: {volume:.6e}");
    let _ = writeln!(text, "  inverted or flat tetrahedra: {inverted}");
    write_bad_tets(&mut text, &flat, &inverted_only);
    match dihedral {
        Some((a, b)) => {
            let _ = writeln!(text, "  dihedral angles: {a:.3}° .. {b:.3}°");
        }
        None => {
            let _ = writeln!(text, "  dihedral angles: undefined (a flat tetrahedron)");
        }
    }
    // What a solver would choke on: nodes without tetrahedra (empty
    // rows), repeated tetrahedra, edges where the boundary is not a
    // closed manifold. Named, so the user can fix the file.
    let unused = mesh.unused_nodes();
    let duplicates = mesh.duplicate_tets();
    let non_manifold = mesh.non_manifold_boundary_edges();
    let first = |list: Vec<String>| {
        let shown: Vec<String> = list.iter().take(5).cloned().collect();
        let more = if list.len() > 5 { ", …" } else { "" };
        format!("{}{more}", shown.join(", "))
    };
    let _ = writeln!(text, "  unused nodes: {}", unused.len());
    if !unused.is_empty() {
        let nodes = first(unused.iter().map(u32::to_string).collect());
        let _ = writeln!(text, "    nodes {nodes} are used by no tetrahedron");
    }
    let _ = writeln!(text, "  duplicate tetrahedra: {}", duplicates.len());
    if !duplicates.is_empty() {
        let pairs = first(
            duplicates
                .iter()
                .map(|(a, b)| format!("{b} repeats {a}"))
                .collect(),
        );
        let _ = writeln!(text, "    tetrahedron {pairs}");
    }
    let _ = writeln!(
        text,
        "  non-manifold boundary edges: {}",
        non_manifold.len()
    );
    if !non_manifold.is_empty() {
        let edges = first(
            non_manifold
                .iter()
                .map(|e| format!("({}, {})", e[0], e[1]))
                .collect(),
        );
        let _ = writeln!(text, "    edges {edges}");
    }
    let mut json = json!({"file": super::shown(path), "kind": "tetrahedral mesh", "nodes": mesh.positions.len(),
               "tetrahedra": mesh.tets.len(), "boundary_triangles": boundary,
               "bounds": [lo.to_array(), hi.to_array()], "volume": volume, "inverted": inverted,
               "flat_tetrahedra": flat, "inverted_tetrahedra": inverted_only,
               "dihedral_degrees": dihedral.map(|(a, b)| [a, b]),
               "unused_nodes": unused, "duplicate_tetrahedra": duplicates,
               "non_manifold_boundary_edges": non_manifold});
    add_warnings(&mut text, &mut json, &mesh.warnings);
    Ok((text, json))
}

/// A TetGen `.face` file: its triangles as a surface (parts, holes,
/// closed), and whether they are the boundary of the tetrahedra of the
/// `.node` and `.ele` files beside it (TetGen can also list interior
/// faces, or faces of a mesh since changed).
fn face_info(context: &mut Context, path: &Path) -> Result<(String, Value)> {
    let files = context.step("reading the TetGen files", || {
        trilux_io::tet::tetgen::read_all(path)
    })?;
    let faces = files.faces.unwrap_or_default();
    let tets = &files.mesh;
    let key = |f: &[u32; 3]| {
        let mut k = *f;
        k.sort_unstable();
        k
    };
    let mut listed: Vec<[u32; 3]> = faces.iter().map(key).collect();
    listed.sort_unstable();
    let mut boundary: Vec<[u32; 3]> = tets.boundary().iter().map(key).collect();
    boundary.sort_unstable();
    let matches = listed == boundary;
    let surface = trilux_io::mesh::TriMesh {
        positions: tets.positions.iter().map(|p| p.as_vec3()).collect(),
        objects: vec![trilux_io::mesh::Object {
            name: String::new(),
            triangles: 0..faces.len(),
            material: None,
        }],
        indices: faces,
        ..Default::default()
    };
    let (mut text, mut json) = describe_mesh(context, path, "TetGen faces", &surface);
    let _ = writeln!(
        text,
        "  faces: {} ({} tetrahedra on {} nodes in the .node and .ele files)",
        surface.indices.len(),
        tets.tets.len(),
        tets.positions.len()
    );
    let _ = writeln!(
        text,
        "  the tetrahedra's boundary ({} triangles): {}",
        boundary.len(),
        if matches {
            "the same triangles"
        } else {
            "different triangles (interior faces, or a mesh changed since)"
        }
    );
    if let Some(object) = json.as_object_mut() {
        object.insert("faces".into(), json!(surface.indices.len()));
        object.insert("nodes".into(), json!(tets.positions.len()));
        object.insert("tetrahedra".into(), json!(tets.tets.len()));
        object.insert("boundary_triangles".into(), json!(boundary.len()));
        object.insert("matches_tetrahedra".into(), json!(matches));
    }
    Ok((text, json))
}

fn image_info(context: &mut Context, path: &Path) -> Result<(String, Value)> {
    let image = context.step("reading the image", || trilux_io::image::read(path))?;
    let mut lo = [f32::INFINITY; 4];
    let mut hi = [f32::NEG_INFINITY; 4];
    for p in &image.pixels {
        for c in 0..4 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    let lum = image.luminance();
    let mean = lum.iter().map(|&l| f64::from(l)).sum::<f64>() / lum.len().max(1) as f64;
    let max = lum.iter().copied().fold(0.0f32, f32::max);
    let zero = lum.iter().filter(|&&l| l <= 0.0).count();
    let mut text = format!("{}: image\n", path.display());
    let _ = writeln!(text, "  size: {}×{}", image.width, image.height);
    for (c, name) in ["R", "G", "B", "A"].iter().enumerate() {
        let _ = writeln!(text, "  {name} (linear): {} .. {}", lo[c], hi[c]);
    }
    let _ = writeln!(
        text,
        "  luminance (Rec. 709): mean {mean:.4}, max {max}, {zero} pixels at zero"
    );
    Ok((
        text,
        json!({"file": super::shown(path), "kind": "image", "width": image.width, "height": image.height,
               "min": lo, "max": hi, "luminance": {"mean": mean, "max": max, "zero_pixels": zero}}),
    ))
}

fn meshcolors_info(context: &mut Context, path: &Path) -> Result<(String, Value)> {
    let (colors, mip) = context
        .step("reading the mesh colours", || mesh_colors::file::load(path))
        .map_err(|e| file_cause(path, e))?;
    let mut histogram = std::collections::BTreeMap::new();
    for r in (0..colors.face_count()).filter_map(|f| colors.face_resolution(f)) {
        *histogram.entry(r).or_insert(0usize) += 1;
    }
    let mut text = format!("{}: mesh colours\n", path.display());
    let _ = writeln!(text, "  channels: {}", colors.channels());
    let _ = writeln!(text, "  vertices: {}", colors.topology().vertex_count());
    let _ = writeln!(text, "  faces: {}", colors.face_count());
    let _ = writeln!(text, "  samples: {}", colors.sample_count());
    let _ = writeln!(
        text,
        "  face resolutions: {}",
        histogram
            .iter()
            .map(|(r, n)| format!("R={r}: {n}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        text,
        "  MIP pyramid: {}",
        if mip.is_some() { "yes" } else { "no" }
    );
    Ok((
        text,
        json!({"file": super::shown(path), "kind": "mesh colours", "channels": colors.channels(),
               "vertices": colors.topology().vertex_count(), "faces": colors.face_count(),
               "samples": colors.sample_count(),
               "resolutions": histogram.iter().map(|(r, n)| (r.to_string(), json!(n))).collect::<serde_json::Map<_, _>>(),
               "mip": mip.is_some()}),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use trilux_io::mesh::gltf::{Attribute, AttributeValues, Points, VertexData};

    #[test]
    fn glb_points_list_their_colours_and_custom_attributes_far_from_the_origin() {
        let points = Points {
            positions: vec![glam::Vec3::ZERO, glam::Vec3::ONE],
            origin: glam::DVec3::new(1e6, 0.0, 0.0),
            vertex_data: VertexData {
                colors: Some(vec![[1.0, 0.0, 0.0, 0.5], [0.0, 1.0, 0.0, 1.0]]),
                attributes: vec![
                    Attribute {
                        name: "W".into(),
                        values: AttributeValues::Scalar(vec![1.0, 2.0]),
                    },
                    Attribute {
                        name: "DIR".into(),
                        values: AttributeValues::Vec3(vec![glam::Vec3::X; 2]),
                    },
                ],
            },
            ..Default::default()
        };
        let (mut text, mut json) = (String::new(), json!({}));
        describe_points(&mut text, &mut json, &points, "");
        assert_eq!(
            text,
            "  points: 2\n  bounds: [1000000, 0, 0] .. [1000001, 1, 1]\n  attributes: colors (RGBA), \
             _W (1 component), _DIR (3 components)\n"
        );
        assert_eq!(json["points"], 2);
        assert_eq!(
            json["bounds"],
            json!([[1e6, 0.0, 0.0], [1e6 + 1.0, 1.0, 1.0]])
        );
        assert_eq!(json["attributes"], json!(["colors", "_W", "_DIR"]));
        assert_eq!(json["colors"], "RGBA");
        assert_eq!(
            json["custom_attributes"],
            json!([{"name": "_W", "components": 1}, {"name": "_DIR", "components": 3}])
        );
        assert_eq!(
            (&json["normals"], &json["uvs"], &json["face_ids"]),
            (&json!(false), &Value::Null, &Value::Null)
        );
    }
}
