//! The thread that owns the paint session: it applies the page's
//! requests and sends the texels they changed.
//!
//! Snapshot slots (what a page that connects is sent first, in order):
//! 0 the hello, 1 the mesh, 2 the face table and the samples (then the
//! texel updates since, appended: strokes' and resolution changes',
//! folded back into one face table and one samples frame once the
//! requests pause), 3 the status, 4 the scatter panel's points and
//! strands.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use axum::body::Bytes;
use mesh_colors::MipMap;
use mesh_colors::gpu::{Changes, GpuLayout, TexelRect};
use mesh_colors::session::{Changed, Edit, PaintSession};
use serde_json::json;

use super::protocol::{ExportKind, Request};
use super::scatter::{ScatterState, Updated};
use super::{Document, LIMITS, MAGIC, Options, PAGE, VERSION};
use crate::web::frame::{HEADER, Header, LeWord, put_f32, put_slice, put_u32};
use crate::web::{App, Idle, Inbox, Limits, Out, Outbox, ReplyTo};

use super::TEXTURE_WIDTH;
/// Edits between autosaves while painting.
const AUTOSAVE_EVERY: usize = 5;
/// A pause after which unsaved edits are autosaved (short: a crash soon
/// after a few strokes should not lose them).
const AUTOSAVE_PAUSE: Duration = Duration::from_secs(3);
/// A pause after which the texel updates appended to the textures' slot
/// are folded into it (folding copies the whole texture, tens of ms for
/// a large one: not between one gesture and the next).
const FOLD_PAUSE: Duration = Duration::from_millis(500);
/// Appended updates of this many times the textures' size are folded
/// without waiting for the pause (the memory they hold is bounded; below
/// it, detail brushing at a steady pace is never held up by a fold).
const FOLD_WITHOUT_PAUSE: usize = 2;

const SLOT_HELLO: usize = 0;
const SLOT_MESH: usize = 1;
const SLOT_TEXTURES: usize = 2;
const SLOT_STATUS: usize = 3;
const SLOT_SCATTER: usize = 4;
/// While a stroke goes on, the scatter's points are sent at most this
/// often (a million points is 12 MB a frame); its end sends them at once.
const SCATTER_EVERY: Duration = Duration::from_millis(60);

/// The paint app: the session and its GPU copy.
pub(crate) struct Worker {
    doc: Document,
    session: PaintSession,
    mip: MipMap,
    gpu: GpuLayout,
    export_dir: PathBuf,
    autosave: Option<PathBuf>,
    /// Autosaves of earlier sessions, for the page to offer.
    earlier_autosaves: Vec<PathBuf>,
    /// Edits since the last autosave.
    unsaved: usize,
    /// Texel updates appended to the textures' slot since it was last
    /// folded.
    appended: usize,
    /// Their bytes (folded at once when they outgrow the textures
    /// [`FOLD_WITHOUT_PAUSE`] times).
    appended_bytes: usize,
    /// A stroke is being painted (its updates are folded after it ends:
    /// folding copies the whole texture).
    stroke_open: bool,
    /// The seqs answered since the last status.
    answered: Vec<u64>,
    /// When the last request was handled (the autosave waits for a
    /// pause).
    last_request: Instant,
    /// The scatter panel, when the page asked for points.
    scatter: Option<ScatterState>,
    /// Points changed since they were last sent.
    scatter_dirty: bool,
    /// When they were last sent.
    scatter_sent: Instant,
}

impl Worker {
    /// The session over `doc` with `log` replayed, and its GPU layout.
    pub(crate) fn new(
        doc: Document,
        log: Option<&[Edit]>,
        options: Options,
    ) -> Result<Self, String> {
        let session = super::open_session(&doc, log.unwrap_or(&[]), options.history)?;
        let mip = MipMap::new(session.colors().clone());
        // Spare rows for the detail brush: its first raise then writes
        // into them instead of packing (and sending) everything again.
        let gpu = GpuLayout::with_spare_rows(&mip, TEXTURE_WIDTH).map_err(|e| e.to_string())?;
        // Replayed edits are not saved anywhere yet: the autosave keeps them.
        let unsaved = log.map_or(0, <[Edit]>::len);
        Ok(Self {
            doc,
            session,
            mip,
            gpu,
            export_dir: options.export_dir,
            autosave: options.autosave,
            earlier_autosaves: options.earlier_autosaves,
            unsaved,
            appended: 0,
            appended_bytes: 0,
            stroke_open: false,
            answered: Vec::new(),
            last_request: Instant::now(),
            scatter: None,
            scatter_dirty: false,
            scatter_sent: Instant::now(),
        })
    }

    fn frame(kind: u8, a: u32, b: u32, payload: &[u8]) -> Out {
        Self::frame_with(kind, a, b, payload.len(), |f| f.extend_from_slice(payload))
    }

    /// A frame whose payload `fill` appends (`len` bytes, as room to
    /// reserve) behind the header: a payload of megabytes is written once,
    /// not copied again behind a header.
    fn frame_with(kind: u8, a: u32, b: u32, len: usize, fill: impl FnOnce(&mut Vec<u8>)) -> Out {
        let header = Header {
            magic: *MAGIC,
            version: VERSION,
            kind,
            flags: 0,
            tag: 0,
            a,
            b,
        };
        let mut frame = Vec::with_capacity(HEADER + len);
        frame.extend_from_slice(&header.bytes());
        fill(&mut frame);
        Out::Binary(Bytes::from(frame))
    }

    fn hello(&self) -> Out {
        let (lo, hi) = self.doc.bounds();
        let mut channels = vec!["color".to_string()];
        channels.extend(self.doc.scalars.iter().cloned());
        Out::Text(
            json!({
                "type": "hello", "app": "paint", "protocol": VERSION,
                "bounds": [lo.to_array(), hi.to_array()],
                "channels": channels, "base": self.doc.base,
                "mirror_x": self.doc.mirror_x(),
                "faces": self.doc.surface.faces.len(),
                "area": self.doc.area(),
                "autosave": self.autosave.as_ref().map(|p| p.display().to_string()),
                "earlier_autosaves": self.earlier_autosaves.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
                "max_level": mesh_colors::MAX_LEVEL,
            })
            .to_string(),
        )
    }

    /// The welded surface: positions, then triangles (the page expands
    /// them to unindexed corners, face id = vertex id / 3).
    fn mesh(&self) -> Out {
        let s = &self.doc.surface;
        let mut payload = Vec::with_capacity(s.positions.len() * 12 + s.faces.len() * 12);
        put_f32(&mut payload, s.positions.iter().flat_map(|p| p.to_array()));
        put_u32(&mut payload, s.faces.iter().flatten().copied());
        Self::frame(1, s.positions.len() as u32, s.faces.len() as u32, &payload)
    }

    fn textures(&self) -> Vec<Out> {
        let w = self.gpu.width();
        let (faces, samples) = (self.gpu.face_texels(), self.gpu.sample_texels());
        let used = &samples[..(self.gpu.used_sample_rows() * w * 4) as usize];
        vec![
            Self::frame_with(2, w, self.gpu.face_height(), 4 * faces.len(), |f| {
                put_slice(f, faces);
            }),
            // The rows in use; the page allocates all `sample_height`
            // (the rest are zeros, spare room for resolution changes).
            Self::frame_with(3, w, self.gpu.sample_height(), 4 * used.len(), |f| {
                put_slice(f, used);
            }),
        ]
    }

    /// The sample texels of `rects`, as absolute values.
    fn sample_rects(&self, rects: &[TexelRect]) -> Out {
        let w = self.gpu.width();
        Self::frame_with(4, rects.len() as u32, w, rect_bytes(rects), |f| {
            put_rects(f, w as usize, rects, self.gpu.sample_texels());
        })
    }

    /// Kind 7: the sample and face-table texels a resolution change
    /// rewrote, as absolute values, in one frame (the page applies both
    /// before it draws again).
    fn layout_rects(&self, changes: &Changes) -> Out {
        let w = self.gpu.width() as usize;
        let (samples, faces) = (&changes.samples, &changes.faces);
        let len = rect_bytes(samples) + rect_bytes(faces);
        Self::frame_with(7, samples.len() as u32, faces.len() as u32, len, |f| {
            put_rects(f, w, samples, self.gpu.sample_texels());
            put_rects(f, w, faces, self.gpu.face_texels());
        })
    }

    /// Sends `frame` and appends it to the textures' slot.
    fn append(&mut self, out: &Outbox, frame: Out) {
        if let Out::Binary(b) = &frame {
            self.appended_bytes += b.len();
        }
        out.append(SLOT_TEXTURES, frame);
        self.appended += 1;
    }

    fn status(&mut self) -> Out {
        let h = self.session.history();
        let colors = self.session.colors();
        let finest = (0..colors.face_count())
            .filter_map(|f| colors.face_level(f))
            .max()
            .unwrap_or(0);
        let steps: Vec<&str> = h
            .steps()
            .map(|s| match s {
                mesh_colors::undo::Step::Paint(_) => "paint",
                mesh_colors::undo::Step::Resolution(_) => "detail",
            })
            .collect();
        let seqs = std::mem::take(&mut self.answered);
        Out::Text(
            json!({
                "type": "status", "seqs": seqs,
                "samples": colors.sample_count(),
                "memory": colors.memory_bytes(),
                "undo_memory": self.session.undo_memory_bytes(),
                "finest_level": finest,
                "undo": h.undo_len(), "redo": h.redo_len(), "history": steps,
                "edits": self.session.log().len(),
                "points": self.scatter.as_ref().map_or(0, |s| s.points().len()),
                "strands": self.scatter.as_ref().and_then(|s| s.strands()).map_or(0, |s| s.len()),
                "scatter_ms": self.scatter.as_ref().map_or(0.0, |s| s.last_ms),
                "scatter": self.scatter.as_ref().map(ScatterState::request),
            })
            .to_string(),
        )
    }

    fn publish_status(&mut self, out: &Outbox) {
        let status = self.status();
        out.publish(SLOT_STATUS, vec![status]);
    }

    /// Sends what `changed` changed: texels, or the whole layout.
    fn upload(&mut self, changed: Changed, out: &Outbox) -> Result<(), String> {
        let colors = self.session.colors();
        match changed {
            Changed::Nothing => {}
            Changed::Samples(list) => {
                if let Some(scatter) = &mut self.scatter {
                    let updated = scatter
                        .samples_changed(&list, colors)
                        .map_err(|(f, m)| format!("{f}: {m}"))?;
                    self.scatter_dirty |= updated == Updated::Points;
                }
                let runs = runs(&list);
                let spans = self.mip.refresh(colors, &runs).map_err(|e| e.to_string())?;
                let changes = self
                    .gpu
                    .refresh(&self.mip, &spans)
                    .map_err(|e| e.to_string())?;
                if !changes.samples.is_empty() {
                    let frame = self.sample_rects(&changes.samples);
                    self.append(out, frame);
                }
            }
            Changed::Layout(faces) => {
                let changes = match self.refresh_layout(&faces) {
                    Ok(changes) => changes,
                    Err(e) => return Err(self.take_back(&faces, &e)),
                };
                if changes.resized {
                    out.publish(SLOT_TEXTURES, self.textures());
                    (self.appended, self.appended_bytes) = (0, 0);
                } else if !changes.is_empty() {
                    let frame = self.layout_rects(&changes);
                    self.append(out, frame);
                }
                if let Some(scatter) = &mut self.scatter {
                    let updated = scatter
                        .layout_changed(&self.doc.surface, self.session.colors(), &self.doc.scalars)
                        .map_err(|(f, m)| format!("{f}: {m}"))?;
                    self.scatter_dirty |= updated == Updated::Points;
                }
            }
        }
        Ok(())
    }

    /// The pyramid and the textures after a resolution change of `faces`.
    fn refresh_layout(&mut self, faces: &[usize]) -> Result<Changes, String> {
        let colors = self.session.colors();
        let spans = self
            .mip
            .refresh_resolutions(colors, faces)
            .map_err(|e| e.to_string())?;
        self.gpu
            .refresh_resolutions(&self.mip, &spans)
            .map_err(|e| e.to_string())
    }

    /// A resolution change the textures cannot hold (`problem`) is taken
    /// back: the session as before it (colours, history, log) and the
    /// pyramid again (the textures refuse a change whole, so they are as
    /// before). Returns the error for the page.
    fn take_back(&mut self, faces: &[usize], problem: &str) -> String {
        let back = self
            .session
            .withdraw()
            .map_err(|e| e.to_string())
            .and_then(|_| {
                let colors = self.session.colors();
                self.mip
                    .refresh_resolutions(colors, faces)
                    .map_err(|e| e.to_string())
            });
        match back {
            Ok(_) => {
                // The edit was counted as unsaved; it is gone.
                self.unsaved = self.unsaved.saturating_sub(1);
                format!("no more detail fits the GPU textures ({problem}); the change was not made")
            }
            Err(e) => format!("{problem}; taking the change back failed too: {e}"),
        }
    }

    /// The session's brush for the page's: the channel by name, the
    /// mirror plane of the mesh (worked out only when a brush is given,
    /// not for every batch of dabs).
    fn brush(
        &self,
        spec: &super::protocol::BrushSpec,
    ) -> Result<mesh_colors::session::Brush, (String, String)> {
        spec.resolve(&self.doc.scalars, self.doc.mirror_x())
            .map_err(|b| (b.field, b.problem))
    }

    fn edit(
        &mut self,
        to: ReplyTo,
        request: Request,
        out: &Outbox,
    ) -> Result<(), (String, String)> {
        // Any request but dabs ends a stroke (the session ends it too).
        self.stroke_open = matches!(request, Request::Begin(_) | Request::Dabs(_));
        let changed = match request {
            Request::Begin(spec) => {
                let brush = self.brush(&spec)?;
                self.session
                    .begin_stroke(brush)
                    .map_err(|e| ("brush".to_string(), e.to_string()))?;
                Changed::Nothing
            }
            Request::Dabs(dabs) => self
                .session
                .add_dabs(&dabs)
                .map_err(|e| ("dabs".to_string(), e.to_string()))?,
            Request::End => {
                self.session.end_stroke();
                self.unsaved += 1;
                Changed::Nothing
            }
            Request::Fill(face, spec) => {
                let brush = self.brush(&spec)?;
                self.unsaved += 1;
                self.session
                    .apply(Edit::Fill { face, brush })
                    .map_err(|e| ("face".to_string(), e.to_string()))?
            }
            Request::Edit(e) => {
                self.unsaved += 1;
                self.session
                    .apply(e)
                    .map_err(|e| ("op".to_string(), e.to_string()))?
            }
            Request::Scatter(spec) => {
                let off = spec.mode == super::scatter::ScatterMode::Off;
                self.scatter = if off {
                    None
                } else {
                    Some(
                        ScatterState::new(
                            spec,
                            &self.doc.surface,
                            self.session.colors(),
                            &self.doc.scalars,
                        )
                        .map_err(|b| (b.field, b.problem))?,
                    )
                };
                self.scatter_dirty = true;
                return Ok(());
            }
            Request::Pick(face, b) => {
                let color = self
                    .session
                    .pick(face, b)
                    .map_err(|e| ("face".to_string(), e.to_string()))?;
                out.reply(
                    to,
                    Out::Text(json!({"type": "pick", "seq": to.seq, "color": color}).to_string()),
                );
                return Ok(());
            }
            Request::Save { name, overwrite } => {
                let path = self.export_dir.join(&name);
                let result = self.save(&path, overwrite);
                self.exported(to, &path, result, out);
                return Ok(());
            }
            Request::Export {
                kind,
                name,
                overwrite,
            } => {
                let path = self.export_dir.join(&name);
                let result = self.export(kind, &path, overwrite);
                self.exported(to, &path, result, out);
                return Ok(());
            }
        };
        self.upload(changed, out).map_err(|e| ("op".to_string(), e))
    }

    /// Answers a save or export: its path, or an error that says whether
    /// the file was in the way (the page then asks to replace it).
    fn exported(&self, to: ReplyTo, path: &Path, result: crate::Result<()>, out: &Outbox) {
        let text = match result {
            Ok(()) => json!({"type": "export", "seq": to.seq, "path": path.display().to_string()})
                .to_string(),
            Err(crate::Error::Exists(p)) => crate::web::json::error_with(
                to.seq,
                "name",
                &format!("{}: the file exists", p.display()),
                &[("exists", json!(true))],
            ),
            Err(e) => crate::web::json::error(to.seq, "name", &e.to_string()),
        };
        out.reply(to, Out::Text(text));
    }

    /// Writes the colours as `.meshcolors`, atomically.
    fn save(&self, path: &Path, overwrite: bool) -> crate::Result<()> {
        let colors = self.session.colors();
        crate::output::write_atomic(path, overwrite, |tmp| {
            mesh_colors::file::save(tmp, colors, None).map_err(crate::Error::from)
        })
    }

    fn export(&self, kind: ExportKind, path: &Path, overwrite: bool) -> crate::Result<()> {
        match kind {
            ExportKind::Session => {
                let v = super::session_file::to_json(&self.doc, self.session.log());
                crate::output::write_atomic(path, overwrite, |tmp| {
                    std::fs::write(tmp, format!("{v:#}\n")).map_err(|source| crate::Error::File {
                        path: tmp.to_path_buf(),
                        source,
                    })
                })
            }
            ExportKind::Glb | ExportKind::Obj => {
                let atlas = mesh_colors::atlas::bake(
                    self.session.colors(),
                    &mesh_colors::atlas::Options::default(),
                )?;
                let (mut baked, _) = crate::colors::atlas_mesh(&self.doc.surface, &atlas, None);
                // Named after the model: Blender lists the object, mesh,
                // material and texture by these names.
                let model = self.doc.model_name();
                for object in &mut baked.objects {
                    object.name.clone_from(&model);
                }
                for material in &mut baked.materials {
                    material.name.clone_from(&model);
                }
                // The scalar channels as textures of their own (GLB), not
                // as the base colour's alpha.
                crate::colors::attach_scalar_channels(&mut baked, &atlas, &self.doc.scalars)?;
                if kind == ExportKind::Glb {
                    crate::output::write_gltf(path, overwrite, |tmp| baked.write(tmp)).map(drop)
                } else {
                    crate::output::write_atomic_files(path, overwrite, |tmp| Ok(baked.write(tmp)?))
                        .map(drop)
                }
            }
            ExportKind::Strands => {
                let curves = self.curves()?;
                let write = |tmp: &Path| trilux_io::curves::write(tmp, &curves);
                if has_extension(path, "glb") {
                    crate::output::write_gltf(path, overwrite, write).map(drop)
                } else {
                    crate::output::write_atomic(path, overwrite, |tmp| Ok(write(tmp)?))
                }
            }
            ExportKind::Points => {
                let cloud = self.point_cloud()?;
                if has_extension(path, "glb") {
                    let points = trilux_io::mesh::gltf::Points::from(&cloud);
                    crate::output::write_gltf(path, overwrite, |tmp| {
                        trilux_io::mesh::gltf::write_points(tmp, &points)
                    })
                    .map(drop)
                } else {
                    crate::output::write_atomic(path, overwrite, |tmp| {
                        Ok(trilux_io::mesh::ply::write(
                            tmp,
                            &cloud,
                            trilux_io::mesh::ply::Format::default(),
                        )?)
                    })
                }
            }
        }
    }

    /// The scatter's points as a point cloud: positions, normals, the
    /// face each lies on, in the surface's frame (its origin restored).
    fn point_cloud(&self) -> crate::Result<trilux_io::mesh::ply::PlyData> {
        let points = self.scatter_points()?;
        Ok(trilux_io::mesh::ply::PlyData {
            positions: points.iter().map(|p| p.position).collect(),
            origin: self.doc.surface.origin,
            normals: Some(points.iter().map(|p| p.normal).collect()),
            face_ids: Some(points.iter().map(|p| p.face).collect()),
            ..Default::default()
        })
    }

    /// Strands from every point of the scatter, as the panel's hair asks.
    fn curves(&self) -> crate::Result<trilux_io::curves::Curves> {
        self.scatter_points()?;
        let scatter = self.scatter.as_ref().ok_or_else(nothing_scattered)?;
        let strands = scatter
            .strands_from(self.session.colors(), usize::MAX, true)
            .map_err(|b| crate::Error::Invalid(format!("{}: {}", b.field, b.problem)))?
            .ok_or_else(|| {
                crate::Error::Invalid("no strands: turn on hair in the scatter panel first".into())
            })?;
        Ok(crate::hair::into_curves(strands, self.doc.surface.origin))
    }

    /// The scatter's points, or an error when the panel has none.
    fn scatter_points(&self) -> crate::Result<&[mesh_sampling::SurfacePoint]> {
        let points = self
            .scatter
            .as_ref()
            .map(|s| s.points())
            .ok_or_else(nothing_scattered)?;
        if points.is_empty() {
            return Err(crate::Error::Invalid(
                "no points to export yet: paint the scatter's channel first".into(),
            ));
        }
        Ok(points)
    }

    /// Writes the autosave when there is one and something to save.
    fn autosave(&mut self) {
        if self.unsaved == 0 {
            return;
        }
        if let Some(path) = self.autosave.clone() {
            match self.save(&path, true) {
                Ok(()) => self.unsaved = 0,
                Err(e) => eprintln!("trilux paint: the autosave failed: {e}"),
            }
        }
    }
}

impl Worker {
    /// Count and blue-noise points are drawn again once a stroke ends (or
    /// after any edit outside one).
    fn follow_stroke_end(&mut self) -> Result<(), (String, String)> {
        if self.stroke_open {
            return Ok(());
        }
        if let Some(scatter) = &mut self.scatter {
            let updated = scatter.stroke_ended(&self.doc.surface, self.session.colors())?;
            self.scatter_dirty |= updated == Updated::Points;
        }
        Ok(())
    }

    /// Publishes the scatter's points and strands when they changed: at
    /// once outside a stroke, at most every [`SCATTER_EVERY`] inside one.
    fn send_scatter(&mut self, out: &Outbox) {
        if !self.scatter_dirty || (self.stroke_open && self.scatter_sent.elapsed() < SCATTER_EVERY)
        {
            return;
        }
        out.publish(SLOT_SCATTER, self.scatter_frames());
        self.scatter_dirty = false;
        self.scatter_sent = Instant::now();
    }

    /// Kind 5, the points' positions; kind 6, the preview strands'
    /// polylines (`a` strands of `b` points). No scatter: no points.
    fn scatter_frames(&self) -> Vec<Out> {
        let Some(scatter) = &self.scatter else {
            return vec![Self::frame(5, 0, 0, &[])];
        };
        let points = scatter.points();
        let mut payload = Vec::with_capacity(points.len() * 12);
        put_f32(
            &mut payload,
            points.iter().flat_map(|p| p.position.to_array()),
        );
        let mut frames = vec![Self::frame(5, points.len() as u32, 0, &payload)];
        if let Some(strands) = scatter.strands() {
            let mut lines = Vec::with_capacity(strands.points.len() * 12);
            put_f32(&mut lines, strands.points.iter().flat_map(|p| p.to_array()));
            frames.push(Self::frame(
                6,
                strands.len() as u32,
                strands.points_per_strand() as u32,
                &lines,
            ));
        }
        frames
    }
}

fn nothing_scattered() -> crate::Error {
    crate::Error::Invalid("nothing is scattered: choose a mode in the scatter panel first".into())
}

/// Whether `path` ends in `.ext` (any case).
fn has_extension(path: &Path, ext: &str) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// Appends each of `rects` of `texels` (a texture `w` texels wide, 4
/// words a texel): `x, y, w, h`, then its rows.
fn put_rects<T: bytemuck::NoUninit + LeWord>(
    payload: &mut Vec<u8>,
    w: usize,
    rects: &[TexelRect],
    texels: &[T],
) {
    for r in rects {
        put_u32(payload, [r.x, r.y, r.width, r.height]);
        for y in r.y..r.y + r.height {
            let start = (y as usize * w + r.x as usize) * 4;
            let row = texels
                .get(start..start + r.width as usize * 4)
                .unwrap_or(&[]);
            put_slice(payload, row);
        }
    }
}

/// The bytes [`put_rects`] writes for `rects`.
fn rect_bytes(rects: &[TexelRect]) -> usize {
    rects
        .iter()
        .map(|r| 16 + 16 * r.width as usize * r.height as usize)
        .sum()
}

/// Sorted, distinct sample indices as runs `(first, count)`.
fn runs(list: &[u32]) -> Vec<(u32, u32)> {
    let mut runs: Vec<(u32, u32)> = Vec::new();
    for &i in list {
        match runs.last_mut() {
            Some((start, n)) if *start + *n == i => *n += 1,
            _ => runs.push((i, 1)),
        }
    }
    runs
}

impl App for Worker {
    const NAME: &'static str = "paint";
    const PAGE: &'static [crate::web::Asset] = PAGE;
    const LIMITS: Limits = LIMITS;
    type Request = Request;

    fn parse(m: &crate::web::Incoming<'_>) -> Result<Request, crate::web::BadField> {
        super::protocol::parse(m)
    }

    fn begin(&mut self, out: &Outbox) {
        out.publish(SLOT_HELLO, vec![self.hello()]);
        out.publish(SLOT_MESH, vec![self.mesh()]);
        out.publish(SLOT_TEXTURES, self.textures());
        self.publish_status(out);
    }

    fn handle(&mut self, first: (ReplyTo, Request), inbox: &mut Inbox<Request>, out: &Outbox) {
        let mut last = first.0;
        let mut next = Some(first);
        // Dabs already waiting are painted before the status goes out.
        while let Some((to, request)) = next {
            if let Err((field, message)) = self.edit(to, request, out) {
                out.error(to, &field, &message);
            }
            self.answered.extend(to.seq);
            last = to;
            next = inbox.try_next();
        }
        if let Err((field, message)) = self.follow_stroke_end() {
            out.error(last, &field, &message);
        }
        self.send_scatter(out);
        self.publish_status(out);
        self.last_request = Instant::now();
        if self.unsaved >= AUTOSAVE_EVERY {
            self.autosave();
        }
    }

    fn idle(&mut self, _cancel: &AtomicBool, out: &Outbox) -> Idle {
        // Points held back during a stroke go out once it pauses.
        if self.scatter_dirty {
            let wait = SCATTER_EVERY.saturating_sub(self.scatter_sent.elapsed());
            if !wait.is_zero() {
                return Idle::WaitAtMost(wait);
            }
            self.send_scatter(out);
        }
        // Fold the texel updates into one face table and one samples
        // frame for pages that connect later (every page has them
        // already), once the requests pause or the updates outgrow the
        // textures.
        let waited = self.last_request.elapsed();
        let mut fold_in = None;
        if self.appended > 0 && !self.stroke_open {
            let whole = 4 * (self.gpu.sample_texels().len() + self.gpu.face_texels().len());
            if waited >= FOLD_PAUSE || self.appended_bytes >= FOLD_WITHOUT_PAUSE * whole {
                out.keep(SLOT_TEXTURES, self.textures());
                (self.appended, self.appended_bytes) = (0, 0);
            } else {
                fold_in = Some(FOLD_PAUSE - waited);
            }
        }
        let autosave_in = if self.unsaved == 0 {
            None
        } else if waited >= AUTOSAVE_PAUSE {
            self.autosave();
            None
        } else {
            Some(AUTOSAVE_PAUSE - waited)
        };
        match fold_in.into_iter().chain(autosave_in).min() {
            Some(wait) => Idle::WaitAtMost(wait),
            None => Idle::Wait,
        }
    }

    fn stop(&mut self, _out: &Outbox) {
        self.session.end_stroke();
        let unsaved = self.unsaved;
        self.autosave();
        // Say where the colours are as the server stops (Ctrl+C).
        if let (Some(path), true) = (&self.autosave, unsaved > 0 && self.unsaved == 0) {
            let edits = if unsaved == 1 { "edit" } else { "edits" };
            eprintln!(
                "trilux paint: {unsaved} unsaved {edits} autosaved to {} (resume with --colors {})",
                path.display(),
                path.display()
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_join_consecutive_indices() {
        assert_eq!(runs(&[1, 2, 3, 7, 9, 10]), vec![(1, 3), (7, 1), (9, 2)]);
        assert!(runs(&[]).is_empty());
    }
}
