//! A content hash for recognising inputs again (bench resume keys, a run's map digest): 64-bit
//! FNV-1a over length-delimited fields. Not cryptographic: it tells an edited map from the
//! one a run used, not a forged one.

/// FNV-1a, 64 bits, with every field followed by its length (so `"ab","c"` and `"a","bc"`
/// differ).
#[derive(Clone, Debug)]
pub struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    /// A hash of nothing yet.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one field.
    pub fn bytes(&mut self, b: &[u8]) {
        self.field(b.iter().copied());
    }

    /// Adds one field given byte by byte (the same hash as [`Self::bytes`] of those bytes,
    /// without gathering them).
    pub fn field(&mut self, b: impl Iterator<Item = u8>) {
        let mut len = 0u64;
        for x in b {
            self.0 ^= u64::from(x);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
            len += 1;
        }
        self.0 ^= len;
        self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
    }

    /// The hash so far.
    #[must_use]
    pub fn finish(&self) -> u64 {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_delimited() {
        let h = |parts: &[&[u8]]| {
            let mut f = Fnv::new();
            for p in parts {
                f.bytes(p);
            }
            f.finish()
        };
        assert_ne!(h(&[b"ab", b"c"]), h(&[b"a", b"bc"]));
        assert_eq!(h(&[b"ab", b"c"]), h(&[b"ab", b"c"]));
        let mut f = Fnv::new();
        f.field(b"ab".iter().copied());
        f.bytes(b"c");
        assert_eq!(f.finish(), h(&[b"ab", b"c"]));
    }
}
