//! The interactive session of TransCut (Sec. 5 and the paper's title:
//! *interactive* cutouts): one or more [`Object`]s (pieces, after a
//! fracture), an edit log with undo and redo, and progressive solves —
//! the model behind `trilux view`, `trilux diffuse --session` and Python.
//!
//! - Edits are queued by [`Session::push`] (checked at once, so a bad one
//!   never reaches the object) and applied by [`Session::apply_pending`],
//!   which coalesces what waits: consecutive light changes and piece moves
//!   keep the last, consecutive paint dabs are all painted and solved once.
//! - Each applied batch is solved to a loose tolerance first
//!   ([`SessionOptions::coarse_tolerance`]: a picture within a few
//!   iterations), then [`Session::refine`] solves it to the objects'
//!   tolerance unless new input cancels it. An interrupted refinement puts
//!   the coarse `φ` back, so `φ` after every edit is a function of the
//!   log alone: a saved log ([`Session::log`]) replays bit-identically
//!   ([`Session::replay`]) on any number of threads.
//! - The solver's hierarchy is kept across paint, light, material and move
//!   edits (see [`Object::hierarchy_builds`]); only cut, fracture and
//!   recombine build a new one.
//! - Undo keeps small deltas: a paint keeps the changed tets' previous
//!   media (their rows are re-assembled from them, exactly), a light
//!   change the previous lights, a move the previous offset, and each of
//!   them the `φ` before it (`3 × 8` bytes per vertex) so that undo
//!   restores `φ` bit for bit without a solve. Cut, fracture and
//!   recombine keep a checkpoint (the pieces before). The deltas share a
//!   budget ([`SessionOptions::undo_budget_bytes`]): past it, the oldest
//!   `φ` copies are dropped first (undoing those edits then re-solves, to
//!   the tolerance rather than bit for bit), then the oldest entries.

use std::collections::VecDeque;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use glam::{DAffine3, DVec3};

use crate::error::finite_vec;
use crate::{Budget, Cut, Error, Light, Medium, Object, SolveReport, Stroke};

/// One edit of a session. Points and directions are in the display frame
/// (the pieces moved by their offsets), mesh units.
#[derive(Debug, Clone)]
pub enum Edit {
    /// Paint dabs (brush stamps along a stroke), all painted, then one
    /// solve.
    Paint(Vec<Stroke>),
    /// Replaces the lights of every piece.
    Lights(Vec<Light>),
    /// Gives every tetrahedron of every piece one medium.
    Material(Medium),
    /// Cuts every piece the cut reaches (a piece it removes entirely is
    /// dropped).
    Cut(Cut),
    /// Breaks piece `piece` in two along a plane.
    Fracture {
        /// The piece (index into [`Session::pieces`]).
        piece: usize,
        /// A point of the plane.
        point: DVec3,
        /// The plane's normal; the second piece is on its side.
        normal: DVec3,
    },
    /// Moves piece `piece` to `offset` (a translation of its display
    /// frame; the physics stays in the mesh's own frame).
    Move {
        /// The piece.
        piece: usize,
        /// Its new offset, mesh units.
        offset: DVec3,
    },
    /// Merges pieces `a` and `b`, the two pieces of one fracture, back
    /// into the object they came from.
    Recombine {
        /// One piece.
        a: usize,
        /// The other.
        b: usize,
    },
}

impl Edit {
    /// A short name ("paint", "lights", …).
    pub fn name(&self) -> &'static str {
        match self {
            Self::Paint(_) => "paint",
            Self::Lights(_) => "lights",
            Self::Material(_) => "material",
            Self::Cut(_) => "cut",
            Self::Fracture { .. } => "fracture",
            Self::Move { .. } => "move",
            Self::Recombine { .. } => "recombine",
        }
    }

    /// Whether it changes the mesh (and so keeps a checkpoint and builds
    /// a new hierarchy).
    pub fn changes_topology(&self) -> bool {
        matches!(
            self,
            Self::Cut(_) | Self::Fracture { .. } | Self::Recombine { .. }
        )
    }

    /// Checks the values that do not depend on the session.
    ///
    /// # Errors
    /// [`Error::BadArgument`] naming the value.
    pub fn check(&self) -> Result<(), Error> {
        match self {
            Self::Paint(dabs) => {
                if dabs.is_empty() {
                    return Err(Error::BadArgument {
                        what: "the number of paint dabs".into(),
                        value: 0.0,
                        need: "a paint edit needs at least one dab",
                    });
                }
                dabs.iter().try_for_each(Stroke::check)
            }
            Self::Lights(lights) => lights.iter().try_for_each(Light::check),
            Self::Material(m) => m.check("the material"),
            Self::Cut(c) => c.check(),
            Self::Fracture { point, normal, .. } => {
                finite_vec("the fracture plane's point", *point)?;
                finite_vec("the fracture plane's normal", *normal)?;
                if normal.length_squared() == 0.0 {
                    return Err(Error::BadArgument {
                        what: "the length of the fracture plane's normal".into(),
                        value: 0.0,
                        need: "it must be non-zero",
                    });
                }
                Ok(())
            }
            Self::Move { offset, .. } => finite_vec("the piece's offset", *offset).map(|_| ()),
            Self::Recombine { a, b } if a == b => Err(Error::BadArgument {
                what: "the second piece to recombine".into(),
                value: *b as f64,
                need: "it must differ from the first",
            }),
            Self::Recombine { .. } => Ok(()),
        }
    }
}

/// An applied edit as the log keeps it: what was done, and whether its
/// solve was refined to the full tolerance (or stopped at the coarse
/// result because new input came first).
#[derive(Debug, Clone)]
pub struct Logged {
    /// The edit (coalesced).
    pub edit: Edit,
    /// Whether [`Session::refine`] finished for it.
    pub refined: bool,
}

/// A session's log: enough, with the object it started from, to rebuild
/// it exactly ([`Session::replay`]).
#[derive(Debug, Clone, Default)]
pub struct Log {
    /// Whether the first solve (before any edit) was refined.
    pub refined_initially: bool,
    /// The applied edits, oldest first.
    pub edits: Vec<Logged>,
}

/// How a session solves and how much undo it keeps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SessionOptions {
    /// Relative residual of the first result after an edit (10⁻²: with
    /// the V-cycle, a few iterations).
    pub coarse_tolerance: f64,
    /// How cuts cut (see [`Object::cut`]): exact by default, or the
    /// paper's relaxation.
    pub cut_method: crate::CutMethod,
    /// Bytes the undo deltas may hold together.
    pub undo_budget_bytes: usize,
}

impl Default for SessionOptions {
    /// 10⁻², exact cuts, 512 MiB of undo.
    fn default() -> Self {
        Self {
            coarse_tolerance: 1e-2,
            cut_method: crate::CutMethod::Exact,
            undo_budget_bytes: 512 << 20,
        }
    }
}

/// What undoing an entry needs (and, after an undo, what redoing it
/// needs: the same slot holds the other state).
#[derive(Debug, Clone)]
enum Delta {
    /// Paint, lights, material or a move: values only.
    Values {
        /// Per piece, the changed tets and their previous media.
        media: Vec<Vec<(u32, Medium)>>,
        /// The lights before (per piece), for a light edit.
        lights: Option<Vec<Vec<Light>>>,
        /// The offsets before, for a move.
        offsets: Option<Vec<DVec3>>,
        /// `φ` of each piece in the other state, unless dropped for the
        /// budget.
        phi: Option<Vec<[Vec<f64>; 3]>>,
    },
    /// Cut, fracture, recombine: the pieces and offsets in the other
    /// state.
    Checkpoint(Vec<Object>, Vec<DVec3>),
}

impl Delta {
    fn bytes(&self) -> usize {
        match self {
            Delta::Values {
                media, lights, phi, ..
            } => {
                let m: usize = media
                    .iter()
                    .map(|v| v.len() * std::mem::size_of::<(u32, Medium)>())
                    .sum();
                let l = lights.as_ref().map_or(0, |l| {
                    l.iter()
                        .map(|v| v.len() * std::mem::size_of::<Light>())
                        .sum()
                });
                let p: usize = phi
                    .as_ref()
                    .map_or(0, |p| p.iter().map(|c| 3 * 8 * c[0].len()).sum());
                m + l + p
            }
            Delta::Checkpoint(pieces, _) => pieces.iter().map(Object::memory_bytes).sum(),
        }
    }
}

#[derive(Debug, Clone)]
struct Entry {
    logged: Logged,
    delta: Delta,
}

/// What [`Session::apply_pending`] or [`Session::refine`] did.
#[derive(Debug, Clone)]
pub struct Applied {
    /// The edit applied (coalesced from this many pushed edits).
    pub edit: Edit,
    /// Pushed edits it coalesced.
    pub coalesced: usize,
    /// The solve of each piece solved (pieces the edit did not touch are
    /// not solved).
    pub solves: Vec<SolveReport>,
    /// Wall time of the edit and its solve, ms.
    pub wall_ms: f64,
    /// Whether the mesh changed (the page needs the new surface).
    pub topology_changed: bool,
}

/// An interactive TransCut session (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct Session {
    pieces: Vec<Object>,
    offsets: Vec<DVec3>,
    /// Applied edits whose deltas the budget dropped (they cannot be
    /// undone, but stay in the log).
    settled: Log,
    history: Vec<Entry>,
    /// Entries `..cursor` are applied; `cursor..` can be redone.
    cursor: usize,
    pending: VecDeque<Edit>,
    options: SessionOptions,
    /// Whether the last applied entry still waits for its refinement.
    unrefined: bool,
}

impl Session {
    /// A session on `object` (solved to the coarse tolerance at once).
    ///
    /// # Errors
    /// Those of [`Object::solve_monitored`].
    pub fn new(object: Object, options: SessionOptions) -> Result<Self, Error> {
        let mut s = Self {
            pieces: vec![object],
            offsets: vec![DVec3::ZERO],
            settled: Log::default(),
            history: Vec::new(),
            cursor: 0,
            pending: VecDeque::new(),
            options,
            unrefined: true,
        };
        s.solve_coarse(&[0])?;
        Ok(s)
    }

    /// The pieces (one object until a fracture).
    pub fn pieces(&self) -> &[Object] {
        &self.pieces
    }

    /// Each piece's display offset.
    pub fn offsets(&self) -> &[DVec3] {
        &self.offsets
    }

    /// The options.
    pub fn options(&self) -> &SessionOptions {
        &self.options
    }

    /// Queues an edit after checking its values.
    ///
    /// # Errors
    /// [`Error::BadArgument`] from [`Edit::check`]; the queue is unchanged.
    pub fn push(&mut self, edit: Edit) -> Result<(), Error> {
        edit.check()?;
        self.pending.push_back(edit);
        Ok(())
    }

    /// Edits waiting to be applied.
    pub fn pending(&self) -> usize {
        self.pending.len()
    }

    /// Applies the waiting edits that coalesce with the first one (the
    /// last of consecutive light changes or moves of one piece; all of
    /// consecutive paint dabs), records them as one log entry, and solves
    /// the touched pieces to the coarse tolerance. `None` when nothing
    /// waits.
    ///
    /// # Errors
    /// What the edit's [`Object`] method returns (a cut that removes
    /// everything, a plane that does not split the piece, pieces that do
    /// not recombine, an index past the pieces); the session is then as
    /// before the edit, and the coalesced edits are dropped.
    pub fn apply_pending(&mut self) -> Option<Result<Applied, Error>> {
        let first = self.pending.pop_front()?;
        let mut coalesced = 1;
        let mut edit = first;
        while let Some(next) = self.pending.front() {
            let merged = match (&mut edit, next) {
                (Edit::Paint(a), Edit::Paint(b)) => {
                    a.extend(b.iter().cloned());
                    true
                }
                (Edit::Lights(_), Edit::Lights(_)) => {
                    edit = next.clone();
                    true
                }
                (Edit::Move { piece: p, .. }, Edit::Move { piece: q, .. }) if p == q => {
                    edit = next.clone();
                    true
                }
                _ => false,
            };
            if !merged {
                break;
            }
            self.pending.pop_front();
            coalesced += 1;
        }
        Some(self.apply(edit, coalesced))
    }

    fn apply(&mut self, edit: Edit, coalesced: usize) -> Result<Applied, Error> {
        let start = Instant::now();
        let (delta, touched) = self.perform(&edit)?;
        self.history.truncate(self.cursor);
        self.history.push(Entry {
            logged: Logged {
                edit: edit.clone(),
                refined: false,
            },
            delta,
        });
        self.cursor = self.history.len();
        let solves = self.solve_coarse(&touched)?;
        self.unrefined = true;
        self.enforce_budget();
        Ok(Applied {
            topology_changed: edit.changes_topology(),
            edit,
            coalesced,
            solves,
            wall_ms: start.elapsed().as_secs_f64() * 1e3,
        })
    }

    /// Does `edit` to the pieces; returns the delta that undoes it and
    /// the pieces to solve. On error the pieces are unchanged.
    fn perform(&mut self, edit: &Edit) -> Result<(Delta, Vec<usize>), Error> {
        let n = self.pieces.len();
        let check_piece = |what: &str, p: usize| -> Result<(), Error> {
            if p >= n {
                return Err(Error::BadArgument {
                    what: what.into(),
                    value: p as f64,
                    need: "it must be below the number of pieces",
                });
            }
            Ok(())
        };
        let phi_now = |s: &Self| Some(s.pieces.iter().map(phi_of).collect::<Vec<_>>());
        match edit {
            Edit::Paint(dabs) => {
                let phi = phi_now(self);
                let mut media = vec![Vec::new(); n];
                let mut touched = Vec::new();
                for (p, piece) in self.pieces.iter_mut().enumerate() {
                    for dab in dabs {
                        let local = Stroke {
                            points: dab.points.iter().map(|&x| x - self.offsets[p]).collect(),
                            ..dab.clone()
                        };
                        let (report, previous) = piece.paint_recorded(&local)?;
                        media[p].extend(previous);
                        if report.tets > 0 && !touched.contains(&p) {
                            touched.push(p);
                        }
                    }
                }
                let delta = Delta::Values {
                    media,
                    lights: None,
                    offsets: None,
                    phi,
                };
                Ok((delta, touched))
            }
            Edit::Material(m) => {
                let phi = phi_now(self);
                let mut media = Vec::with_capacity(n);
                for piece in &mut self.pieces {
                    media.push(piece.set_all_media(*m));
                }
                let delta = Delta::Values {
                    media,
                    lights: None,
                    offsets: None,
                    phi,
                };
                Ok((delta, (0..n).collect()))
            }
            Edit::Lights(lights) => {
                let phi = phi_now(self);
                let before: Vec<Vec<Light>> = self.pieces.iter().map(Object::lights).collect();
                for p in 0..n {
                    self.set_piece_lights(p, lights)?;
                }
                let delta = Delta::Values {
                    media: vec![Vec::new(); n],
                    lights: Some(before),
                    offsets: None,
                    phi,
                };
                Ok((delta, (0..n).collect()))
            }
            Edit::Move { piece, offset } => {
                check_piece("the piece to move", *piece)?;
                let phi = phi_now(self);
                let before = self.offsets.clone();
                self.offsets[*piece] = *offset;
                self.pieces[*piece].set_transform(DAffine3::from_translation(*offset));
                // Point lights are fixed in the display frame: the moved
                // piece sees them from elsewhere.
                let lights = self.pieces[*piece].lights();
                let display: Vec<Light> = lights.iter().map(|l| shift(l, before[*piece])).collect();
                self.set_piece_lights(*piece, &display)?;
                let delta = Delta::Values {
                    media: vec![Vec::new(); n],
                    lights: None,
                    offsets: Some(before),
                    phi,
                };
                Ok((delta, vec![*piece]))
            }
            Edit::Cut(cut) => {
                let before = (self.pieces.clone(), self.offsets.clone());
                let mut pieces = Vec::new();
                let mut offsets = Vec::new();
                let mut touched = Vec::new();
                let mut removed_all = 0;
                for (piece, offset) in self.pieces.iter().zip(&self.offsets) {
                    let local = cut_in(cut, *offset);
                    let reached = piece
                        .mesh()
                        .positions()
                        .iter()
                        .any(|&x| local.side(x) > 0.0);
                    if !reached {
                        pieces.push(piece.clone());
                        offsets.push(*offset);
                        continue;
                    }
                    let mut piece = piece.clone();
                    match piece.cut(&local, self.options.cut_method) {
                        Ok(_) => {
                            touched.push(pieces.len());
                            pieces.push(piece);
                            offsets.push(*offset);
                        }
                        Err(Error::CutRemovesEverything { tets }) => removed_all += tets,
                        Err(e) => return Err(e),
                    }
                }
                if pieces.is_empty() {
                    return Err(Error::CutRemovesEverything { tets: removed_all });
                }
                self.pieces = pieces;
                self.offsets = offsets;
                Ok((Delta::Checkpoint(before.0, before.1), touched))
            }
            Edit::Fracture {
                piece,
                point,
                normal,
            } => {
                check_piece("the piece to fracture", *piece)?;
                let offset = self.offsets[*piece];
                let [a, b] = self.pieces[*piece].fracture(*point - offset, *normal)?;
                let before = (self.pieces.clone(), self.offsets.clone());
                self.pieces[*piece] = a;
                self.pieces.insert(*piece + 1, b);
                self.offsets.insert(*piece + 1, offset);
                for p in [*piece, *piece + 1] {
                    self.pieces[p].set_transform(DAffine3::from_translation(offset));
                }
                Ok((
                    Delta::Checkpoint(before.0, before.1),
                    vec![*piece, *piece + 1],
                ))
            }
            Edit::Recombine { a, b } => {
                check_piece("the first piece to recombine", *a)?;
                check_piece("the second piece to recombine", *b)?;
                let merged = Object::recombine(&self.pieces[*a], &self.pieces[*b])?;
                let before = (self.pieces.clone(), self.offsets.clone());
                let (lo, hi) = ((*a).min(*b), (*a).max(*b));
                self.pieces.remove(hi);
                self.offsets.remove(hi);
                self.pieces[lo] = merged;
                self.offsets[lo] = DVec3::ZERO;
                Ok((Delta::Checkpoint(before.0, before.1), vec![lo]))
            }
        }
    }

    /// Gives piece `p` `lights` (display frame).
    fn set_piece_lights(&mut self, p: usize, lights: &[Light]) -> Result<(), Error> {
        let offset = self.offsets[p];
        let piece = &mut self.pieces[p];
        piece.clear_lights();
        for l in lights {
            piece.add_light(shift(l, -offset))?;
        }
        Ok(())
    }

    fn solve_coarse(&mut self, pieces: &[usize]) -> Result<Vec<SolveReport>, Error> {
        let budget = Budget {
            tolerance: Some(self.options.coarse_tolerance),
            ..Budget::default()
        };
        pieces
            .iter()
            .map(|&p| {
                let o = &mut self.pieces[p];
                if o.settings.tolerance >= self.options.coarse_tolerance {
                    o.solve()
                } else {
                    o.solve_monitored(&budget)
                }
            })
            .collect()
    }

    /// Keeps the coarse result of the last edit as it is (after a
    /// refinement that failed): the log says it was not refined.
    pub fn skip_refinement(&mut self) {
        self.unrefined = false;
    }

    /// Whether the last edit's result is still the coarse one.
    pub fn needs_refinement(&self) -> bool {
        self.unrefined
    }

    /// Solves every piece to its full tolerance, stopping when `cancel`
    /// is set. Returns the solves and whether it finished; when it did
    /// not, `φ` is put back to the coarse result, so that the state stays
    /// a function of the log.
    ///
    /// # Errors
    /// Those of [`Object::solve_monitored`] (`φ` is then put back too).
    pub fn refine(&mut self, cancel: &AtomicBool) -> Result<(Vec<SolveReport>, bool), Error> {
        if !self.unrefined {
            return Ok((Vec::new(), true));
        }
        let saved: Vec<[Vec<f64>; 3]> = self.pieces.iter().map(phi_of).collect();
        let budget = Budget {
            cancel: Some(cancel),
            ..Budget::default()
        };
        let mut reports = Vec::new();
        for p in 0..self.pieces.len() {
            match self.pieces[p].solve_monitored(&budget) {
                Ok(r) if r.interrupted => {
                    self.restore_phi(saved);
                    return Ok((reports, false));
                }
                Ok(r) => reports.push(r),
                Err(e) => {
                    self.restore_phi(saved);
                    return Err(e);
                }
            }
        }
        self.unrefined = false;
        match self.cursor.checked_sub(1) {
            Some(i) => self.history[i].logged.refined = true,
            None if self.settled.edits.is_empty() => self.settled.refined_initially = true,
            None => {}
        }
        Ok((reports, true))
    }

    fn restore_phi(&mut self, phi: Vec<[Vec<f64>; 3]>) {
        for (piece, p) in self.pieces.iter_mut().zip(phi) {
            piece.phi = p;
        }
    }

    /// The applied edits, oldest first: what [`replay`](Self::replay)
    /// takes (the redo branch is not in it).
    pub fn log(&self) -> Log {
        let mut log = self.settled.clone();
        log.edits
            .extend(self.history[..self.cursor].iter().map(|e| e.logged.clone()));
        log
    }

    /// Names of the applied edits and of those that can be redone.
    pub fn history(&self) -> (Vec<&'static str>, Vec<&'static str>) {
        let names = |e: &[Entry]| e.iter().map(|e| e.logged.edit.name()).collect();
        (
            names(&self.history[..self.cursor]),
            names(&self.history[self.cursor..]),
        )
    }

    /// A session on `object` with `log` applied: the same pieces, media,
    /// lights and `φ`, bit for bit, as the session that wrote the log
    /// (given the same object and options).
    ///
    /// # Errors
    /// The first edit's error, naming its position in the log.
    pub fn replay(
        object: Object,
        options: SessionOptions,
        log: &Log,
    ) -> Result<Self, (usize, Error)> {
        let mut s = Self::new(object, options).map_err(|e| (0, e))?;
        if log.refined_initially {
            s.refine_now().map_err(|e| (0, e))?;
        }
        for (k, l) in log.edits.iter().enumerate() {
            s.push(l.edit.clone()).map_err(|e| (k, e))?;
            // One at a time: the log already holds coalesced edits.
            let edit = s.pending.pop_front().ok_or((
                k,
                Error::BadArgument {
                    what: "the log".into(),
                    value: k as f64,
                    need: "an edit was lost",
                },
            ))?;
            s.apply(edit, 1).map_err(|e| (k, e))?;
            if l.refined {
                s.refine_now().map_err(|e| (k, e))?;
            }
        }
        Ok(s)
    }

    /// [`refine`](Self::refine) without a cancel flag.
    ///
    /// # Errors
    /// As [`refine`](Self::refine).
    pub fn refine_now(&mut self) -> Result<Vec<SolveReport>, Error> {
        let never = AtomicBool::new(false);
        self.refine(&never).map(|(r, _)| r)
    }

    /// Whether there is an edit to undo / to redo.
    pub fn can_undo(&self) -> bool {
        self.cursor > 0
    }

    /// Whether there is an undone edit to redo.
    pub fn can_redo(&self) -> bool {
        self.cursor < self.history.len()
    }

    /// Undoes the last applied edit: media, lights, offsets, pieces and `φ`
    /// as they were before it (φ bit for bit while its copy is within the
    /// budget, else re-solved). Waiting edits are dropped. Returns the
    /// edit undone, or `None` when there is none.
    ///
    /// # Errors
    /// Those of a re-solve (only when `φ`'s copy was dropped).
    pub fn undo(&mut self) -> Result<Option<Edit>, Error> {
        self.pending.clear();
        let Some(i) = self.cursor.checked_sub(1) else {
            return Ok(None);
        };
        let mut entry = self.history[i].clone();
        let resolve = self.swap_back(&mut entry.delta, &entry.logged.edit)?;
        self.history[i].delta = entry.delta;
        self.cursor = i;
        self.unrefined = false;
        if resolve {
            self.refine_after_swap()?;
        }
        Ok(Some(entry.logged.edit))
    }

    /// Redoes the last undone edit (the same media, lights and `φ` as when
    /// it was first applied). Returns it, or `None` when there is none.
    ///
    /// # Errors
    /// Those of the edit (which succeeded before, so none in practice) or
    /// of a re-solve.
    pub fn redo(&mut self) -> Result<Option<Edit>, Error> {
        self.pending.clear();
        if self.cursor >= self.history.len() {
            return Ok(None);
        }
        let i = self.cursor;
        let edit = self.history[i].logged.edit.clone();
        let resolve = match &mut self.history[i].delta {
            Delta::Checkpoint(..) => {
                let mut delta = self.history[i].delta.clone();
                self.swap_back(&mut delta, &edit)?;
                self.history[i].delta = delta;
                false
            }
            Delta::Values { phi, .. } => {
                let after = phi.take();
                let (delta, _) = self.perform(&edit)?;
                let resolve = after.is_none();
                if let Some(after) = after {
                    self.restore_phi(after);
                }
                self.history[i].delta = delta;
                resolve
            }
        };
        self.cursor = i + 1;
        self.unrefined = false;
        if resolve {
            self.refine_after_swap()?;
        }
        Ok(Some(edit))
    }

    fn refine_after_swap(&mut self) -> Result<(), Error> {
        for p in &mut self.pieces {
            p.solve()?;
        }
        Ok(())
    }

    /// Puts the state in `delta` back and leaves the current one in it
    /// (for the opposite move). Returns whether `φ` must be re-solved.
    fn swap_back(&mut self, delta: &mut Delta, edit: &Edit) -> Result<bool, Error> {
        match delta {
            Delta::Checkpoint(pieces, offsets) => {
                std::mem::swap(&mut self.pieces, pieces);
                std::mem::swap(&mut self.offsets, offsets);
                Ok(false)
            }
            Delta::Values {
                media,
                lights,
                offsets,
                phi,
            } => {
                for (piece, previous) in self.pieces.iter_mut().zip(media.iter()) {
                    if matches!(edit, Edit::Material(_)) {
                        piece.restore_all_media(previous);
                    } else {
                        piece.restore_media(previous);
                    }
                }
                if let Some(before) = offsets.take() {
                    for (p, &o) in before.iter().enumerate() {
                        if o != self.offsets[p] {
                            let display: Vec<Light> = self.pieces[p]
                                .lights()
                                .iter()
                                .map(|l| shift(l, self.offsets[p]))
                                .collect();
                            self.offsets[p] = o;
                            self.pieces[p].set_transform(DAffine3::from_translation(o));
                            self.set_piece_lights(p, &display)?;
                        }
                    }
                }
                if let Some(before) = lights.take() {
                    for (p, l) in before.into_iter().enumerate() {
                        let piece = &mut self.pieces[p];
                        piece.clear_lights();
                        for l in l {
                            piece.add_light(l)?;
                        }
                    }
                }
                let now: Vec<[Vec<f64>; 3]> = self.pieces.iter().map(phi_of).collect();
                let resolve = match phi.take() {
                    Some(before) => {
                        self.restore_phi(before);
                        false
                    }
                    None => true,
                };
                *phi = Some(now);
                Ok(resolve)
            }
        }
    }

    /// Bytes the undo and redo deltas hold.
    pub fn undo_bytes(&self) -> usize {
        self.history.iter().map(|e| e.delta.bytes()).sum()
    }

    /// Drops the oldest `φ` copies, then the oldest entries, until the
    /// deltas fit the budget (the newest entry is always kept).
    fn enforce_budget(&mut self) {
        let budget = self.options.undo_budget_bytes;
        let mut total = self.undo_bytes();
        let mut k = 0;
        while total > budget && k + 1 < self.cursor {
            if let Delta::Values { phi, .. } = &mut self.history[k].delta
                && let Some(p) = phi.take()
            {
                total -= p.iter().map(|c| 3 * 8 * c[0].len()).sum::<usize>();
            }
            k += 1;
        }
        while total > budget && self.cursor > 1 {
            let e = self.history.remove(0);
            total -= e.delta.bytes();
            self.settled.edits.push(e.logged);
            self.cursor -= 1;
        }
    }
}

/// `φ` of an object, per channel.
fn phi_of(o: &Object) -> [Vec<f64>; 3] {
    o.phi.clone()
}

/// `light` moved by `by` (point lights only: directions and maps have no
/// position).
fn shift(light: &Light, by: DVec3) -> Light {
    match light {
        Light::Point {
            position,
            intensity,
        } => Light::Point {
            position: *position + by,
            intensity: *intensity,
        },
        other => other.clone(),
    }
}

/// `cut` in the frame of a piece displayed at `offset`.
fn cut_in(cut: &Cut, offset: DVec3) -> Cut {
    match cut {
        Cut::Plane { point, normal } => Cut::Plane {
            point: *point - offset,
            normal: *normal,
        },
        Cut::Stroke { points, view } => Cut::Stroke {
            points: points.iter().map(|&p| p - offset).collect(),
            view: *view,
        },
    }
}
