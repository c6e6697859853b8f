//! The app that owns the [`Session`] on the web core's thread
//! ([`App`]): it takes requests in order, coalesces the edits waiting,
//! solves coarse first, refines when idle (cancelled by the next
//! request), and sends frames and status to every connected page. A
//! dropped connection does not touch it: a reload continues the same
//! session.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use axum::body::Bytes;
use serde_json::{Value, json};
use tet_diffusion::glam::DVec3;
use tet_diffusion::{Applied, Edit, Light, Session, SolveReport};

use super::protocol::{self, ExportKind, FINAL, LAST, RADIANCE, Request, SURFACE};
use super::{Exporter, session_file};
use crate::web::{App, Asset, BadField, Idle, Inbox, Incoming, Limits, Out, Outbox, ReplyTo, json};

/// The snapshot slots a page that connects is sent, in this order.
const HELLO: usize = 0;
const SURFACES: usize = 1;
const RADIANCES: usize = 2;
const STATUS: usize = 3;

pub(crate) struct Worker {
    pub(crate) session: Session,
    pub(crate) exporter: Box<dyn Exporter>,
    pub(crate) export_dir: PathBuf,
    pub(crate) source: Value,
    /// The exposure's white point, fixed at the start (a camera's
    /// exposure does not follow each edit).
    pub(crate) white: f64,
    /// The environment maps loaded, with their files (for session files).
    pub(crate) envs: session_file::EnvFiles,
}

/// Process CPU time, ms (Linux; 0 elsewhere).
fn cpu_ms() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // Fields after the command name in parentheses; utime and stime are
    // the 14th and 15th fields, in clock ticks (100 per second on Linux).
    let Some(rest) = stat.rsplit_once(')').map(|(_, r)| r) else {
        return 0.0;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) * 10.0
}

impl App for Worker {
    const NAME: &'static str = "view";
    const PAGE: &'static [Asset] = super::PAGE;
    const LIMITS: Limits = super::LIMITS;
    type Request = Request;

    fn parse(m: &Incoming<'_>) -> Result<Request, BadField> {
        protocol::parse_incoming(m)
    }

    fn parse_binary(bytes: &[u8]) -> Result<(u64, Request), BadField> {
        protocol::parse_upload(bytes)
    }

    /// A probe does not cancel the refinement: the page's brush sends one
    /// every 150 ms while it hovers, and a cancelled refinement starts
    /// over, so hovering could starve it. The probe waits for the
    /// refinement instead.
    fn interrupts(request: &Request) -> bool {
        !matches!(request, Request::Probe { .. })
    }

    fn begin(&mut self, out: &Outbox) {
        self.publish_all(out);
    }

    fn handle(&mut self, first: (ReplyTo, Request), inbox: &mut Inbox<Request>, out: &Outbox) {
        self.gather(out, first, inbox);
    }

    fn idle(&mut self, cancel: &AtomicBool, out: &Outbox) -> Idle {
        if !self.session.needs_refinement() {
            return Idle::Wait;
        }
        self.refine(out, cancel);
        Idle::Busy
    }
}

/// An error for the page that asked `to`; with no asker (a failed
/// refinement) for every page, with seq 0.
fn error(out: &Outbox, to: Option<ReplyTo>, field: &str, message: &str) {
    match to {
        Some(to) => out.error(to, field, message),
        None => out.broadcast(Out::Text(json::error(Some(0), field, message))),
    }
}

impl Worker {
    fn refine(&mut self, out: &Outbox, cancel: &AtomicBool) {
        let t = Instant::now();
        let c = cpu_ms();
        match self.session.refine(cancel) {
            Ok((reports, true)) => {
                self.send_radiance(out, true, 0);
                publish_status(out, self.status(&[], "refine", &reports, t, c, false));
            }
            Ok((_, false)) => {}
            Err(e) => {
                error(out, None, "(solve)", &e.to_string());
                // Keep the coarse result; nothing more to refine until the
                // next edit.
                self.session.skip_refinement();
            }
        }
    }

    /// Handles `first` and, if it is an edit, every edit already waiting
    /// behind it (coalesced by the session); a non-edit request stops
    /// the gathering and is handled after them.
    fn gather(&mut self, out: &Outbox, first: (ReplyTo, Request), inbox: &mut Inbox<Request>) {
        let mut askers = Vec::new();
        let mut after = None;
        let mut request = Some(first);
        while let Some((to, r)) = request.take() {
            match r {
                Request::Edit(mut edit, gesture) => {
                    // The page's lights are the directional and point ones:
                    // the environment map loaded stays.
                    if let Edit::Lights(l) = &mut edit
                        && !l.iter().any(|l| matches!(l, Light::Environment(_)))
                        && let Some(env) = self.environment_now()
                    {
                        l.push(Light::Environment(env));
                    }
                    match self.session.push_in(edit, gesture) {
                        Ok(()) => askers.push(to),
                        Err(e) => error(out, Some(to), &field_of(&e), &e.to_string()),
                    }
                    request = inbox.try_next();
                }
                other => after = Some((to, other)),
            }
        }
        if !askers.is_empty() || self.session.pending() > 0 {
            self.apply(out, &askers);
        }
        if let Some((to, r)) = after {
            self.other(out, to, r);
        }
    }

    /// Applies the edits waiting, which `askers` sent (an error goes to
    /// the last of them).
    fn apply(&mut self, out: &Outbox, askers: &[ReplyTo]) {
        let t = Instant::now();
        let c = cpu_ms();
        let mut reports: Vec<SolveReport> = Vec::new();
        let mut name = "edit";
        let seqs: Vec<u64> = askers.iter().map(|a| a.seq.unwrap_or(0)).collect();
        let last = seqs.last().copied().unwrap_or(0);
        // A cut's new surface goes out before its solve (a new hierarchy
        // and the coarse solve take longer than the cut), coloured by the
        // φ carried over until the solved radiance follows.
        let show_new_surface = |s: &Session, edit: &Edit| {
            if edit.changes_topology() {
                publish_surfaces(out, s);
                publish_radiance(out, s, false, last);
            }
        };
        while let Some(result) = self.session.apply_pending_with(show_new_surface) {
            match result {
                Ok(Applied { edit, solves, .. }) => {
                    name = edit.name();
                    reports.extend(solves);
                }
                Err(e) => {
                    error(out, askers.last().copied(), &field_of(&e), &e.to_string());
                }
            }
        }
        self.send_radiance(out, !self.session.needs_refinement(), last);
        let coarse = self.session.needs_refinement();
        publish_status(out, self.status(&seqs, name, &reports, t, c, coarse));
    }

    fn other(&mut self, out: &Outbox, to: ReplyTo, r: Request) {
        let seq = to.seq.unwrap_or(0);
        let t = Instant::now();
        let c = cpu_ms();
        match r {
            Request::Edit(..) => {}
            // The page got the state when it connected (the snapshot):
            // the answer is a status for its seq, to it alone.
            Request::Hello => {
                let status = self.status(&[seq], "hello", &[], t, c, false);
                out.reply(to, Out::Text(status));
            }
            Request::Undo | Request::Redo => {
                let undo = matches!(r, Request::Undo);
                let result = if undo {
                    self.session.undo()
                } else {
                    self.session.redo()
                };
                match result {
                    Ok(Some(edit)) => {
                        if edit.changes_topology() {
                            publish_surfaces(out, &self.session);
                        }
                        self.send_radiance(out, true, seq);
                        let name = if undo { "undo" } else { "redo" };
                        publish_status(out, self.status(&[seq], name, &[], t, c, false));
                    }
                    Ok(None) => error(
                        out,
                        Some(to),
                        "op",
                        if undo {
                            "nothing to undo"
                        } else {
                            "nothing to redo"
                        },
                    ),
                    Err(e) => error(out, Some(to), "op", &e.to_string()),
                }
            }
            Request::Probe { piece, point } => self.probe(out, to, piece, point),
            Request::Environment { hdr } => self.environment(out, to, &hdr),
            Request::Export {
                kind,
                name,
                size,
                overwrite,
                view,
            } => {
                let path = self.export_dir.join(&name);
                // A file in the way is found before writing, by the files
                // the kind writes (a tet export's .ele too), so that the
                // page asks whether to replace it: the command line's
                // "pass --force" means nothing there.
                let taken = kind.files(&path).into_iter().find(|f| f.exists());
                let result = match (taken, overwrite) {
                    (Some(file), false) => Err(Refused::Exists(file)),
                    _ => self
                        .export(kind, &path, size, view, overwrite)
                        .map_err(Refused::Failed),
                };
                match result {
                    Ok(()) => out.reply(to, Out::Text(
                        json!({"type": "export", "seq": seq, "path": path.display().to_string()})
                            .to_string(),
                    )),
                    Err(refused) => {
                        let (message, exists) = match refused {
                            Refused::Exists(file) => {
                                (format!("{}: the file exists", file.display()), true)
                            }
                            Refused::Failed(e) => (e, false),
                        };
                        let extra = [("exists", json!(exists))];
                        let e = json::error_with(to.seq, "name", &message, &extra);
                        out.reply(to, Out::Text(e));
                    }
                }
            }
        }
    }

    /// Writes the export `kind` to `path`.
    fn export(
        &self,
        kind: ExportKind,
        path: &std::path::Path,
        size: u32,
        view: Option<DVec3>,
        overwrite: bool,
    ) -> Result<(), String> {
        match kind {
            ExportKind::Session => {
                let log = self.session.log();
                session_file::write(path, &self.source, &log, &self.envs, view, overwrite)
            }
            ExportKind::Glb => write_glb(&self.session, path, size, view, overwrite),
            _ => self
                .exporter
                .export(&self.session, kind, path, size, view, overwrite),
        }
    }

    /// The environment map lighting the object now, if any.
    fn environment_now(&self) -> Option<Arc<tet_diffusion::Environment>> {
        self.session.pieces()[0]
            .lights()
            .into_iter()
            .find_map(|l| match l {
                Light::Environment(e) => Some(e),
                _ => None,
            })
    }

    /// Lights the object by the uploaded `.hdr` (kept beside the exports
    /// under a name from its content, for session files), or without an
    /// environment map when `hdr` is empty; the other lights stay.
    fn environment(&mut self, out: &Outbox, to: ReplyTo, hdr: &[u8]) {
        let off = self.session.offsets()[0];
        let mut lights: Vec<Light> = self.session.pieces()[0]
            .lights()
            .into_iter()
            .filter_map(|l| match l {
                Light::Environment(_) => None,
                Light::Point {
                    position,
                    intensity,
                } => Some(Light::Point {
                    position: position + off,
                    intensity,
                }),
                other => Some(other),
            })
            .collect();
        if !hdr.is_empty() {
            match self.load_environment(hdr) {
                Ok(env) => lights.push(Light::Environment(env)),
                Err(e) => return error(out, Some(to), "(upload)", &e),
            }
        }
        match self.session.push(Edit::Lights(lights)) {
            Ok(()) => self.apply(out, &[to]),
            Err(e) => error(out, Some(to), "(upload)", &e.to_string()),
        }
    }

    fn load_environment(&mut self, hdr: &[u8]) -> Result<Arc<tet_diffusion::Environment>, String> {
        // FNV-1a of the bytes: the same file gets the same name.
        let hash = hdr.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        });
        let name = format!("env-{hash:016x}.hdr");
        if let Some((e, _)) = self.envs.iter().find(|(_, f)| *f == name) {
            return Ok(e.clone());
        }
        let env = session_file::environment(hdr, &name)?;
        let path = self.export_dir.join(&name);
        if !path.exists() {
            crate::output::write_atomic(&path, false, |tmp| {
                std::fs::write(tmp, hdr).map_err(|source| crate::Error::File {
                    path: tmp.to_path_buf(),
                    source,
                })
            })
            .map_err(|e| e.to_string())?;
        }
        self.envs.push((env.clone(), name));
        Ok(env)
    }

    fn probe(&self, out: &Outbox, to: ReplyTo, piece: usize, point: DVec3) {
        let Some(o) = self.session.pieces().get(piece) else {
            return error(out, Some(to), "piece", "no such piece");
        };
        let local = point - self.session.offsets()[piece];
        let m = o.mesh();
        let Some((k, &v)) = m.boundary_vertices().iter().enumerate().min_by(|a, b| {
            let da = m.positions()[*a.1 as usize].distance_squared(local);
            let db = m.positions()[*b.1 as usize].distance_squared(local);
            da.total_cmp(&db)
        }) else {
            return error(out, Some(to), "piece", "the piece has no surface");
        };
        let radiance = o.radiance(None)[k];
        // The medium of a tet around the vertex, by name when measured.
        let t = m.vertex_tets(v as usize).first().copied().unwrap_or(0) as usize;
        let medium = o.medium(t).copied();
        let name = medium.and_then(|md| {
            tet_diffusion::MEASURED
                .iter()
                .find(|(n, _, _)| tet_diffusion::Medium::measured(n).ok() == Some(md))
                .map(|(n, _, _)| n.to_string())
        });
        out.reply(
            to,
            Out::Text(
                json!({
                    "type": "probe", "seq": to.seq, "piece": piece, "vertex": v,
                    "material": name.unwrap_or_else(|| "mixed".into()),
                    "sigma_a": medium.map(|m| m.sigma_a),
                    "sigma_s_prime": medium.map(|m| m.sigma_s_prime),
                    "radiance": radiance,
                })
                .to_string(),
            ),
        );
    }

    fn hello(&self) -> String {
        let (lo, hi) = self.bounds();
        json!({
            "type": "hello",
            "app": "view",
            "protocol": protocol::VERSION,
            "eta": self.session.pieces()[0].eta(),
            "unit_mm": self.session.pieces()[0].length_unit_mm(),
            "white": self.white,
            "max_upload": protocol::MAX_UPLOAD,
            "materials": tet_diffusion::MEASURED.iter().map(|m| m.0).collect::<Vec<_>>(),
            "bounds": [lo.to_array(), hi.to_array()],
            "lights": lights_json(&self.session, &self.envs),
            "source": self.source,
        })
        .to_string()
    }

    fn bounds(&self) -> (DVec3, DVec3) {
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        for (o, off) in self.session.pieces().iter().zip(self.session.offsets()) {
            for &p in o.mesh().positions() {
                lo = lo.min(p + *off);
                hi = hi.max(p + *off);
            }
        }
        (lo, hi)
    }

    /// Everything a page needs, into the snapshot's slots.
    fn publish_all(&mut self, out: &Outbox) {
        out.publish(HELLO, vec![Out::Text(self.hello())]);
        publish_surfaces(out, &self.session);
        self.send_radiance(out, !self.session.needs_refinement(), 0);
        publish_status(
            out,
            self.status(&[], "hello", &[], Instant::now(), cpu_ms(), false),
        );
    }

    fn send_radiance(&mut self, out: &Outbox, refined: bool, seq: u64) {
        publish_radiance(out, &self.session, refined, seq);
    }

    /// The status: `seqs` answered by `edit` (with its solve `reports`,
    /// timed from `start` and `cpu_start`), the session's counts, history
    /// and memory.
    fn status(
        &self,
        seqs: &[u64],
        edit: &str,
        reports: &[SolveReport],
        start: Instant,
        cpu_start: f64,
        coarse: bool,
    ) -> String {
        let s = &self.session;
        let (done, redo) = s.history();
        let memory = s.undo_memory();
        json!({
            "type": "status",
            "seqs": seqs,
            "edit": edit,
            "coarse": coarse,
            "wall_ms": start.elapsed().as_secs_f64() * 1e3,
            "cpu_ms": cpu_ms() - cpu_start,
            "solves": reports.iter().map(|r| json!({
                "levels": r.levels,
                "iterations": r.channels.map(|c| c.iterations),
                "residual": r.channels.map(|c| if c.residual.is_finite() { c.residual } else { -1.0 }),
                "hierarchy_built": r.hierarchy_built,
                "hierarchy_ms": r.hierarchy_ms,
                "coarse_level": r.coarse_level,
                "solve_ms": r.solve_ms,
                "solver": r.choice.solver.to_string(),
            })).collect::<Vec<_>>(),
            "pieces": s.pieces().len(),
            "offsets": s.offsets().iter().map(|o| o.to_array()).collect::<Vec<_>>(),
            "tets": s.pieces().iter().map(|o| o.mesh().tets().len()).collect::<Vec<_>>(),
            "surface_vertices": s.pieces().iter().map(|o| o.mesh().boundary_vertices().len()).collect::<Vec<_>>(),
            "history": {"done": done, "redo": redo},
            "undo_bytes": memory.undo_bytes,
            "object_bytes": memory.object_bytes,
            "undo_parts": {"media": memory.media_bytes, "phi": memory.phi_bytes,
                           "hierarchy": memory.hierarchy_bytes, "checkpoints": memory.checkpoint_bytes},
            "hierarchy_builds": s.pieces().iter().map(|o| o.hierarchy_builds()).collect::<Vec<_>>(),
            "lights": lights_json(s, &self.envs),
        })
        .to_string()
    }
}

/// Why an export was not written.
enum Refused {
    /// A file it would write exists (the page may ask to replace it).
    Exists(PathBuf),
    /// The writer's error.
    Failed(String),
}

/// Sends the status to every page and keeps it for later ones.
fn publish_status(out: &Outbox, status: String) {
    out.publish(STATUS, vec![Out::Text(status)]);
}

/// The export of kind `glb`: the pieces' boundary surfaces with their
/// radiance ([`crate::tet::write_radiance_gltf`]), the vertex colours at
/// the exposure of the PNG the page would export now (`size` pixels,
/// seen from `view`).
fn write_glb(
    session: &Session,
    path: &std::path::Path,
    size: u32,
    view: Option<DVec3>,
    overwrite: bool,
) -> Result<(), String> {
    // A file in the way is refused before the picture is drawn.
    crate::output::check_new(path, overwrite).map_err(|e| e.to_string())?;
    let picture = crate::tet::render_session(session, size, view.map(|v| v.as_vec3()));
    let white = crate::tet::exposure_white(&picture);
    crate::tet::write_radiance_gltf(path, session.pieces(), white, overwrite)
        .map(drop)
        .map_err(|e| e.to_string())
}

/// Sends each piece's boundary surface (positions, normals, triangles)
/// and keeps the frames for pages that connect later.
fn publish_surfaces(out: &Outbox, session: &Session) {
    let frames = piece_frames(session, |p, o, last| {
        let m = o.mesh();
        let bv = m.boundary_vertices();
        let mut payload = Vec::with_capacity(bv.len() * 24 + m.boundary().len() * 12);
        protocol::put_f32(
            &mut payload,
            bv.iter()
                .flat_map(|&v| m.positions()[v as usize].as_vec3().to_array()),
        );
        protocol::put_f32(
            &mut payload,
            bv.iter()
                .flat_map(|&v| m.vertex_normals()[v as usize].as_vec3().to_array()),
        );
        protocol::put_u32(
            &mut payload,
            crate::tet::boundary_triangles(m).into_iter().flatten(),
        );
        protocol::frame(
            SURFACE,
            last,
            p as u8,
            bv.len() as u32,
            m.boundary().len() as u32,
            &payload,
        )
    });
    out.publish(SURFACES, frames);
}

/// Sends each piece's radiance per boundary vertex, tagged with the edit
/// `seq` and whether it is refined, and keeps the frames.
fn publish_radiance(out: &Outbox, session: &Session, refined: bool, seq: u64) {
    let frames = piece_frames(session, |p, o, last| {
        let l = o.radiance(None);
        let mut payload = Vec::with_capacity(l.len() * 12);
        protocol::put_f32(&mut payload, l.iter().flat_map(|c| c.map(|x| x as f32)));
        let flags = if refined { FINAL } else { 0 } | last;
        protocol::frame(
            RADIANCE,
            flags,
            p as u8,
            l.len() as u32,
            seq as u32,
            &payload,
        )
    });
    out.publish(RADIANCES, frames);
}

/// One frame per piece, made by `frame(piece index, piece, flag)`, where
/// the flag is [`LAST`] for the last piece and 0 before it.
fn piece_frames(
    session: &Session,
    frame: impl Fn(usize, &tet_diffusion::Object, u8) -> Vec<u8>,
) -> Vec<Out> {
    let n = session.pieces().len();
    session
        .pieces()
        .iter()
        .enumerate()
        .map(|(p, o)| {
            let flag = if p + 1 == n { LAST } else { 0 };
            Out::Binary(Bytes::from(frame(p, o, flag)))
        })
        .collect()
}

/// The field an edit's error names: the argument for a bad one, else the
/// edit itself (`op`).
fn field_of(e: &tet_diffusion::Error) -> String {
    match e {
        tet_diffusion::Error::BadArgument { what, .. } => what.clone(),
        _ => "op".into(),
    }
}

/// The lights of the first piece, display frame, as the page sends them
/// (an environment map by its file).
fn lights_json(s: &Session, envs: &session_file::EnvFiles) -> Value {
    let off = s.offsets()[0];
    Value::Array(
        s.pieces()[0]
            .lights()
            .iter()
            .map(|l| match l {
                Light::Directional {
                    to_light,
                    irradiance,
                } => json!({"kind": "dir", "dir": to_light.to_array(), "rgb": irradiance}),
                Light::Point {
                    position,
                    intensity,
                } => {
                    json!({"kind": "point", "pos": (*position + off).to_array(), "rgb": intensity})
                }
                Light::Environment(e) => {
                    let file = envs.iter().find(|(x, _)| Arc::ptr_eq(x, e));
                    json!({"kind": "env", "file": file.map(|(_, f)| f.as_str())})
                }
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probes_do_not_interrupt_the_refinement_and_edits_do() {
        let probe = Request::Probe {
            piece: 0,
            point: DVec3::ZERO,
        };
        assert!(!Worker::interrupts(&probe));
        assert!(Worker::interrupts(&Request::Undo));
        let edit = Request::Edit(Edit::Recombine { a: 0, b: 1 }, None);
        assert!(Worker::interrupts(&edit));
    }
}
