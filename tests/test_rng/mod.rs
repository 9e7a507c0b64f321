//! The one seeded random generator of the integration tests that draw their own numbers
//! (xorshift64, the same sequence as the library's unit-test generator `src/test_rng.rs`):
//! reproducible inputs, the same on every platform. Tests that want distributions use
//! `rand`'s `StdRng` instead.

/// xorshift64 with its state; seed it with any value but 0.
pub struct TestRng(pub u64);

impl TestRng {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// The next value, uniform in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}
