//! FNV-1a, 64 bits: a small, stable hash of bytes (the same on every machine and in every
//! version), for assigning sweep configurations to shards and fingerprinting scenes. Not
//! cryptographic: it tells accidental differences apart, not deliberate collisions.

/// An FNV-1a hasher; also a `fmt::Write`, so that a value's `Debug` text can be hashed as it
/// is formatted, without building the string.
#[derive(Clone, Copy, Debug)]
pub struct Fnv64(u64);

impl Default for Fnv64 {
    fn default() -> Self {
        Fnv64(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv64 {
    pub fn bytes(&mut self, bytes: &[u8]) -> &mut Self {
        for &byte in bytes {
            self.0 ^= u64::from(byte);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
        self
    }

    pub fn finish(&self) -> u64 {
        self.0
    }
}

impl std::fmt::Write for Fnv64 {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.bytes(s.as_bytes());
        Ok(())
    }
}

/// A 64-bit FNV-1a hash of `bytes`, as 16 hex digits: a content fingerprint (to tell that a
/// file changed, not against an adversary).
pub fn content_hash(bytes: &[u8]) -> String {
    format!("{:016x}", Fnv64::default().bytes(bytes).finish())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_published_fnv1a_values() {
        // From the FNV reference test vectors (draft-eastlake-fnv).
        assert_eq!(Fnv64::default().finish(), 0xcbf2_9ce4_8422_2325);
        assert_eq!(Fnv64::default().bytes(b"a").finish(), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(
            Fnv64::default().bytes(b"foobar").finish(),
            0x8594_4171_f739_67e8
        );
    }
}
