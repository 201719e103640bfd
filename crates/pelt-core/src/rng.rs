//! Deterministic, stateless randomness.
//!
//! Everything random in Pelt (texture seeds, direction jitter, wind noise) is a pure function of
//! a seed and a coordinate, so results never depend on evaluation order or thread count.

/// A 64-bit mix (SplitMix64's finaliser). Good avalanche, no state.
#[must_use]
#[inline]
pub fn mix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// Hashes a seed and up to three coordinates into 64 random bits.
#[must_use]
#[inline]
pub fn hash(seed: u64, a: u64, b: u64, c: u64) -> u64 {
    mix64(mix64(mix64(seed ^ mix64(a)) ^ b) ^ c.wrapping_mul(0xD6E8_FEB8_6659_FD93))
}

/// A uniform float in `[0, 1)` from 64 random bits (the top 24 bits, exact in `f32`).
#[must_use]
#[inline]
pub fn unit_f32(bits: u64) -> f32 {
    (bits >> 40) as f32 * (1.0 / 16_777_216.0)
}

/// A small sequential generator for places that need a stream (still fully seeded).
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// A generator whose stream depends only on `seed`.
    #[must_use]
    pub fn new(seed: u64) -> Self {
        Self { state: mix64(seed) }
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        mix64(self.state)
    }

    /// Uniform in `[0, 1)`.
    pub fn next_f32(&mut self) -> f32 {
        unit_f32(self.next_u64())
    }

    /// Uniform in `[low, high)`.
    pub fn range_f32(&mut self, low: f32, high: f32) -> f32 {
        low + (high - low) * self.next_f32()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_is_in_range_and_spread() {
        let mut rng = Rng::new(7);
        let values: Vec<f32> = (0..10_000).map(|_| rng.next_f32()).collect();
        assert!(values.iter().all(|v| (0.0..1.0).contains(v)));
        let mean = values.iter().sum::<f32>() / values.len() as f32;
        assert!((mean - 0.5).abs() < 0.02, "mean {mean}");
    }

    #[test]
    fn hash_depends_on_every_input() {
        let h = hash(1, 2, 3, 4);
        assert_ne!(h, hash(0, 2, 3, 4));
        assert_ne!(h, hash(1, 0, 3, 4));
        assert_ne!(h, hash(1, 2, 0, 4));
        assert_ne!(h, hash(1, 2, 3, 0));
        assert_eq!(h, hash(1, 2, 3, 4));
    }
}
