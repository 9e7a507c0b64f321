//! Reading structured values from a fuzzer's bytes: each read takes bytes from the front and
//! reads zeros once they run out, so every byte string is a valid input and short inputs stay
//! meaningful (a hand-written `arbitrary::Unstructured`, to keep the fuzz targets free of
//! dependencies so that `tests/fuzz_short.rs` can compile them into the test suite).

/// Numbers where floating point code breaks: signed zeros, the extremes, NaN, infinities,
/// subnormals, and lengths of the thesis robot.
pub const SPECIAL_F64: [f64; 16] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::MAX,
    f64::MIN,
    f64::MIN_POSITIVE,
    5e-324,
    1e-300,
    1e300,
    100.0,
    400.0,
    -450.0,
];

/// A cursor over fuzzer bytes.
pub struct Input<'a> {
    data: &'a [u8],
}

impl<'a> Input<'a> {
    /// A cursor at the start of `data`.
    pub fn new(data: &'a [u8]) -> Self {
        Input { data }
    }

    /// Whether every byte has been read.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// The next `N` bytes, zero-padded past the end.
    pub fn bytes<const N: usize>(&mut self) -> [u8; N] {
        let n = N.min(self.data.len());
        let mut out = [0u8; N];
        out[..n].copy_from_slice(&self.data[..n]);
        self.data = &self.data[n..];
        out
    }

    /// One byte.
    pub fn byte(&mut self) -> u8 {
        self.bytes::<1>()[0]
    }

    /// A little-endian `u32`.
    pub fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.bytes())
    }

    /// A little-endian `u64`.
    pub fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.bytes())
    }

    /// Whether the next byte is odd.
    pub fn flag(&mut self) -> bool {
        self.byte() & 1 == 1
    }

    /// A number: a tag byte picks one of [`SPECIAL_F64`], raw bits (any NaN payload), or a
    /// length-like value in `[-1024, 1024)` mm with a 1/32 mm step.
    pub fn f64(&mut self) -> f64 {
        match self.byte() % 4 {
            0 => SPECIAL_F64[usize::from(self.byte()) % SPECIAL_F64.len()],
            1 => f64::from_bits(self.u64()),
            _ => f64::from(i16::from_le_bytes(self.bytes())) / 32.0,
        }
    }

    /// A TCP-like point (mm): a tag byte picks any [`Input::f64`] per coordinate (1 in 8),
    /// anywhere within about a metre below the base (3 in 8), or near the thesis robot's
    /// workspace, `|x|, |y| < 256`, `z` in `(-556, -300]` (4 in 8), where most TCPs reach.
    pub fn point(&mut self) -> [f64; 3] {
        let tag = self.byte() % 8;
        if tag == 0 {
            return [self.f64(), self.f64(), self.f64()];
        }
        let [x, y]: [i16; 2] = [i16::from_le_bytes(self.bytes()), i16::from_le_bytes(self.bytes())];
        let z = f64::from(u16::from_le_bytes(self.bytes()));
        if tag < 4 {
            [f64::from(x) / 64.0, f64::from(y) / 64.0, -z / 64.0]
        } else {
            [f64::from(x) / 128.0, f64::from(y) / 128.0, -300.0 - z / 256.0]
        }
    }
}

/// Encoding helpers: the inverse of the reads above, for writing seed inputs.
#[derive(Default)]
pub struct Encoder {
    /// The bytes written so far.
    pub bytes: Vec<u8>,
}

impl Encoder {
    /// Appends one byte.
    pub fn byte(&mut self, b: u8) -> &mut Self {
        self.bytes.push(b);
        self
    }

    /// Appends a little-endian `u16`.
    pub fn u16(&mut self, v: u16) -> &mut Self {
        self.bytes.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// Appends a little-endian `u32`.
    pub fn u32(&mut self, v: u32) -> &mut Self {
        self.bytes.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// Appends a little-endian `u64`.
    pub fn u64(&mut self, v: u64) -> &mut Self {
        self.bytes.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// Appends `v` as raw bits (read back exactly by [`Input::f64`]).
    pub fn f64(&mut self, v: f64) -> &mut Self {
        self.byte(1);
        self.bytes.extend_from_slice(&v.to_bits().to_le_bytes());
        self
    }

    /// Appends a point read back exactly by [`Input::point`] (coordinates as raw bits).
    pub fn point(&mut self, p: [f64; 3]) -> &mut Self {
        self.byte(0);
        p.iter().for_each(|&v| {
            self.f64(v);
        });
        self
    }
}
