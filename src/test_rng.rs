//! The one seeded random generator of the unit tests (xorshift64): reproducible inputs
//! without a dependency, the same sequence on every platform. Not for anything but tests.

use crate::math::{Real, Vec3};

/// xorshift64 with its state; seed it with any value but 0.
pub(crate) struct TestRng(pub u64);

impl TestRng {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// The next value, uniform in `[-1, 1)`.
    pub fn unit(&mut self) -> Real {
        (self.next_u64() >> 11) as Real / (1u64 << 53) as Real * 2.0 - 1.0
    }

    /// A vector with components uniform in `[-s, s)`.
    pub fn vec(&mut self, s: Real) -> Vec3 {
        Vec3::new(self.unit(), self.unit(), self.unit()) * s
    }
}
