//! Undo and redo for the painting system (Sec. 5.1): a stroke is kept as
//! the delta of the samples it touched — each sample's value before the
//! stroke, stored once however many dabs reached it — and a detail change
//! as the [`ResolutionChange`] of the faces it resampled; never a copy of
//! the whole colours.
//!
//! A [`Recorder`] collects a stroke's old values as [`Painter::paint_recorded`]
//! (or the caller, through [`Recorder::record`]) changes samples;
//! [`Recorder::finish`] turns it into a [`Delta`]: sorted runs of sample
//! indices (8 bytes a run) and their values, compressed without loss.
//! [`Delta::undo`] and [`Delta::redo`] *swap* the stored values with the
//! colours' ones, so one copy serves both directions and both are exact.
//!
//! **Value coding**: the values are split into byte planes — for each
//! channel, the most significant byte of every sample's value, then the
//! next byte, and so on — and the planes are compressed with DEFLATE
//! (RFC 1951, through `miniz_oxide`), losslessly. Sign and exponent
//! bytes of neighbouring samples repeat, and the colours of a texture
//! converted from 8 bits take few distinct values, so a stroke's old
//! values typically take a third or less of their raw size.
//!
//! [`History`] keeps a bounded list of steps of either kind.
//!
//! Deltas hold sample indices, which a resolution change renumbers: undo
//! and redo must run in history order (last in, first out), which
//! [`History`] does.
//!
//! [`Painter::paint_recorded`]: crate::Painter::paint_recorded

use std::collections::VecDeque;

use crate::Error;
use crate::edit::ResolutionChange;
use crate::structure::MeshColors;

/// Collects the old values of the samples one stroke changes, each sample
/// once (the first time it is recorded). Its scratch memory is one bit per
/// sample of the colours, freed by [`Recorder::finish`].
#[derive(Debug, Clone)]
pub struct Recorder {
    channels: usize,
    sample_count: usize,
    seen: Vec<u64>,
    indices: Vec<u32>,
    values: Vec<f32>,
}

impl Recorder {
    /// A recorder for a stroke on `colors`.
    pub fn new(colors: &MeshColors) -> Self {
        Self {
            channels: colors.channels(),
            sample_count: colors.sample_count(),
            seen: vec![0; colors.sample_count().div_ceil(64)],
            indices: Vec::new(),
            values: Vec::new(),
        }
    }

    /// Checks that `colors` have the channel and sample counts this
    /// recorder (or delta) was made for.
    pub(crate) fn fits(&self, colors: &MeshColors) -> Result<(), Error> {
        fits(self.channels, self.sample_count, colors)
    }

    /// Records sample `sample`'s current value in `colors`, to be called
    /// *before* the caller changes it; returns whether this was the first
    /// time (later calls for the same sample keep the first value).
    ///
    /// # Errors
    /// [`Error::StaleUndo`] if `colors` have other channel or sample counts
    /// than the colours this recorder was made for, or `sample` is out of
    /// range.
    pub fn record(&mut self, colors: &MeshColors, sample: usize) -> Result<bool, Error> {
        self.fits(colors)?;
        match colors.sample(sample) {
            Some(value) => Ok(self.note(sample, value)),
            None => Err(Error::StaleUndo {
                what: "sample",
                index: sample,
                reason: "is out of range",
            }),
        }
    }

    /// As [`Recorder::record`] for an index and value already checked.
    #[inline]
    pub(crate) fn note(&mut self, sample: usize, value: &[f32]) -> bool {
        let (word, bit) = (sample / 64, 1u64 << (sample % 64));
        if self.seen[word] & bit != 0 {
            return false;
        }
        self.seen[word] |= bit;
        self.indices.push(sample as u32);
        self.values.extend_from_slice(value);
        true
    }

    /// Heap bytes the recorder holds: one bit per sample of the colours
    /// and the old values recorded so far, uncompressed.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.seen.capacity() * 8
            + self.indices.capacity() * 4
            + self.values.capacity() * 4
    }

    /// The number of samples recorded so far.
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    /// Whether no sample was recorded.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// The stroke's delta: the recorded samples sorted into runs of
    /// consecutive indices, with their old values.
    pub fn finish(self) -> Delta {
        let c = self.channels;
        let mut order: Vec<u32> = (0..self.indices.len() as u32).collect();
        order.sort_unstable_by_key(|&k| self.indices[k as usize]);
        let mut runs: Vec<(u32, u32)> = Vec::new();
        let mut values = Vec::with_capacity(self.values.len());
        for &k in &order {
            let i = self.indices[k as usize];
            match runs.last_mut() {
                Some((start, len)) if *start + *len == i => *len += 1,
                _ => runs.push((i, 1)),
            }
            let k = k as usize;
            values.extend_from_slice(&self.values[k * c..(k + 1) * c]);
        }
        runs.shrink_to_fit();
        Delta {
            channels: c,
            sample_count: self.sample_count,
            runs,
            count: order.len(),
            coded: encode(&values, c),
            undone: false,
        }
    }
}

fn fits(channels: usize, sample_count: usize, colors: &MeshColors) -> Result<(), Error> {
    if colors.channels() != channels {
        return Err(Error::StaleUndo {
            what: "channels",
            index: colors.channels(),
            reason: "differ from the colours the record was made for",
        });
    }
    if colors.sample_count() != sample_count {
        return Err(Error::StaleUndo {
            what: "sample count",
            index: colors.sample_count(),
            reason: "differs from the colours the record was made for",
        });
    }
    Ok(())
}

/// The samples one stroke changed and their values on the other side of
/// the stroke: before it while it is applied, after it once undone.
#[derive(Debug, Clone, PartialEq)]
pub struct Delta {
    channels: usize,
    sample_count: usize,
    /// Sorted, disjoint, non-adjacent runs `(first sample, length)`.
    runs: Vec<(u32, u32)>,
    /// Samples in the runs.
    count: usize,
    /// `channels` values per sample, in run order, coded (module docs).
    coded: Vec<u8>,
    undone: bool,
}

impl Delta {
    /// Puts the samples back to their values before the stroke (and keeps
    /// the stroke's values for [`Delta::redo`]), exactly.
    ///
    /// # Errors
    /// [`Error::StaleUndo`] if it is undone already or `colors` are not
    /// the colours it was recorded on (other channel or sample counts);
    /// nothing changes then.
    pub fn undo(&mut self, colors: &mut MeshColors) -> Result<(), Error> {
        self.toggle(colors, false)
    }

    /// Applies the stroke again after [`Delta::undo`], exactly.
    ///
    /// # Errors
    /// [`Error::StaleUndo`] if it is not undone, or as for [`Delta::undo`].
    pub fn redo(&mut self, colors: &mut MeshColors) -> Result<(), Error> {
        self.toggle(colors, true)
    }

    fn toggle(&mut self, colors: &mut MeshColors, undone: bool) -> Result<(), Error> {
        if self.undone != undone {
            return Err(Error::StaleUndo {
                what: "stroke of samples",
                index: self.samples(),
                reason: if undone {
                    "is not undone, so it cannot be redone"
                } else {
                    "is undone already"
                },
            });
        }
        fits(self.channels, self.sample_count, colors)?;
        let c = self.channels;
        let stored = decode(&self.coded, self.count, c).ok_or(Error::StaleUndo {
            what: "stroke of samples",
            index: self.count,
            reason: "has stored values that do not decode",
        })?;
        let mut current = Vec::with_capacity(stored.len());
        let mut at = 0;
        let samples = colors.samples_mut();
        for &(start, len) in &self.runs {
            let (start, len) = (start as usize * c, len as usize * c);
            current.extend_from_slice(&samples[start..start + len]);
            samples[start..start + len].copy_from_slice(&stored[at..at + len]);
            at += len;
        }
        self.coded = encode(&current, c);
        self.undone = !undone;
        Ok(())
    }

    /// Whether the stroke is undone (the colours hold the old values).
    pub fn is_undone(&self) -> bool {
        self.undone
    }

    /// The changed samples as sorted runs `(first sample index, count)`:
    /// what a renderer must upload again after undo or redo.
    pub fn runs(&self) -> &[(u32, u32)] {
        &self.runs
    }

    /// The number of samples the stroke changed.
    pub fn samples(&self) -> usize {
        self.count
    }

    /// Whether the stroke changed nothing.
    pub fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }

    /// Heap bytes this delta holds: the coded values (module docs), 8 per
    /// run, and the struct.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.runs.capacity() * std::mem::size_of::<(u32, u32)>()
            + self.coded.capacity()
    }
}

/// The DEFLATE level of the value coding: the default trade-off (a
/// stroke's few kilobytes take well under a millisecond).
const LEVEL: u8 = 6;

/// Codes `values` (`c` per sample) as the module documentation says.
fn encode(values: &[f32], c: usize) -> Vec<u8> {
    let n = values.len() / c.max(1);
    let mut planes = Vec::with_capacity(values.len() * 4);
    for ch in 0..c {
        for byte in (0..4).rev() {
            planes.extend(
                values
                    .iter()
                    .skip(ch)
                    .step_by(c)
                    .take(n)
                    .map(|v| v.to_bits().to_le_bytes()[byte]),
            );
        }
    }
    let mut out = miniz_oxide::deflate::compress_to_vec(&planes, LEVEL);
    out.shrink_to_fit();
    out
}

/// The inverse of [`encode`] for `count` samples of `c` values; `None`
/// when `coded` does not decode to that many.
fn decode(coded: &[u8], count: usize, c: usize) -> Option<Vec<f32>> {
    let len = count * c * 4;
    let planes = miniz_oxide::inflate::decompress_to_vec_with_limit(coded, len).ok()?;
    if planes.len() != len {
        return None;
    }
    let mut bits = vec![0u32; count * c];
    for ch in 0..c {
        for (k, byte) in (0..4).rev().enumerate() {
            let plane = &planes[(ch * 4 + k) * count..(ch * 4 + k + 1) * count];
            for (s, &b) in plane.iter().enumerate() {
                bits[s * c + ch] |= u32::from(b) << (8 * byte);
            }
        }
    }
    Some(bits.into_iter().map(f32::from_bits).collect())
}

/// One undoable gesture.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// A paint stroke (any number of dabs).
    Paint(Delta),
    /// A detail (resolution) change.
    Resolution(ResolutionChange),
}

impl Step {
    /// Heap bytes the step holds.
    pub fn memory_bytes(&self) -> usize {
        match self {
            Step::Paint(d) => d.memory_bytes(),
            Step::Resolution(r) => r.memory_bytes(),
        }
    }
}

/// A linear undo history of at most `limit` steps and, optionally, at
/// most a budget of bytes: pushing a step drops the steps undone before
/// it (no branches) and then the oldest steps while there are more than
/// `limit` or they hold more than the budget — the newest step is always
/// kept, whatever it holds.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct History {
    steps: VecDeque<Step>,
    /// Steps `0..done` are applied, `done..` undone.
    done: usize,
    limit: usize,
    /// The most bytes ([`History::memory_bytes`]) kept.
    budget: usize,
}

impl History {
    /// An empty history keeping up to `limit` steps (0: none), of any
    /// size.
    pub fn new(limit: usize) -> Self {
        Self::with_budget(limit, usize::MAX)
    }

    /// An empty history keeping up to `limit` steps that together hold at
    /// most `budget` bytes ([`History::memory_bytes`]; the newest step is
    /// kept even when it alone holds more).
    pub fn with_budget(limit: usize, budget: usize) -> Self {
        Self {
            steps: VecDeque::new(),
            done: 0,
            limit,
            budget,
        }
    }

    /// The most bytes the steps kept may hold.
    pub fn budget(&self) -> usize {
        self.budget
    }

    /// Sets the budget and drops the oldest applied steps beyond it
    /// (undone steps stay, so redo still walks them in order).
    pub fn set_budget(&mut self, budget: usize) {
        self.budget = budget;
        self.trim();
    }

    /// Drops the oldest applied steps while more than `limit` are kept or
    /// they hold more than the budget; the newest step stays.
    fn trim(&mut self) {
        while self.done > 0
            && self.steps.len() > 1
            && (self.steps.len() > self.limit || self.memory_bytes() > self.budget)
        {
            self.steps.pop_front();
            self.done -= 1;
        }
    }

    /// Records a step just applied to the colours.
    pub fn push(&mut self, step: Step) {
        self.steps.truncate(self.done);
        self.steps.push_back(step);
        self.done = self.steps.len();
        self.trim();
        // A limit of 0 keeps nothing.
        if self.limit == 0 {
            self.steps.clear();
            self.done = 0;
        }
    }

    /// Undoes the last applied step; returns it (`None` when there is
    /// nothing to undo) so the caller knows what changed.
    ///
    /// # Errors
    /// As [`Delta::undo`] or [`MeshColors::revert_resolutions`] when the
    /// colours are not in the state the history left them in; the history
    /// and the colours are unchanged then.
    pub fn undo(&mut self, colors: &mut MeshColors) -> Result<Option<&Step>, Error> {
        if self.done == 0 {
            return Ok(None);
        }
        let k = self.done - 1;
        match &mut self.steps[k] {
            Step::Paint(d) => d.undo(colors)?,
            Step::Resolution(r) => colors.revert_resolutions(r)?,
        }
        self.done = k;
        Ok(Some(&self.steps[k]))
    }

    /// Redoes the first undone step; returns it (`None` when there is
    /// nothing to redo).
    ///
    /// # Errors
    /// As [`History::undo`].
    pub fn redo(&mut self, colors: &mut MeshColors) -> Result<Option<&Step>, Error> {
        let k = self.done;
        let Some(step) = self.steps.get_mut(k) else {
            return Ok(None);
        };
        match step {
            Step::Paint(d) => d.redo(colors)?,
            Step::Resolution(r) => *r = colors.set_face_resolutions(&r.requests())?,
        }
        self.done = k + 1;
        Ok(Some(&self.steps[k]))
    }

    /// Forgets the undone steps (what a new step does before it is
    /// pushed).
    pub(crate) fn drop_undone(&mut self) {
        self.steps.truncate(self.done);
    }

    /// Steps that can be undone.
    pub fn undo_len(&self) -> usize {
        self.done
    }

    /// Steps that can be redone.
    pub fn redo_len(&self) -> usize {
        self.steps.len() - self.done
    }

    /// All steps kept, oldest first.
    pub fn steps(&self) -> impl ExactSizeIterator<Item = &Step> {
        self.steps.iter()
    }

    /// Heap bytes of every step kept.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>() + self.steps.iter().map(Step::memory_bytes).sum::<usize>()
    }
}
