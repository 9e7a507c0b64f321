//! The one seeded random generator of the benches (xorshift64*): rings of inputs and random
//! configurations that are the same on every run and platform. `table_report` draws its
//! configurations with it exactly as the CLI's `eval` does, so their figures can be compared.

/// xorshift64* with its state; seed it with any value but 0.
pub struct BenchRng(pub u64);

impl BenchRng {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// The next value, uniform in `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}
