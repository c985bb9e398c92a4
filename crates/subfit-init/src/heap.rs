//! The collapse queue of [`crate::simplify`]: a 4-ary heap of 24-byte entries.

use std::cmp::Ordering;

/// A queued collapse (24 bytes: the heap's sift-down dominated the run time with the position
/// stored too, so the position is recomputed when the entry is popped and still valid).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Entry {
    pub(crate) cost: f64,
    pub(crate) keep: u32,
    pub(crate) remove: u32,
    pub(crate) stamp_keep: u32,
    pub(crate) stamp_remove: u32,
}

/// A 4-ary max-heap of entries (by [`Entry`]'s reversed order: the top is the cheapest). Half the
/// depth of a binary heap, and the four children share about two cache lines: the queue holds
/// ~10 entries per collapse (lazy invalidation), far beyond the caches on large meshes.
pub(crate) struct QuadHeap(pub(crate) Vec<Entry>);

impl QuadHeap {
    pub(crate) fn push(&mut self, e: Entry) {
        let v = &mut self.0;
        v.push(e);
        let mut i = v.len() - 1;
        while i > 0 {
            let p = (i - 1) / 4;
            if v[p] >= v[i] {
                break;
            }
            v.swap(p, i);
            i = p;
        }
    }

    pub(crate) fn pop(&mut self) -> Option<Entry> {
        let v = &mut self.0;
        let last = v.pop()?;
        if v.is_empty() {
            return Some(last);
        }
        let top = std::mem::replace(&mut v[0], last);
        let n = v.len();
        let mut i = 0;
        loop {
            let first = 4 * i + 1;
            if first >= n {
                break;
            }
            let mut best = first;
            for c in first + 1..(first + 4).min(n) {
                if v[c] > v[best] {
                    best = c;
                }
            }
            if v[i] >= v[best] {
                break;
            }
            v.swap(i, best);
            i = best;
        }
        Some(top)
    }
}

impl PartialEq for Entry {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Entry {
    /// Reversed (the greatest is the cheapest), ties broken by vertex ids.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .cost
            .total_cmp(&self.cost)
            .then_with(|| other.remove.cmp(&self.remove))
            .then_with(|| other.keep.cmp(&self.keep))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_heap_pops_cheapest_first_with_id_ties() {
        let mut h = QuadHeap(Vec::new());
        let mut x: u64 = 12345;
        let mut costs = Vec::new();
        for i in 0..1000u32 {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let cost = (x >> 40) as f64 % 97.0;
            costs.push((cost, i));
            h.push(Entry {
                cost,
                keep: 0,
                remove: i,
                stamp_keep: 0,
                stamp_remove: 0,
            });
        }
        costs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let popped: Vec<(f64, u32)> = std::iter::from_fn(|| h.pop())
            .map(|e| (e.cost, e.remove))
            .collect();
        assert_eq!(popped, costs);
    }
}
