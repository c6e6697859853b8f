//! The interactive session (see [`Session`]).

use std::collections::VecDeque;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use glam::{DAffine3, DVec3};

use crate::error::finite_vec;
use crate::object::Kept;
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
    /// The user's gesture it belongs to (one paint stroke, one light or
    /// piece drag: the page sends it as many edits), if any: consecutive
    /// entries of one gesture are undone and redone together, as an
    /// editor's undo takes back a stroke, not each of its dabs.
    pub gesture: Option<u64>,
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
    /// the V-cycle, a few iterations), on the system it is solved on (see
    /// `preview_rows`).
    pub coarse_tolerance: f64,
    /// The first result after an edit of a piece with more vertices than
    /// this is TransCut's (Sec. 4.2): solved on a coarse level of the
    /// solver's hierarchy (see `preview_rows`) and interpolated to the
    /// vertices ([`Object::solve_preview`]); smaller pieces are solved on
    /// their own system. `usize::MAX`: always on the original system.
    pub preview_above: usize,
    /// The level of such a first result: the finest with at most this
    /// many unknowns.
    pub preview_rows: usize,
    /// How cuts cut (see [`Object::cut`]): exact by default, or the
    /// paper's relaxation.
    pub cut_method: crate::CutMethod,
    /// Bytes the undo deltas may hold together.
    pub undo_budget_bytes: usize,
    /// Every how many edits (since the start or the last cut) an edit
    /// keeps a copy of `φ` before it (an anchor, see [`Session`]):
    /// undoing the edits in between re-does at most this
    /// many minus one edits' solves. At least 1 (1: every edit keeps its
    /// copy, no undo re-solves).
    pub phi_interval: usize,
}

impl Default for SessionOptions {
    /// 10⁻² (on a level of at most 5 000 unknowns for pieces above 30 000
    /// vertices), exact cuts, 512 MiB of undo, a `φ` anchor every 8 edits.
    fn default() -> Self {
        Self {
            coarse_tolerance: 1e-2,
            preview_above: 30_000,
            preview_rows: 5_000,
            cut_method: crate::CutMethod::Exact,
            undo_budget_bytes: 512 << 20,
            phi_interval: 8,
        }
    }
}

/// What the undo history holds, against the object it undoes
/// ([`Session::undo_memory`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UndoMemory {
    /// Bytes of the undo and redo deltas (media, lights, offsets, `φ`
    /// copies, replaced hierarchies, checkpoints).
    pub undo_bytes: usize,
    /// Bytes of the pieces now ([`Object::memory_bytes`]).
    pub object_bytes: usize,
    /// Of `undo_bytes`: the tets' previous media.
    pub media_bytes: usize,
    /// Of `undo_bytes`: the `φ` copies.
    pub phi_bytes: usize,
    /// Of `undo_bytes`: hierarchies replaced by refreshes that undo could
    /// not re-derive (0 unless the media of their time were out of reach).
    pub hierarchy_bytes: usize,
    /// Of `undo_bytes`: the checkpoints of cuts, fractures, recombinations.
    pub checkpoint_bytes: usize,
}

impl UndoMemory {
    /// `undo_bytes / object_bytes`.
    pub fn fraction(&self) -> f64 {
        self.undo_bytes as f64 / self.object_bytes.max(1) as f64
    }
}

/// What undoing an entry needs (and, after an undo, what redoing it
/// needs: the same slot holds the other state).
#[derive(Debug, Clone)]
enum Delta {
    /// Paint, lights, material or a move: values only.
    Values {
        /// Per piece, the changed tets and their previous media.
        media: Vec<Previous>,
        /// The lights before (per piece), for a light edit.
        lights: Option<Vec<Vec<Light>>>,
        /// The offsets before, for a move.
        offsets: Option<Vec<DVec3>>,
        /// `φ` of each piece before the edit, for an anchor, the newest
        /// applied edit, and those an undo recomputed (until the next new
        /// edit); `None` otherwise and while the edit is undone.
        phi: Option<Vec<[Vec<f64>; 3]>>,
        /// While the edit is applied: the pieces whose kept hierarchy its
        /// solve refreshed, each with how undo gets the one it replaced
        /// back. Empty while it is undone: redo's solve refreshes again
        /// (the same state before it, so the same decision and the same
        /// bits).
        kept: Vec<(usize, Replaced)>,
    },
    /// Cut, fracture, recombine: the pieces and offsets in the other
    /// state.
    Checkpoint(Vec<Object>, Vec<DVec3>),
}

impl Delta {
    /// The delta of an edit that changed media only.
    fn media(media: Vec<Vec<(u32, Medium)>>, phi: Option<Vec<[Vec<f64>; 3]>>) -> Self {
        Delta::Values {
            media: media.iter().map(|m| Previous::new(m)).collect(),
            lights: None,
            offsets: None,
            phi,
            kept: Vec::new(),
        }
    }

    fn bytes(&self) -> usize {
        self.parts().iter().sum()
    }

    /// Bytes of `[media, lights and offsets, φ, hierarchies, checkpoints]`.
    fn parts(&self) -> [usize; 5] {
        match self {
            Delta::Values {
                media,
                lights,
                phi,
                kept,
                ..
            } => {
                let m: usize = media.iter().map(Previous::bytes).sum();
                let l = lights.as_ref().map_or(0, |l| {
                    l.iter()
                        .map(|v| v.len() * std::mem::size_of::<Light>())
                        .sum()
                });
                let p: usize = phi.as_ref().map_or(0, |p| phi_bytes(p));
                let k: usize = kept
                    .iter()
                    .map(|(_, k)| match k {
                        Replaced::Derived => 0,
                        Replaced::Stored(k) => Object::kept_bytes(k),
                    })
                    .sum();
                [m, l, p, k, 0]
            }
            Delta::Checkpoint(pieces, _) => {
                [0, 0, 0, 0, pieces.iter().map(Object::memory_bytes).sum()]
            }
        }
    }
}

/// How undo gets back the kept hierarchy an edit's refresh replaced.
#[derive(Debug, Clone)]
enum Replaced {
    /// Re-derived ([`Session::rederive_kept`]): the replaced V-cycles are
    /// a deterministic function of the kept prolongations and the
    /// matrices when they were made, and the media of that time are
    /// reachable through the history (the previous media of the entries
    /// since, and [`Session::base`]). Nothing stored: a stored copy
    /// (matrix copy, coarse operators, coarsest factorisation) is a
    /// quarter of the object.
    Derived,
    /// Stored, when the media of its time are not reachable (it was made
    /// before a checkpoint or before what the budget dropped).
    Stored(Option<Arc<Kept>>),
}

/// Tets (mesh indices, in the order they were changed) and their
/// previous media, each medium stored once: a brush over one material
/// keeps 8 bytes a tet, not 56.
#[derive(Debug, Clone, Default)]
struct Previous {
    /// `(tet, index into palette)`.
    tets: Vec<(u32, u32)>,
    palette: Vec<Medium>,
}

impl Previous {
    fn new(list: &[(u32, Medium)]) -> Self {
        let mut index = std::collections::HashMap::new();
        let mut palette = Vec::new();
        let tets = list
            .iter()
            .map(|(t, m)| {
                let bits = [m.sigma_a, m.sigma_s_prime].map(|v| v.map(f64::to_bits));
                let k = *index.entry(bits).or_insert_with(|| {
                    palette.push(*m);
                    palette.len() as u32 - 1
                });
                (*t, k)
            })
            .collect();
        Self { tets, palette }
    }

    fn expand(&self) -> Vec<(u32, Medium)> {
        self.tets
            .iter()
            .map(|&(t, k)| (t, self.palette[k as usize]))
            .collect()
    }

    fn bytes(&self) -> usize {
        self.tets.len() * 8 + self.palette.len() * std::mem::size_of::<Medium>()
    }

    /// The tets of `self` (older) and of `newer`, each once with its
    /// oldest medium: what puts the media of the state before both back.
    fn merged_with_newer(&self, newer: &Previous) -> Previous {
        let mut list = self.expand();
        list.extend(newer.expand());
        let mut seen = std::collections::HashSet::new();
        list.retain(|(t, _)| seen.insert(*t));
        Previous::new(&list)
    }
}

#[derive(Debug, Clone)]
struct Entry {
    logged: Logged,
    delta: Delta,
    /// Whether it keeps the `φ` before it while applied (see the module
    /// docs).
    anchor: bool,
    /// The pieces whose kept hierarchy its solve built or refreshed (the
    /// points the media of a replaced hierarchy's time are found from).
    built: Vec<usize>,
}

impl Entry {
    fn phi(&self) -> Option<&Vec<[Vec<f64>; 3]>> {
        match &self.delta {
            Delta::Values { phi, .. } => phi.as_ref(),
            Delta::Checkpoint(..) => None,
        }
    }
}

/// Bytes of `φ` copies.
fn phi_bytes(phi: &[[Vec<f64>; 3]]) -> usize {
    phi.iter().map(|c| 3 * 8 * c[0].len()).sum()
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

/// An interactive session of TransCut (Sec. 5 and the paper's title:
/// *interactive* cutouts): one or more [`Object`]s (pieces, after a
/// fracture), an edit log with undo and redo, and progressive solves —
/// the model behind `trilux view`, `trilux diffuse --session` and Python.
///
/// - Edits are queued by [`Session::push`] (checked at once, so a bad one
///   never reaches the object) and applied by [`Session::apply_pending`],
///   which coalesces what waits: consecutive light changes and piece moves
///   keep the last, consecutive paint dabs are all painted and solved once.
/// - Each applied batch is solved to a loose tolerance first
///   ([`SessionOptions::coarse_tolerance`]: a picture within a few
///   iterations; for a large piece on a coarse level of its hierarchy,
///   interpolated, as TransCut's interactive result is, see
///   [`SessionOptions::preview_above`]), then [`Session::refine`] solves
///   it to the objects' tolerance unless new input cancels it. An interrupted refinement puts
///   the coarse `φ` back, so `φ` after every edit is a function of the
///   log alone: a saved log ([`Session::log`]) replays bit-identically
///   ([`Session::replay`]) on any number of threads.
/// - The solver's hierarchy is kept across paint, light, material and move
///   edits (see [`Object::hierarchy_builds`]); only cut, fracture and
///   recombine build a new one.
/// - Undo keeps small deltas: a paint keeps the changed tets' previous
///   media (their rows are re-assembled from them, exactly), a light
///   change the previous lights, a move the previous offset. An edit whose
///   solve refreshed the kept hierarchy keeps nothing for it: undo
///   re-derives the hierarchy before (its operators recomputed on the kept
///   prolongations for the media of the time it was made, which the
///   previous media of the entries since lead back to; bit for bit the
///   same), and stores it only when those media are out of reach. Cut,
///   fracture and recombine keep a checkpoint (the pieces before).
/// - `φ` is restored bit for bit, but not copied for every edit (a copy is
///   `3 × 8` bytes per vertex, 1.5–2% of the object): the newest applied
///   edit and every [`SessionOptions::phi_interval`]-th edit (an
///   *anchor*; also the first edit and the first after a cut) keep the
///   `φ` before them. Undoing another edit recomputes its `φ` from the
///   nearest anchor before it: `φ` after each edit is a deterministic
///   function of the `φ` before it and the edit (the same solves, the
///   same hierarchy), so re-doing the edits in between gives the same
///   bits. The `φ` passed on the way are kept until the next new edit,
///   so undoing step by step recomputes once per anchor interval. Redo
///   re-does the edit and its solves (the same bits again).
/// - The deltas share a budget ([`SessionOptions::undo_budget_bytes`]):
///   past it, the oldest entries (up to the next anchor) leave the undo
///   history (they stay in the log). [`Session::undo_memory`] reports
///   the undo bytes against the object's.
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
    /// Waiting edits, each with its gesture.
    pending: VecDeque<(Edit, Option<u64>)>,
    options: SessionOptions,
    /// Whether the last applied entry still waits for its refinement.
    unrefined: bool,
    /// Per piece at the start of `history`: the tets whose media changed
    /// between the making of the piece's kept hierarchy and that state,
    /// with their media then (empty when it was made in that state);
    /// `None` when unknown. What re-deriving a hierarchy made before the
    /// history's start needs once the budget dropped the entries since.
    base: Vec<Option<Previous>>,
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
            base: Vec::new(),
        };
        let before = s.pieces[0].kept.clone();
        s.solve_coarse(&[0])?;
        // An object that came with a kept hierarchy of an unknown state
        // keeps it (no drift): undo cannot re-derive that one.
        let made_now = !same_kept(&before, &s.pieces[0].kept);
        s.base = vec![made_now.then(Previous::default)];
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
        self.push_in(edit, None)
    }

    /// Queues an edit of a gesture (see [`Logged::gesture`]): edits only
    /// coalesce within one gesture (or among edits of none), and the
    /// entries of one gesture undo and redo as one.
    ///
    /// # Errors
    /// As [`push`](Self::push).
    pub fn push_in(&mut self, edit: Edit, gesture: Option<u64>) -> Result<(), Error> {
        edit.check()?;
        self.pending.push_back((edit, gesture));
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
        self.apply_pending_with(|_, _| {})
    }

    /// [`apply_pending`](Self::apply_pending), calling `performed` once the
    /// edit is done to the pieces and before they are solved: the pieces
    /// then hold the edit with the `φ` of before carried over (the solve's
    /// warm start; a cut's created vertices interpolated along their
    /// edges). A viewer shows a cut's new surface from there, since the
    /// solve after a cut (a new hierarchy, then the coarse solve) takes
    /// longer than the cut. `performed` is not called for an edit that
    /// fails; what it sees is not the edit's result, which
    /// [`Session::pieces`] gives after this returns.
    ///
    /// # Errors
    /// Those of [`apply_pending`](Self::apply_pending).
    pub fn apply_pending_with(
        &mut self,
        performed: impl FnOnce(&Session, &Edit),
    ) -> Option<Result<Applied, Error>> {
        let (mut edit, gesture) = self.pending.pop_front()?;
        let mut coalesced = 1;
        while let Some((next, g)) = self.pending.front() {
            if *g != gesture {
                break;
            }
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
        Some(self.apply(edit, gesture, coalesced, performed))
    }

    fn apply(
        &mut self,
        edit: Edit,
        gesture: Option<u64>,
        coalesced: usize,
        performed: impl FnOnce(&Session, &Edit),
    ) -> Result<Applied, Error> {
        let start = Instant::now();
        let (delta, touched) = self.perform(&edit)?;
        self.history.truncate(self.cursor);
        let k = self.history.len();
        let anchor = self.is_anchor(k);
        self.history.push(Entry {
            logged: Logged {
                edit: edit.clone(),
                refined: false,
                gesture,
            },
            delta,
            anchor,
            built: Vec::new(),
        });
        self.cursor = k + 1;
        performed(self, &edit);
        let solves = self.solve_recording_kept(k, &touched)?;
        self.unrefined = true;
        self.thin_phi();
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
            Edit::Paint(dabs) => self.perform_paint(dabs),
            Edit::Material(m) => {
                let phi = phi_now(self);
                let mut media = Vec::with_capacity(n);
                for piece in &mut self.pieces {
                    media.push(piece.set_all_media(*m));
                }
                let delta = Delta::media(media, phi);
                Ok((delta, (0..n).collect()))
            }
            Edit::Lights(lights) => {
                let phi = phi_now(self);
                let before: Vec<Vec<Light>> = self.pieces.iter().map(Object::lights).collect();
                for p in 0..n {
                    self.set_piece_lights(p, lights)?;
                }
                let delta = Delta::Values {
                    media: vec![Previous::default(); n],
                    lights: Some(before),
                    offsets: None,
                    phi,
                    kept: Vec::new(),
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
                    media: vec![Previous::default(); n],
                    lights: None,
                    offsets: Some(before),
                    phi,
                    kept: Vec::new(),
                };
                Ok((delta, vec![*piece]))
            }
            Edit::Cut(cut) => self.perform_cut(cut),
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

    /// [`perform`](Self::perform) of a paint edit.
    fn perform_paint(&mut self, dabs: &[Stroke]) -> Result<(Delta, Vec<usize>), Error> {
        let n = self.pieces.len();
        let phi = Some(self.pieces.iter().map(phi_of).collect::<Vec<_>>());
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
        Ok((Delta::media(media, phi), touched))
    }

    /// [`perform`](Self::perform) of a cut.
    fn perform_cut(&mut self, cut: &Cut) -> Result<(Delta, Vec<usize>), Error> {
        // The pieces before become the checkpoint as they are: each piece
        // is copied once (the one cut, or one the cut does not reach),
        // not once for the checkpoint and again for the cut.
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
        let before_pieces = std::mem::replace(&mut self.pieces, pieces);
        let before_offsets = std::mem::replace(&mut self.offsets, offsets);
        Ok((Delta::Checkpoint(before_pieces, before_offsets), touched))
    }

    /// Whether an edit applied at history index `k` is an anchor: the
    /// first, the first after a checkpoint, or `phi_interval` after the
    /// previous anchor.
    fn is_anchor(&self, k: usize) -> bool {
        let interval = self.options.phi_interval.max(1);
        let mut back = 0;
        for e in self.history[..k].iter().rev() {
            if matches!(e.delta, Delta::Checkpoint(..)) {
                break;
            }
            back += 1;
            if e.anchor {
                return back >= interval;
            }
        }
        true
    }

    /// Drops the `φ` copies of the applied edits that are neither anchors
    /// nor the newest.
    fn thin_phi(&mut self) {
        let newest = self.cursor.checked_sub(1);
        for (k, e) in self.history.iter_mut().enumerate() {
            if !e.anchor
                && Some(k) != newest
                && let Delta::Values { phi, .. } = &mut e.delta
            {
                *phi = None;
            }
        }
    }

    /// The coarse solve of the pieces `touched` by history entry `k`,
    /// recording in it the pieces whose hierarchy the solve built or
    /// refreshed, and how undo gets a refreshed one's predecessor back.
    fn solve_recording_kept(
        &mut self,
        k: usize,
        touched: &[usize],
    ) -> Result<Vec<SolveReport>, Error> {
        let before: Vec<Option<Arc<Kept>>> = touched
            .iter()
            .map(|&p| self.pieces[p].kept.clone())
            .collect();
        let solves = self.solve_coarse(touched);
        let mut built = Vec::new();
        let mut replaced = Vec::new();
        for (&p, old) in touched.iter().zip(before) {
            if same_kept(&old, &self.pieces[p].kept) {
                continue;
            }
            built.push(p);
            // A first build (after a topology change) is not undone:
            // only a refresh of a kept hierarchy is.
            if old.is_some() {
                let how = if self.source_of_kept(k, p).is_some() {
                    Replaced::Derived
                } else {
                    Replaced::Stored(old)
                };
                replaced.push((p, how));
            }
        }
        let entry = &mut self.history[k];
        entry.built = built;
        if let Delta::Values { kept, .. } = &mut entry.delta {
            *kept = replaced;
        }
        solves
    }

    /// Where the media of the time piece `p`'s kept hierarchy before
    /// applied entry `k` was made are found: the first entry after the one
    /// that made it (its previous media, and those of the entries up to
    /// `k`, lead back there), with [`base`](Self::base) when it was made
    /// before the history's start. `None` when they cannot be found (made
    /// before a checkpoint, or before dropped entries that changed it).
    fn source_of_kept(&self, k: usize, p: usize) -> Option<(usize, Option<&Previous>)> {
        for m in (0..k).rev() {
            let e = &self.history[m];
            if e.built.contains(&p) {
                return Some((m + 1, None));
            }
            if matches!(e.delta, Delta::Checkpoint(..)) {
                return None;
            }
        }
        self.base.get(p)?.as_ref().map(|b| (0, Some(b)))
    }

    /// The kept hierarchy of piece `p` before applied entry `k`, which
    /// refreshed it, with the media of entry `k` already put back: the
    /// media are taken back to when that hierarchy was made, its
    /// operators recomputed there on the kept prolongations (bit for bit
    /// what was made then), and the media returned to what they were.
    fn rederive_kept(&mut self, k: usize, p: usize) -> Result<Option<Arc<Kept>>, Error> {
        let (from, before) = self.source_of_kept(k, p).ok_or(Error::BadArgument {
            what: "the undo history".into(),
            value: k as f64,
            need: "a replaced hierarchy's media are reachable",
        })?;
        // Newest first, so that the oldest medium of a tet is the last set.
        let mut lists: Vec<Vec<(u32, Medium)>> = (from..k)
            .rev()
            .filter_map(|m| match &self.history[m].delta {
                Delta::Values { media, .. } => media.get(p).map(Previous::expand),
                Delta::Checkpoint(..) => None,
            })
            .collect();
        lists.extend(before.map(Previous::expand));
        let piece = &mut self.pieces[p];
        let changed = piece.values_changed;
        let mut back = Vec::with_capacity(lists.len());
        for list in lists.iter().filter(|l| !l.is_empty()) {
            back.push(piece.current_media(list));
            piece.restore_media(list);
        }
        let kept = piece.kept_for_matrices();
        for list in back.iter().rev() {
            piece.restore_media(list);
        }
        // The media are as before, so the drift check owes nothing new.
        piece.values_changed = changed;
        kept
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
                } else if o.mesh().vertex_count() > self.options.preview_above {
                    o.solve_preview(self.options.preview_rows, self.options.coarse_tolerance)
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
        let (reports, finished) = self.solve_full(cancel)?;
        if !finished {
            return Ok((reports, false));
        }
        self.unrefined = false;
        match self.cursor.checked_sub(1) {
            Some(i) => self.history[i].logged.refined = true,
            None if self.settled.edits.is_empty() => self.settled.refined_initially = true,
            None => {}
        }
        Ok((reports, true))
    }

    /// Solves every piece to its full tolerance unless `cancel` stops it
    /// (then `φ` is put back, and the result says it did not finish).
    fn solve_full(&mut self, cancel: &AtomicBool) -> Result<(Vec<SolveReport>, bool), Error> {
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
    /// One name per undo step: the entries of one gesture count once.
    pub fn history(&self) -> (Vec<&'static str>, Vec<&'static str>) {
        let names = |e: &[Entry]| {
            e.iter()
                .enumerate()
                .filter(|&(k, x)| {
                    k == 0
                        || x.logged.gesture.is_none()
                        || x.logged.gesture != e[k - 1].logged.gesture
                })
                .map(|(_, x)| x.logged.edit.name())
                .collect()
        };
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
            s.push_in(l.edit.clone(), l.gesture).map_err(|e| (k, e))?;
            // One at a time: the log already holds coalesced edits.
            let (edit, gesture) = s.pending.pop_front().ok_or((
                k,
                Error::BadArgument {
                    what: "the log".into(),
                    value: k as f64,
                    need: "an edit was lost",
                },
            ))?;
            s.apply(edit, gesture, 1, |_, _| {}).map_err(|e| (k, e))?;
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

    /// Undoes the last applied edit: media, lights, offsets, pieces,
    /// hierarchy and `φ` bit for bit as they were before it (`φ` from its
    /// copy, or recomputed from the nearest anchor: see
    /// [`Session`]). Waiting edits are dropped. Returns the edit undone, or
    /// `None` when there is none. The entries of the last edit's gesture
    /// (see [`Logged::gesture`]) are undone together; the one returned
    /// is the latest of them.
    ///
    /// # Errors
    /// Those of re-doing the edits since the anchor (which succeeded
    /// before, so none in practice).
    pub fn undo(&mut self) -> Result<Option<Edit>, Error> {
        let Some(last) = self.undo_one()? else {
            return Ok(None);
        };
        let gesture = self.history[self.cursor].logged.gesture;
        while gesture.is_some()
            && self
                .cursor
                .checked_sub(1)
                .is_some_and(|i| self.history[i].logged.gesture == gesture)
        {
            self.undo_one()?;
        }
        Ok(Some(last))
    }

    fn undo_one(&mut self) -> Result<Option<Edit>, Error> {
        self.pending.clear();
        let Some(i) = self.cursor.checked_sub(1) else {
            return Ok(None);
        };
        self.unrefined = false;
        if let Delta::Checkpoint(..) = self.history[i].delta {
            self.swap_checkpoint(i);
            self.cursor = i;
            return Ok(Some(self.history[i].logged.edit.clone()));
        }
        self.swap_values_back(i)?;
        self.cursor = i;
        if let Some(phi) = self.take_phi(i) {
            self.restore_phi(phi);
        } else {
            self.recompute_phi_before(i)?;
        }
        Ok(Some(self.history[i].logged.edit.clone()))
    }

    /// Redoes the last undone edit (the same media, lights, hierarchy and
    /// `φ` as when it was first applied: the edit and its solves again).
    /// Returns it, or `None` when there is none. The entries of its
    /// gesture are redone together; the one returned is the latest of them.
    ///
    /// # Errors
    /// Those of the edit and its solves (which succeeded before, so none
    /// in practice).
    pub fn redo(&mut self) -> Result<Option<Edit>, Error> {
        let Some(mut last) = self.redo_one()? else {
            return Ok(None);
        };
        let gesture = self.history[self.cursor - 1].logged.gesture;
        while gesture.is_some()
            && self
                .history
                .get(self.cursor)
                .is_some_and(|e| e.logged.gesture == gesture)
        {
            if let Some(e) = self.redo_one()? {
                last = e;
            }
        }
        Ok(Some(last))
    }

    fn redo_one(&mut self) -> Result<Option<Edit>, Error> {
        self.pending.clear();
        if self.cursor >= self.history.len() {
            return Ok(None);
        }
        let i = self.cursor;
        self.unrefined = false;
        if let Delta::Checkpoint(..) = self.history[i].delta {
            self.swap_checkpoint(i);
        } else {
            let phi = self.pieces.iter().map(phi_of).collect();
            self.reapply(i)?;
            if let Delta::Values { phi: slot, .. } = &mut self.history[i].delta {
                *slot = Some(phi);
            }
        }
        self.cursor = i + 1;
        // A redone edit whose first result was never refined is as
        // unrefined as it was then, so idle time refines it. Only at the
        // end of the history: an entry still to be redone holds a state
        // (a cut's checkpoint) computed from this coarse result, which
        // refining now would leave stale against the log.
        self.unrefined = !self.can_redo() && !self.history[i].logged.refined;
        self.thin_phi();
        Ok(Some(self.history[i].logged.edit.clone()))
    }

    fn take_phi(&mut self, i: usize) -> Option<Vec<[Vec<f64>; 3]>> {
        match &mut self.history[i].delta {
            Delta::Values { phi, .. } => phi.take(),
            Delta::Checkpoint(..) => None,
        }
    }

    /// With the values of entries `i..` undone and `φ` still that after
    /// entry `i`, recomputes `φ` before entry `i`: back to the nearest
    /// earlier entry holding its `φ` (an anchor), then its edits and
    /// solves again, keeping the `φ` met on the way for the next undo.
    fn recompute_phi_before(&mut self, i: usize) -> Result<(), Error> {
        let lost = || Error::BadArgument {
            what: "the undo history".into(),
            value: i as f64,
            need: "an edit without its φ has an anchor before it",
        };
        let j = (0..i)
            .rev()
            .find(|&j| self.history[j].phi().is_some())
            .ok_or_else(lost)?;
        if self.history[j..i]
            .iter()
            .any(|e| matches!(e.delta, Delta::Checkpoint(..)))
        {
            return Err(lost());
        }
        for m in (j..i).rev() {
            self.swap_values_back(m)?;
        }
        let phi = self.history[j].phi().cloned().ok_or_else(lost)?;
        self.restore_phi(phi);
        for m in j..i {
            if m > j {
                let phi = self.pieces.iter().map(phi_of).collect();
                if let Delta::Values { phi: slot, .. } = &mut self.history[m].delta {
                    *slot = Some(phi);
                }
            }
            self.reapply(m)?;
        }
        Ok(())
    }

    /// Does history entry `i` (a values edit, undone) again with the
    /// solves it had: the coarse one (which refreshes the kept hierarchy
    /// where it did then: the same state before it, the same drift) and
    /// the refinement if it was refined. Its delta becomes the new one
    /// (the `φ` slot keeps what it held).
    fn reapply(&mut self, i: usize) -> Result<(), Error> {
        let edit = self.history[i].logged.edit.clone();
        let refined = self.history[i].logged.refined;
        let (mut delta, touched) = self.perform(&edit)?;
        let held = match &mut self.history[i].delta {
            Delta::Values { phi, .. } => phi.take(),
            Delta::Checkpoint(..) => None,
        };
        if let Delta::Values { phi, .. } = &mut delta {
            *phi = held;
        }
        self.history[i].delta = delta;
        self.solve_recording_kept(i, &touched)?;
        if refined {
            let never = AtomicBool::new(false);
            self.solve_full(&never)?;
        }
        Ok(())
    }

    fn swap_checkpoint(&mut self, i: usize) {
        if let Delta::Checkpoint(pieces, offsets) = &mut self.history[i].delta {
            std::mem::swap(&mut self.pieces, pieces);
            std::mem::swap(&mut self.offsets, offsets);
        }
    }

    /// Puts back the media, lights, offsets and hierarchies entry `i`
    /// (a values edit) changed; `φ` is left alone. Redo re-makes the
    /// delta.
    fn swap_values_back(&mut self, i: usize) -> Result<(), Error> {
        let is_material = matches!(self.history[i].logged.edit, Edit::Material(_));
        let Delta::Values {
            media,
            lights,
            offsets,
            kept,
            ..
        } = &mut self.history[i].delta
        else {
            return Ok(());
        };
        let (media, lights, offsets) = (std::mem::take(media), lights.take(), offsets.take());
        let kept = std::mem::take(kept);
        for (piece, previous) in self.pieces.iter_mut().zip(media.iter()) {
            let previous = previous.expand();
            if is_material {
                piece.restore_all_media(&previous);
            } else {
                piece.restore_media(&previous);
            }
        }
        if let Some(before) = offsets {
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
        if let Some(before) = lights {
            for (p, l) in before.into_iter().enumerate() {
                let piece = &mut self.pieces[p];
                piece.clear_lights();
                for l in l {
                    piece.add_light(l)?;
                }
            }
        }
        // After the media: re-deriving starts from the state before `i`.
        for (p, how) in kept {
            self.pieces[p].kept = match how {
                Replaced::Stored(k) => k,
                Replaced::Derived => self.rederive_kept(i, p)?,
            };
        }
        Ok(())
    }

    /// Bytes the undo and redo deltas hold.
    pub fn undo_bytes(&self) -> usize {
        self.history.iter().map(|e| e.delta.bytes()).sum::<usize>() + self.base_bytes()
    }

    /// Bytes of [`base`](Self::base)'s media.
    fn base_bytes(&self) -> usize {
        self.base.iter().flatten().map(Previous::bytes).sum()
    }

    /// The undo history's bytes against the object's (the figure the
    /// memory budget of undo is stated in).
    pub fn undo_memory(&self) -> UndoMemory {
        let mut parts = [0usize; 5];
        for e in &self.history {
            for (a, b) in parts.iter_mut().zip(e.delta.parts()) {
                *a += b;
            }
        }
        parts[0] += self.base_bytes();
        UndoMemory {
            undo_bytes: parts.iter().sum(),
            object_bytes: self.pieces.iter().map(Object::memory_bytes).sum(),
            media_bytes: parts[0],
            phi_bytes: parts[2],
            hierarchy_bytes: parts[3],
            checkpoint_bytes: parts[4],
        }
    }

    /// Drops the oldest entries (with the entries after them that need
    /// their anchor) until the deltas fit the budget; the newest entry is
    /// always kept.
    fn enforce_budget(&mut self) {
        let budget = self.options.undo_budget_bytes;
        let mut total = self.undo_bytes();
        while total > budget && self.cursor > 1 {
            self.drop_oldest(&mut total);
            while self.cursor > 1
                && matches!(self.history[0].delta, Delta::Values { .. })
                && self.history[0].phi().is_none()
            {
                self.drop_oldest(&mut total);
            }
        }
        // The oldest entry holds its φ (the loop above dropped those that
        // did not): it stays an anchor from now on.
        if let Some(e) = self.history.first_mut()
            && e.phi().is_some()
        {
            e.anchor = true;
        }
    }

    fn drop_oldest(&mut self, total: &mut usize) {
        let e = self.history.remove(0);
        self.base = match &e.delta {
            // The pieces after a checkpoint: only those it built are known.
            Delta::Checkpoint(..) => {
                let n = e.built.iter().max().map_or(0, |&m| m + 1);
                (0..n)
                    .map(|p| e.built.contains(&p).then(Previous::default))
                    .collect()
            }
            Delta::Values { media, .. } => {
                let n = self.base.len().max(media.len());
                (0..n)
                    .map(|p| {
                        if e.built.contains(&p) {
                            return Some(Previous::default());
                        }
                        let older = self.base.get(p)?.as_ref()?;
                        Some(match media.get(p) {
                            Some(newer) if !newer.tets.is_empty() => older.merged_with_newer(newer),
                            _ => older.clone(),
                        })
                    })
                    .collect()
            }
        };
        self.settled.edits.push(e.logged);
        self.cursor -= 1;
        *total = self.undo_bytes();
    }
}

/// Whether two kept solver states are the same one.
fn same_kept(a: &Option<Arc<Kept>>, b: &Option<Arc<Kept>>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => Arc::ptr_eq(a, b),
        (None, None) => true,
        _ => false,
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
