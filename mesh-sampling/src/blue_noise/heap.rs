//! The priority queue of the elimination: a bucket queue over quantised
//! weights, updated lazily.
//!
//! Sample elimination pops the heaviest candidate and lowers the weights
//! of its neighbours, millions of times. With a binary heap each lowering
//! is a sift through a heap far larger than the cache, which dominated the
//! run time. Here the weights are quantised to `BUCKETS` levels between 0
//! and the largest initial weight, and each level is a stack of items:
//!
//! - lowering a weight only writes it (O(1));
//! - popping takes items off the highest non-empty stack; an item whose
//!   current weight now belongs to a lower level is moved there, and the
//!   first item that still belongs to the level is the result.
//!
//! Because weights only decrease, the highest non-empty level never rises,
//! so the scan for it costs `BUCKETS` steps over the whole run. Items of
//! one level (weights within 1/`BUCKETS` of the largest weight of each
//! other) count as equal and leave in stack order; the order is a function
//! of the weights and the operations alone, hence deterministic.

/// Levels of the quantisation.
const BUCKETS: usize = 1 << 14;

/// The key of an item no longer in the queue.
const REMOVED: f64 = f64::NEG_INFINITY;

/// A max-priority queue of the items `0..n` with keys that only decrease.
#[derive(Debug)]
pub(crate) struct BucketQueue {
    buckets: Vec<Vec<u32>>,
    /// Each item's current key; `REMOVED` once popped (one array instead
    /// of a key and a flag: one cache miss per neighbour update, not two).
    keys: Vec<f64>,
    /// Levels per unit of key.
    scale: f64,
    /// No level above this one holds an item.
    top: usize,
    len: usize,
}

impl BucketQueue {
    /// A queue of items `0..keys.len()` (at most `u32::MAX` of them), with
    /// keys ≥ 0; an item whose key is −∞ is not in it (already removed).
    pub(crate) fn new(keys: Vec<f64>) -> Self {
        let max = keys.iter().copied().fold(0.0f64, f64::max);
        let scale = if max > 0.0 {
            (BUCKETS - 1) as f64 / max
        } else {
            0.0
        };
        let mut queue = Self {
            buckets: vec![Vec::new(); BUCKETS],
            len: keys.iter().filter(|&&k| k != REMOVED).count(),
            top: BUCKETS - 1,
            keys,
            scale,
        };
        for i in 0..queue.keys.len() {
            if queue.keys[i] != REMOVED {
                let b = queue.level(queue.keys[i]);
                queue.buckets[b].push(i as u32);
            }
        }
        queue
    }

    #[inline]
    fn level(&self, key: f64) -> usize {
        // Negative round-off of a weight that fell to zero lands in level 0.
        ((key * self.scale) as usize).min(BUCKETS - 1)
    }

    /// The number of items left.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Whether `item` is still in the queue.
    #[inline]
    pub(crate) fn contains(&self, item: u32) -> bool {
        self.keys[item as usize] != REMOVED
    }

    /// The current key of `item` (−∞ once removed).
    #[cfg(test)]
    pub(crate) fn key(&self, item: u32) -> f64 {
        self.keys[item as usize]
    }

    /// Lowers the key of `item` by `amount` ≥ 0 (an item no longer in the
    /// queue stays removed).
    #[inline]
    pub(crate) fn decrease(&mut self, item: u32, amount: f64) {
        self.keys[item as usize] -= amount;
    }

    /// Removes and returns an item of the highest level holding one.
    pub(crate) fn pop(&mut self) -> Option<u32> {
        if self.len == 0 {
            return None;
        }
        loop {
            let Some(item) = self.buckets[self.top].pop() else {
                // Items remain, so a lower level holds one.
                self.top = self.top.checked_sub(1)?;
                continue;
            };
            let level = self.level(self.keys[item as usize]);
            if level < self.top {
                self.buckets[level].push(item);
                continue;
            }
            self.keys[item as usize] = REMOVED;
            self.len -= 1;
            return Some(item);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pops_in_descending_key_order() {
        let mut q = BucketQueue::new(vec![3.0, 9.0, 1.0, 8.0, 5.0]);
        assert_eq!(q.pop(), Some(1));
        assert_eq!(q.pop(), Some(3));
        q.decrease(4, 4.5); // 5 -> 0.5
        assert!(q.contains(4));
        assert_eq!(q.pop(), Some(0));
        assert!(!q.contains(0));
        assert_eq!(q.pop(), Some(2));
        assert_eq!(q.pop(), Some(4));
        assert_eq!(q.pop(), None);
        assert_eq!(q.len(), 0);
    }

    #[test]
    fn pops_a_maximum_to_within_one_level_under_random_decreases() {
        // A small LCG keeps the test free of extra dependencies.
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as f64 / (1u64 << 31) as f64
        };
        let n = 500;
        let mut keys: Vec<f64> = (0..n).map(|_| next() * 20.0).collect();
        let width = 20.0 / (BUCKETS - 1) as f64;
        let mut q = BucketQueue::new(keys.clone());
        let mut alive = vec![true; n];
        while q.len() > 0 {
            for _ in 0..5 {
                let i = (next() * n as f64) as usize % n;
                if alive[i] {
                    let d = (next() * 2.0).min(keys[i]);
                    keys[i] -= d;
                    q.decrease(i as u32, d);
                }
            }
            let max = (0..n)
                .filter(|&i| alive[i])
                .map(|i| keys[i])
                .fold(f64::MIN, f64::max);
            let got = q.pop().unwrap() as usize;
            assert!(alive[got]);
            assert!(keys[got] >= max - width, "{} < {max}", keys[got]);
            alive[got] = false;
        }
        assert_eq!(q.pop(), None);
    }

    #[test]
    fn items_with_key_minus_infinity_start_removed() {
        let mut q = BucketQueue::new(vec![2.0, REMOVED, 1.0]);
        assert_eq!(q.len(), 2);
        assert!(!q.contains(1));
        assert_eq!(q.key(1), REMOVED);
        assert_eq!(q.pop(), Some(0));
        assert_eq!(q.pop(), Some(2));
        assert_eq!(q.pop(), None);
    }

    #[test]
    fn all_zero_keys_still_pop_every_item() {
        let mut q = BucketQueue::new(vec![0.0; 4]);
        let mut got: Vec<u32> = std::iter::from_fn(|| q.pop()).collect();
        got.sort_unstable();
        assert_eq!(got, vec![0, 1, 2, 3]);
    }
}
