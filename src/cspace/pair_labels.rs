//! The labels of every pair of samples of two robots, 2 bits each: at k = 64 a cell has 2.26
//! billion pairs, so a byte each (a [`Label`]) would be 2.26 GB held through the labelling,
//! the tree build and a shard merge; packed they are a quarter of that.
//!
//! Pair `p = j * nb + ib` (row `j`, `nb` pairs a row) is bits `2 (p % 4)` and up of byte
//! `p / 4`, with the codes of [`Label`] (0 free, 1 collision, 2 unreachable; 3 never
//! occurs): the layout of a shard file's labels. Four rows take `nb` whole bytes whatever
//! `nb`, so rows are written in parallel four at a time.

use super::Label;
use alloc::vec;
use alloc::vec::Vec;
use core::ops::Index;
#[cfg(feature = "std")]
use rayon::prelude::*;

/// The labels a code stands for (3 is never stored).
static LABELS: [Label; 4] = [Label::Free, Label::Collision, Label::Unreachable, Label::Collision];

/// The label of pair `p` of packed labels `bytes` (module doc).
#[inline]
pub(crate) fn label_in(bytes: &[u8], p: usize) -> Label {
    LABELS[usize::from(bytes[p / 4] >> (2 * (p % 4)) & 3)]
}

/// The byte of up to four labels, the first in the low bits.
fn packed(labels: &[Label]) -> u8 {
    labels.iter().enumerate().fold(0, |byte, (i, &l)| byte | (l as u8) << (2 * i))
}

/// Labels of `rows` x `nb` sample pairs, 2 bits each (module doc).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PairLabels {
    nb: usize,
    len: usize,
    bytes: Vec<u8>,
}

impl PairLabels {
    /// `rows` rows of `nb` labels, every one `label`.
    pub fn filled(rows: usize, nb: usize, label: Label) -> PairLabels {
        let code = label as u8;
        let len = rows * nb;
        let mut bytes = vec![code | code << 2 | code << 4 | code << 6; len.div_ceil(4)];
        // The bits past the last label stay 0, so that equal labels have equal bytes.
        if let (Some(last), 1..) = (bytes.last_mut(), len % 4) {
            *last &= (1 << (2 * (len % 4))) - 1;
        }
        PairLabels { nb, len, bytes }
    }

    /// The labels of `labels`, `nb` a row (`labels.len()` a multiple of `nb`).
    pub fn from_labels(nb: usize, labels: &[Label]) -> PairLabels {
        let mut out =
            PairLabels { nb, len: labels.len(), bytes: vec![0; labels.len().div_ceil(4)] };
        labels.iter().enumerate().for_each(|(p, &l)| out.set(p, l));
        out
    }

    /// Bytes that `pairs` labels take.
    pub fn bytes_for(pairs: u64) -> u64 {
        pairs.div_ceil(4)
    }

    /// How many labels (rows times `nb`).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The packed bytes (module doc).
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// The label of pair `p`.
    #[inline]
    pub fn get(&self, p: usize) -> Label {
        label_in(&self.bytes, p)
    }

    /// Sets the label of pair `p`.
    #[inline]
    pub fn set(&mut self, p: usize, label: Label) {
        let (byte, shift) = (&mut self.bytes[p / 4], 2 * (p % 4));
        *byte = *byte & !(3 << shift) | (label as u8) << shift;
    }

    /// Every label in pair order.
    pub fn iter(&self) -> impl Iterator<Item = Label> + '_ {
        (0..self.len).map(|p| self.get(p))
    }

    /// Row `j`.
    pub fn row(&self, j: usize) -> Vec<Label> {
        (j * self.nb..(j + 1) * self.nb).map(|p| self.get(p)).collect()
    }

    /// Writes `row` as row `j`: label by label up to the first whole byte of the row, then a
    /// byte per four labels, then the rest.
    pub fn set_row(&mut self, j: usize, row: &[Label]) {
        let start = j * self.nb;
        let head = ((4 - start % 4) % 4).min(row.len());
        row[..head].iter().enumerate().for_each(|(i, &l)| self.set(start + i, l));
        let quads = row[head..].chunks_exact(4);
        let (tail, first) = (quads.remainder(), (start + head) / 4);
        for (byte, q) in self.bytes[first..].iter_mut().zip(quads) {
            *byte = packed(q);
        }
        let at = start + row.len() - tail.len();
        tail.iter().enumerate().for_each(|(i, &l)| self.set(at + i, l));
    }
}

#[cfg(feature = "std")]
impl PairLabels {
    /// `rows` rows of `nb` labels, row `j` written by `write(j, row)` into a row of `Collision`
    /// labels, in parallel (four rows per task: their bytes are theirs alone).
    pub fn from_rows(
        rows: usize,
        nb: usize,
        write: impl Fn(usize, &mut [Label]) + Sync,
    ) -> PairLabels {
        // Zeroed by the kernel as both threads first touch their rows' pages.
        let mut out = PairLabels { nb, len: rows * nb, bytes: vec![0; (rows * nb).div_ceil(4)] };
        out.each_row(false, write);
        out
    }

    /// Rewrites every row `j` by `edit(j, row)`, in parallel four rows at a time (each
    /// unpacked, edited and packed again).
    pub fn rows_mut(&mut self, edit: impl Fn(usize, &mut [Label]) + Sync) {
        self.each_row(true, edit);
    }

    /// Every row `j` through `f(j, row)`: `row` unpacked from the bytes (`unpack`) or all
    /// `Collision`, then packed back, four rows per task.
    fn each_row(&mut self, unpack: bool, f: impl Fn(usize, &mut [Label]) + Sync) {
        let (nb, len) = (self.nb, self.len);
        if nb == 0 {
            return;
        }
        self.bytes.par_chunks_mut(nb).enumerate().for_each(|(g, bytes)| {
            let first = 4 * g;
            let rows = (len / nb - first).min(4);
            let mut labels = vec![Label::Collision; nb * rows];
            if unpack {
                labels.iter_mut().enumerate().for_each(|(q, l)| *l = label_in(bytes, q));
            }
            labels.chunks_mut(nb).enumerate().for_each(|(r, row)| f(first + r, row));
            // The group's bytes hold exactly its labels, four to a byte (the last maybe fewer).
            bytes.iter_mut().zip(labels.chunks(4)).for_each(|(byte, q)| *byte = packed(q));
        });
    }

    /// Every label equal to `from` made `to`, in parallel.
    pub fn replace(&mut self, from: Label, to: Label) {
        self.rows_mut(|_, row| row.iter_mut().filter(|l| **l == from).for_each(|l| *l = to));
    }

    /// How many labels are `label`, counted in parallel.
    pub fn count(&self, label: Label) -> usize {
        let code = label as u8;
        let full = self.len / 4;
        let whole: usize = self.bytes[..full]
            .par_iter()
            .map(|&b| (0..4).filter(|i| b >> (2 * i) & 3 == code).count())
            .sum();
        whole + (4 * full..self.len).filter(|&p| self.get(p) == label).count()
    }
}

impl Index<usize> for PairLabels {
    type Output = Label;

    /// The label of pair `p`, as [`PairLabels::get`].
    #[inline]
    fn index(&self, p: usize) -> &Label {
        &LABELS[label_in(&self.bytes, p) as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against a plain array of labels: every length and row width near the byte boundaries,
    /// every label at every place, rows edited in parallel, counts and replacements.
    #[test]
    fn packed_labels_read_back_as_written() {
        let all = [Label::Free, Label::Collision, Label::Unreachable];
        for nb in [1, 2, 3, 4, 5, 7, 8, 13] {
            for rows in [0, 1, 2, 3, 4, 5, 9] {
                let plain: Vec<Label> = (0..rows * nb).map(|p| all[(p * 7 + p / 3) % 3]).collect();
                let mut packed = PairLabels::from_labels(nb, &plain);
                assert_eq!(packed.len(), plain.len());
                assert!(packed.iter().eq(plain.iter().copied()));
                assert!(
                    (0..plain.len()).all(|p| packed[p] == plain[p] && packed.get(p) == plain[p])
                );
                let built = PairLabels::from_rows(rows, nb, |j, row| {
                    assert!(row.iter().all(|&l| l == Label::Collision), "rows start as collisions");
                    row.copy_from_slice(&plain[j * nb..(j + 1) * nb]);
                });
                assert_eq!(built, packed);
                for l in all {
                    assert_eq!(packed.count(l), plain.iter().filter(|&&x| x == l).count());
                }
                let turned = |l: Label| if l == Label::Free { Label::Unreachable } else { l };
                packed.rows_mut(|j, row| {
                    assert_eq!(row, &plain[j * nb..(j + 1) * nb]);
                    row.iter_mut().for_each(|l| *l = turned(*l));
                });
                assert!(packed.iter().eq(plain.iter().map(|&l| turned(l))));
                packed.replace(Label::Unreachable, Label::Collision);
                assert!(packed.iter().all(|l| l == Label::Collision));
                // Row by row over other labels, each row starting at every offset in its byte
                // as `nb` and `j` vary: the rows after it untouched.
                let mut by_rows = PairLabels::filled(rows, nb, Label::Unreachable);
                for j in 0..rows {
                    by_rows.set_row(j, &plain[j * nb..(j + 1) * nb]);
                    assert!(by_rows.iter().skip((j + 1) * nb).all(|l| l == Label::Unreachable));
                }
                assert_eq!(by_rows, PairLabels::from_labels(nb, &plain));
                assert!((0..rows).all(|j| by_rows.row(j) == plain[j * nb..(j + 1) * nb]));
            }
        }
    }
}
