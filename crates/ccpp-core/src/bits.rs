//! Word-at-a-time scans over the blocks of a [`fixedbitset::FixedBitSet`] (row runs of pixel
//! bitsets: free runs cost one word operation, not one test per pixel).

/// Bits per block of a `FixedBitSet`.
pub(crate) const BLOCK_BITS: usize = usize::BITS as usize;

/// The bits `from..to` of a block (`from < to <= BLOCK_BITS`).
#[inline]
pub(crate) fn range_mask(from: usize, to: usize) -> usize {
    if to - from == BLOCK_BITS {
        usize::MAX
    } else {
        ((1usize << (to - from)) - 1) << from
    }
}

/// Calls `f(i)` for every index `i` in `a..b` whose bit is set in `word(block)`, in increasing
/// order, until `f` returns `false`; returns `false` when stopped early.
#[inline]
pub(crate) fn for_each_set(
    a: usize,
    b: usize,
    word: impl Fn(usize) -> usize,
    mut f: impl FnMut(usize) -> bool,
) -> bool {
    let mut blk = a / BLOCK_BITS;
    while blk * BLOCK_BITS < b {
        let start = blk * BLOCK_BITS;
        let mut todo =
            word(blk) & range_mask(a.max(start) - start, b.min(start + BLOCK_BITS) - start);
        while todo != 0 {
            let bit = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            if !f(start + bit) {
                return false;
            }
        }
        blk += 1;
    }
    true
}

/// Sets the bits `a..b` of `blocks` and calls `on_new(i)` for every index `i` among them that
/// was not set before, in increasing order.
#[inline]
pub(crate) fn insert_range(
    blocks: &mut [usize],
    a: usize,
    b: usize,
    mut on_new: impl FnMut(usize),
) {
    let mut blk = a / BLOCK_BITS;
    while blk * BLOCK_BITS < b {
        let start = blk * BLOCK_BITS;
        let mask = range_mask(a.max(start) - start, b.min(start + BLOCK_BITS) - start);
        let mut new = mask & !blocks[blk];
        blocks[blk] |= mask;
        while new != 0 {
            let bit = new.trailing_zeros() as usize;
            new &= new - 1;
            on_new(start + bit);
        }
        blk += 1;
    }
}

/// A set of indices `0..n` kept as a bitset plus a summary bit per non-empty word, so that
/// listing the members in increasing order costs `O(members + n / 4096)` instead of a scan of
/// all `n` (insert and remove stay `O(1)`).
#[derive(Clone, Debug, Default)]
pub(crate) struct IndexSet {
    words: Vec<u64>,
    /// Bit `w % 64` of `summary[w / 64]`: `words[w] != 0`.
    summary: Vec<u64>,
    len: usize,
}

impl IndexSet {
    /// An empty set over `0..n`.
    pub(crate) fn new(n: usize) -> Self {
        let nw = n.div_ceil(64);
        Self {
            words: vec![0; nw],
            summary: vec![0; nw.div_ceil(64)],
            len: 0,
        }
    }

    /// Inserts `k`; returns `true` when it was not a member.
    #[inline]
    pub(crate) fn insert(&mut self, k: usize) -> bool {
        let (w, b) = (k / 64, 1u64 << (k % 64));
        if self.words[w] & b != 0 {
            return false;
        }
        self.words[w] |= b;
        self.summary[w / 64] |= 1u64 << (w % 64);
        self.len += 1;
        true
    }

    /// Removes `k`; returns `true` when it was a member.
    #[inline]
    pub(crate) fn remove(&mut self, k: usize) -> bool {
        let (w, b) = (k / 64, 1u64 << (k % 64));
        if self.words[w] & b == 0 {
            return false;
        }
        self.words[w] &= !b;
        if self.words[w] == 0 {
            self.summary[w / 64] &= !(1u64 << (w % 64));
        }
        self.len -= 1;
        true
    }

    /// Membership.
    #[inline]
    pub(crate) fn contains(&self, k: usize) -> bool {
        self.words
            .get(k / 64)
            .is_some_and(|&w| w & (1u64 << (k % 64)) != 0)
    }

    /// Number of members.
    #[inline]
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Calls `f` for every member in increasing order.
    pub(crate) fn for_each(&self, mut f: impl FnMut(usize)) {
        for (si, &s) in self.summary.iter().enumerate() {
            let mut ws = s;
            while ws != 0 {
                let w = si * 64 + ws.trailing_zeros() as usize;
                ws &= ws - 1;
                let mut bits = self.words[w];
                while bits != 0 {
                    f(w * 64 + bits.trailing_zeros() as usize);
                    bits &= bits - 1;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visits_exactly_the_set_bits_in_range() {
        let words = [0b1011usize, usize::MAX, 1 << 63];
        for a in 0..3 * BLOCK_BITS {
            for b in a..=3 * BLOCK_BITS {
                let mut got = Vec::new();
                for_each_set(
                    a,
                    b,
                    |k| words[k],
                    |i| {
                        got.push(i);
                        true
                    },
                );
                let want: Vec<usize> = (a..b)
                    .filter(|&i| words[i / BLOCK_BITS] >> (i % BLOCK_BITS) & 1 == 1)
                    .collect();
                assert_eq!(got, want, "{a}..{b}");
            }
        }
        let mut n = 0;
        assert!(!for_each_set(
            0,
            3 * BLOCK_BITS,
            |k| words[k],
            |_| {
                n += 1;
                n < 3
            }
        ));
        assert_eq!(n, 3);
    }

    #[test]
    fn insert_range_reports_only_new_bits() {
        let mut words = [0b1010usize, 0, 0];
        let mut new = Vec::new();
        insert_range(&mut words, 1, BLOCK_BITS + 3, |i| new.push(i));
        let want: Vec<usize> = (1..BLOCK_BITS + 3).filter(|&i| i != 1 && i != 3).collect();
        assert_eq!(new, want);
        assert_eq!(words, [usize::MAX - 1, 0b111, 0]);
    }

    #[test]
    fn index_set_lists_members_in_order() {
        let n = 64 * 64 * 2 + 7;
        let mut s = IndexSet::new(n);
        let mut want = std::collections::BTreeSet::new();
        let mut x = 12345u64;
        for _ in 0..20_000 {
            x = x
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let k = (x >> 33) as usize % n;
            if x & 1 == 0 {
                assert_eq!(s.insert(k), want.insert(k));
            } else {
                assert_eq!(s.remove(k), want.remove(&k));
            }
            assert_eq!(s.len(), want.len());
        }
        let mut got = Vec::new();
        s.for_each(|k| got.push(k));
        assert_eq!(got, want.iter().copied().collect::<Vec<_>>());
        for k in 0..n {
            assert_eq!(s.contains(k), want.contains(&k));
        }
    }
}
