//! Bounds-checked little-endian reads of a file's bytes, shared by the table format and the
//! shard format: every failure names the field, in the error type of the format reading it.

use alloc::{format, string::String};
use core::marker::PhantomData;

/// The two ways a read fails, as each format's error type spells them.
pub(crate) trait ReadError {
    /// The buffer ends before `needed` bytes (`have` there are) while reading `what`.
    fn truncated(what: &'static str, needed: usize, have: usize) -> Self;
    /// A field holds a value no valid file holds.
    fn corrupt(what: String) -> Self;
}

/// A cursor over `buf`; reads fail with `E`.
pub(crate) struct Reader<'a, E> {
    buf: &'a [u8],
    pos: usize,
    error: PhantomData<E>,
}

impl<'a, E: ReadError> Reader<'a, E> {
    /// A reader at the start of `buf`.
    pub(crate) fn new(buf: &'a [u8]) -> Self {
        Reader { buf, pos: 0, error: PhantomData }
    }

    /// Bytes read so far.
    pub(crate) fn pos(&self) -> usize {
        self.pos
    }

    /// The next `n` bytes.
    pub(crate) fn take(&mut self, n: usize, what: &'static str) -> Result<&'a [u8], E> {
        let end = self
            .pos
            .checked_add(n)
            .ok_or_else(|| E::corrupt(format!("{what}: length overflows")))?;
        let bytes =
            self.buf.get(self.pos..end).ok_or_else(|| E::truncated(what, end, self.buf.len()))?;
        self.pos = end;
        Ok(bytes)
    }

    pub(crate) fn u32(&mut self, what: &'static str) -> Result<u32, E> {
        self.take(4, what).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    pub(crate) fn u64(&mut self, what: &'static str) -> Result<u64, E> {
        self.take(8, what).map(|b| u64::from_le_bytes(core::array::from_fn(|i| b[i])))
    }

    /// A `u64` that must fit in a `usize`.
    pub(crate) fn size(&mut self, what: &'static str) -> Result<usize, E> {
        let v = self.u64(what)?;
        usize::try_from(v).map_err(|_| E::corrupt(format!("{what} = {v} does not fit in memory")))
    }

    /// A finite `f64`.
    pub(crate) fn f64(&mut self, what: &'static str) -> Result<f64, E> {
        let v = f64::from_bits(self.u64(what)?);
        if v.is_finite() {
            Ok(v)
        } else {
            Err(E::corrupt(format!("{what} = {v} is not finite")))
        }
    }

    pub(crate) fn f64x3(&mut self, what: &'static str) -> Result<[f64; 3], E> {
        Ok([self.f64(what)?, self.f64(what)?, self.f64(what)?])
    }

    /// The FNV-1a checksum that ends the file: it must be the last 8 bytes and match every
    /// byte before it.
    pub(crate) fn checksum(&mut self) -> Result<(), E> {
        let body_end = self.pos;
        let stored = self.u64("checksum")?;
        if self.pos != self.buf.len() {
            return Err(E::corrupt(format!(
                "{} trailing bytes after the checksum",
                self.buf.len() - self.pos
            )));
        }
        let computed = crate::cell::fnv1a64(&self.buf[..body_end]);
        if stored != computed {
            return Err(E::corrupt(format!(
                "checksum = {stored:#018x}, the bytes give {computed:#018x}"
            )));
        }
        Ok(())
    }

    /// `n` items of `size` bytes each.
    pub(crate) fn items(
        &mut self,
        n: usize,
        size: usize,
        what: &'static str,
    ) -> Result<&'a [u8], E> {
        let len = n
            .checked_mul(size)
            .ok_or_else(|| E::corrupt(format!("{what}: {n} entries overflow")))?;
        self.take(len, what)
    }
}
