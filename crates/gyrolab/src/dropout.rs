//! Dropout rows of a multi-channel record: rows a logger wrote when the sensor delivered
//! nothing (every channel exactly zero) or nothing new (every channel equal to the row before).
//!
//! Rule (docs/METHODS.md, "Dropouts"): with at least two channels, rows whose channels are all
//! exactly zero are dropouts when there are far more of them than chance allows: more than
//! 10 x the count expected if the channels were zero independently (the product of each
//! channel's fraction of zeros, times the rows) plus 3. Quantized outputs read 0 often on one
//! channel, rarely on all at once by chance. The same test, with each channel's fraction of
//! values equal to the row before, finds repeated rows. Dropouts are found, never repaired: the
//! callers leave them out of means and treat them as missing samples.

use serde::{Deserialize, Serialize};

/// Why a row is a dropout.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DropoutKind {
    /// Every channel exactly zero.
    AllZero,
    /// Every channel equal to the row before.
    Repeated,
}

/// The dropout rows of a record.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Dropouts {
    /// Row indices of all-zero dropouts, ascending.
    pub all_zero: Vec<usize>,
    /// Row indices of repeated-row dropouts, ascending.
    pub repeated: Vec<usize>,
}

impl Dropouts {
    /// Number of dropout rows.
    pub fn len(&self) -> usize {
        self.all_zero.len() + self.repeated.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Every dropout row, ascending.
    pub fn rows(&self) -> Vec<usize> {
        let mut v: Vec<usize> = self.all_zero.iter().chain(&self.repeated).copied().collect();
        v.sort_unstable();
        v
    }
}

/// Whether `hits` rows hit on every channel, of `rows`, are far more than chance gives when
/// channel c is hit independently in `per_channel[c]` rows: more than 10 x the expected count
/// plus 3 (the module's rule).
pub fn beyond_chance(hits: u64, rows: u64, per_channel: &[u64]) -> bool {
    if rows == 0 || per_channel.len() < 2 {
        return false;
    }
    let expected = per_channel.iter().fold(rows as f64, |e, &c| e * c as f64 / rows as f64);
    hits as f64 > 10.0 * expected + 3.0
}

/// Which kinds of dropout rows a record has, by the module's rule (the verdict of a
/// [`DropoutTally`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct DropoutVerdict {
    /// All-zero rows are dropouts.
    pub all_zero: bool,
    /// Repeated rows are dropouts.
    pub repeated: bool,
}

impl DropoutVerdict {
    /// Whether any row can be a dropout.
    pub fn any(&self) -> bool {
        self.all_zero || self.repeated
    }
}

/// The counts of the module's rule, fed row by row (or block by block) in one pass: each
/// channel's zeros and the all-zero rows; each channel's values equal to the row before and the
/// rows repeated on every channel, both over every row and over the rows that neither are
/// all zero nor follow an all-zero row (the rows repeats are looked for among when all-zero
/// rows are dropouts: a run of zeros repeats itself). The whole-record [`find_dropouts`] and
/// the streaming readers use it, so both follow one rule.
#[derive(Debug, Clone, PartialEq)]
pub struct DropoutTally {
    rows: u64,
    zeros: Vec<u64>,
    all_zero: u64,
    /// Repeats over every row: (rows considered, per channel, on every channel).
    rep: (u64, Vec<u64>, u64),
    /// Repeats over rows neither all zero nor after an all-zero row: (rows considered, on every
    /// channel); per channel, the repeats over every row less `skipped`.
    rep_skip: (u64, u64),
    /// Per channel, the repeats on the rows the second count leaves out.
    skipped: Vec<u64>,
    prev: Vec<f64>,
    prev_zero: bool,
    hits: Vec<bool>,
}

impl DropoutTally {
    /// A tally of `channels` channels.
    pub fn new(channels: usize) -> Self {
        DropoutTally {
            rows: 0,
            zeros: vec![0; channels],
            all_zero: 0,
            rep: (0, vec![0; channels], 0),
            rep_skip: (0, 0),
            skipped: vec![0; channels],
            prev: Vec::new(),
            prev_zero: false,
            hits: vec![false; channels],
        }
    }

    /// Adds the rows of a block, one slice per channel (equal lengths; the rows follow those
    /// of the previous block). Column by column, a few thousand rows at a time: each channel's
    /// zeros and repeats are counted in one vectorised sweep and marked in a per-row mask (one
    /// bit a channel); the rows' verdicts (all zero, all repeated, and which rows the second
    /// count skips) are read from the masks.
    pub fn push_block(&mut self, channels: &[&[f64]]) {
        let nch = self.zeros.len();
        if channels.len() != nch || nch == 0 {
            return;
        }
        if nch > 64 {
            return self.push_rows(channels);
        }
        const ROWS: usize = 4096;
        let full = if nch == 64 { u64::MAX } else { (1u64 << nch) - 1 };
        let n = channels.iter().map(|c| c.len()).min().unwrap_or(0);
        let mut zero_mask = [0u64; ROWS];
        let mut rep_mask = [0u64; ROWS];
        let mut start = 0;
        while start < n {
            let end = (start + ROWS).min(n);
            let len = end - start;
            let (zm, rm) = (&mut zero_mask[..len], &mut rep_mask[..len]);
            zm.fill(0);
            rm.fill(0);
            for (k, c) in channels.iter().enumerate() {
                let bit = 1u64 << k;
                let col = &c[start..end];
                // The row before the chunk (none at the record's start: NaN repeats nothing).
                let before = if start > 0 { c[start - 1] } else { self.prev.get(k).copied().unwrap_or(f64::NAN) };
                // Masks (the counts are read from them below).
                for (z, &v) in zm.iter_mut().zip(col) {
                    *z |= bit & 0u64.wrapping_sub(u64::from(v == 0.0));
                }
                rm[0] |= bit & 0u64.wrapping_sub(u64::from(col[0] == before));
                for ((r, &v), &p) in rm[1..].iter_mut().zip(&col[1..]).zip(&col[..len - 1]) {
                    *r |= bit & 0u64.wrapping_sub(u64::from(v == p));
                }
            }
            // Rows: all zero, all repeated; the second count leaves out all-zero rows and the
            // rows after them (their repeats are taken back per channel).
            for k in 0..nch {
                self.zeros[k] += zm.iter().map(|&z| (z >> k) & 1).sum::<u64>();
                self.rep.1[k] += rm.iter().map(|&r| (r >> k) & 1).sum::<u64>();
            }
            let mut prev_zero = self.prev_zero;
            for (&z, &r) in zm.iter().zip(rm.iter()) {
                let all_zero = z == full;
                let all_rep = r == full;
                self.all_zero += u64::from(all_zero);
                self.rep.2 += u64::from(all_rep);
                if !all_zero && !prev_zero {
                    self.rep_skip.0 += 1;
                    self.rep_skip.1 += u64::from(all_rep);
                } else if r != 0 {
                    for (k, skip) in self.skipped.iter_mut().enumerate() {
                        *skip += (r >> k) & 1;
                    }
                }
                prev_zero = all_zero;
            }
            self.rep.0 += len as u64;
            self.prev_zero = prev_zero;
            self.rows += len as u64;
            start = end;
        }
        if n > 0 {
            self.prev.clear();
            self.prev.extend(channels.iter().map(|c| c[n - 1]));
        }
    }

    /// [`DropoutTally::push_block`] row by row (for more than 64 channels).
    fn push_rows(&mut self, channels: &[&[f64]]) {
        let n = channels.iter().map(|c| c.len()).min().unwrap_or(0);
        for i in 0..n {
            let mut all_zero = true;
            for (c, z) in channels.iter().zip(self.zeros.iter_mut()) {
                let zero = c[i] == 0.0;
                *z += u64::from(zero);
                all_zero &= zero;
            }
            self.all_zero += u64::from(all_zero);
            let has_prev = !self.prev.is_empty();
            let mut all_rep = has_prev;
            for (k, c) in channels.iter().enumerate() {
                let h = has_prev && c[i] == self.prev[k];
                self.hits[k] = h;
                all_rep &= h;
            }
            self.rep.0 += 1;
            for (r, &h) in self.rep.1.iter_mut().zip(&self.hits) {
                *r += u64::from(h);
            }
            self.rep.2 += u64::from(all_rep);
            if !all_zero && !self.prev_zero {
                self.rep_skip.0 += 1;
                self.rep_skip.1 += u64::from(all_rep);
            } else {
                for (skip, &h) in self.skipped.iter_mut().zip(&self.hits) {
                    *skip += u64::from(h);
                }
            }
            self.prev.clear();
            self.prev.extend(channels.iter().map(|c| c[i]));
            self.prev_zero = all_zero;
            self.rows += 1;
        }
    }

    /// The tally of this part and the part after it (tallied from the row before it).
    fn join(mut self, next: DropoutTally) -> DropoutTally {
        let add = |a: &mut Vec<u64>, b: &[u64]| a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
        self.rows += next.rows;
        add(&mut self.zeros, &next.zeros);
        self.all_zero += next.all_zero;
        self.rep.0 += next.rep.0;
        add(&mut self.rep.1, &next.rep.1);
        self.rep.2 += next.rep.2;
        self.rep_skip.0 += next.rep_skip.0;
        self.rep_skip.1 += next.rep_skip.1;
        add(&mut self.skipped, &next.skipped);
        if next.rows > 0 {
            self.prev = next.prev;
            self.prev_zero = next.prev_zero;
        }
        self
    }

    /// Rows tallied.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// The verdict of the module's rule ([`beyond_chance`] for all-zero rows, then for repeated
    /// rows among the rows that remain).
    pub fn verdict(&self) -> DropoutVerdict {
        let all_zero = beyond_chance(self.all_zero, self.rows, &self.zeros);
        let skip_per: Vec<u64> = self.rep.1.iter().zip(&self.skipped).map(|(r, s)| r - s).collect();
        let (considered, per, hits) = if all_zero {
            (self.rep_skip.0, &skip_per, self.rep_skip.1)
        } else {
            (self.rep.0, &self.rep.1, self.rep.2)
        };
        DropoutVerdict { all_zero, repeated: beyond_chance(hits, considered, per) }
    }
}

/// Marks the dropout rows of a record row by row (or block by block) once the verdict is known
/// (from a first pass with [`DropoutTally`]), carrying the row before across blocks.
#[derive(Debug, Clone, PartialEq)]
pub struct DropoutMarker {
    verdict: DropoutVerdict,
    prev: Vec<f64>,
    prev_zero: bool,
}

impl DropoutMarker {
    /// A marker for `verdict`.
    pub fn new(verdict: DropoutVerdict) -> Self {
        DropoutMarker { verdict, prev: Vec::new(), prev_zero: false }
    }

    /// The verdict it marks.
    pub fn verdict(&self) -> DropoutVerdict {
        self.verdict
    }

    /// The dropout kind of each row of a block (one slice per channel, equal lengths, the rows
    /// following those of the previous block), calling `on_row(row in block, kind)` for each
    /// dropout row. A row repeating an all-zero row is not a repeat when all-zero rows are
    /// dropouts (the rule of [`DropoutTally`]).
    pub fn mark_block(&mut self, channels: &[&[f64]], mut on_row: impl FnMut(usize, DropoutKind)) {
        if !self.verdict.any() || channels.len() < 2 {
            return;
        }
        let n = channels.iter().map(|c| c.len()).min().unwrap_or(0);
        for i in 0..n {
            let all_zero = channels.iter().all(|c| c[i] == 0.0);
            if self.verdict.all_zero && all_zero {
                on_row(i, DropoutKind::AllZero);
            } else if self.verdict.repeated
                && !(self.verdict.all_zero && self.prev_zero)
                && !self.prev.is_empty()
                && channels.iter().zip(&self.prev).all(|(c, &p)| c[i] == p)
            {
                on_row(i, DropoutKind::Repeated);
            }
            self.prev.clear();
            self.prev.extend(channels.iter().map(|c| c[i]));
            self.prev_zero = all_zero;
        }
    }
}

/// Finds the dropout rows of `channels` (equal lengths; NaN never counts as zero or equal).
///
/// ```
/// use gyrolab::dropout::find_dropouts;
/// // Three channels (an accelerometer axis reading about 1 g among them) with 40 all-zero rows.
/// let n = 10_000;
/// let ch: Vec<Vec<f64>> = (0..3)
///     .map(|c| (0..n).map(|i| if (2000..2040).contains(&i) { 0.0 } else { (c * 10 + (i * 7 + c) % 5) as f64 }).collect())
///     .collect();
/// let refs: Vec<&[f64]> = ch.iter().map(|c| &c[..]).collect();
/// let d = find_dropouts(&refs);
/// assert_eq!(d.all_zero, (2000..2040).collect::<Vec<_>>());
/// ```
pub fn find_dropouts(channels: &[&[f64]]) -> Dropouts {
    let n = channels.iter().map(|c| c.len()).min().unwrap_or(0);
    if channels.len() < 2 || n < 2 {
        return Dropouts::default();
    }
    let channels: Vec<&[f64]> = channels.iter().map(|c| &c[..n]).collect();
    let tally = tally_in_parts(&channels);
    let mut d = Dropouts::default();
    DropoutMarker::new(tally.verdict()).mark_block(&channels, |i, kind| match kind {
        DropoutKind::AllZero => d.all_zero.push(i),
        DropoutKind::Repeated => d.repeated.push(i),
    });
    d
}

/// The tally of a whole record (channels of equal length), in parts tallied in parallel (each
/// from the row before it) and joined in order: the same counts as one pass.
fn tally_in_parts(channels: &[&[f64]]) -> DropoutTally {
    let n = channels.iter().map(|c| c.len()).min().unwrap_or(0);
    // Tallied in parts in parallel (each part starting from the row before it), joined in order.
    use rayon::prelude::*;
    const PARTS: usize = 4;
    let parts = if n < (1 << 16) { 1 } else { PARTS };
    let part = |k: usize| {
        let (a, b) = (n * k / parts, n * (k + 1) / parts);
        let mut t = DropoutTally::new(channels.len());
        if a > 0 {
            t.prev = channels.iter().map(|c| c[a - 1]).collect();
            t.prev_zero = t.prev.iter().all(|&v| v == 0.0);
        }
        let part: Vec<&[f64]> = channels.iter().map(|c| &c[a..b]).collect();
        t.push_block(&part);
        t
    };
    // A short record in one part on the calling thread: no rayon call, so no pool is started.
    if parts == 1 {
        return part(0);
    }
    (0..parts)
        .into_par_iter()
        .map(part)
        .reduce_with(DropoutTally::join)
        .unwrap_or_else(|| DropoutTally::new(channels.len()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// LSB-like quantized noise: integers in -3..=3 (zero about one time in seven), from
    /// splitmix64 (independent streams for different seeds).
    fn quantized(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed.wrapping_mul(0x2545_F491_4F6C_DD1D);
        (0..n)
            .map(|_| {
                s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
                let mut z = s;
                z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
                z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
                ((z ^ (z >> 31)) % 7) as f64 - 3.0
            })
            .collect()
    }

    mod prop {
        use super::super::*;
        use proptest::prelude::*;

        proptest! {
            /// The column-wise tally equals the row-by-row one, fed the same blocks: records of
            /// small integers (zeros and repeats on one channel common, on all of them in runs),
            /// with NaN.
            #[test]
            fn column_wise_tally_equals_the_row_by_row_one(
                nch in 2usize..6,
                rows in proptest::collection::vec((0u8..4, 0u8..10), 1..9000),
                blocks in proptest::collection::vec(1usize..5000, 1..6),
            ) {
                let mut ch: Vec<Vec<f64>> = vec![Vec::new(); nch];
                let mut last = vec![0.0; nch];
                for (i, &(kind, v)) in rows.iter().enumerate() {
                    for (c, col) in ch.iter_mut().enumerate() {
                        let x = match kind {
                            0 => 0.0,                                        // all zero
                            1 => last[c],                                    // all repeated
                            _ if v == 9 && c == 0 => f64::NAN,
                            _ => ((i * 7 + c * 3 + v as usize) % 5) as f64, // noise
                        };
                        col.push(x);
                        last[c] = x;
                    }
                }
                let n = rows.len();
                let (mut a, mut b) = (DropoutTally::new(nch), DropoutTally::new(nch));
                let mut at = 0;
                for &len in blocks.iter().cycle() {
                    if at >= n {
                        break;
                    }
                    let end = (at + len).min(n);
                    let refs: Vec<&[f64]> = ch.iter().map(|c| &c[at..end]).collect();
                    a.push_block(&refs);
                    b.push_rows(&refs);
                    at = end;
                }
                prop_assert_eq!(&a.zeros, &b.zeros);
                prop_assert_eq!(a.all_zero, b.all_zero);
                prop_assert_eq!(&a.rep, &b.rep);
                prop_assert_eq!(a.rep_skip, b.rep_skip);
                prop_assert_eq!(&a.skipped, &b.skipped);
                prop_assert_eq!(a.rows, b.rows);
                prop_assert_eq!(a.prev_zero, b.prev_zero);
                prop_assert_eq!(a.verdict(), b.verdict());
            }
        }

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(16))]
            /// A long record tallied in parallel parts equals one row-by-row pass (runs of zeros
            /// and repeats cross the parts' bounds).
            #[test]
            fn tally_in_parts_equals_one_pass(seed in 0u64..1000, run in 1usize..300) {
                let n = 70_001 + seed as usize;
                let ch: Vec<Vec<f64>> = (0..3)
                    .map(|c| {
                        (0..n)
                            .map(|i| {
                                let block = (i / run) as u64 ^ seed;
                                match block % 5 {
                                    0 => 0.0,
                                    1 => (block * 3 + c) as f64,
                                    _ => ((i as u64 * 2654435761 + c * 97 + seed) % 11) as f64,
                                }
                            })
                            .collect()
                    })
                    .collect();
                let refs: Vec<&[f64]> = ch.iter().map(|c| &c[..]).collect();
                let mut a = tally_in_parts(&refs);
                let mut b = DropoutTally::new(3);
                b.push_rows(&refs);
                // `hits` is the row-by-row pass's scratch, not a count.
                a.hits.fill(false);
                b.hits.fill(false);
                prop_assert_eq!(a, b);
            }
        }
    }

    #[test]
    fn mpu6050_like_zero_rows_are_found_exactly() {
        // Six LSB channels (accelerometer z reads about 16384 LSB = 1 g), 720 all-zero rows in
        // runs of 60 (a logger writing zeros while the I2C bus hangs).
        let n = 100_000;
        let mut ch: Vec<Vec<f64>> = (0..6).map(|c| quantized(n, c as u64 + 1)).collect();
        ch[5].iter_mut().for_each(|v| *v += 16384.0);
        let mut expected = Vec::new();
        for run in 0..12 {
            for i in 0..60 {
                let r = 5_000 + run * 8_000 + i;
                expected.push(r);
                ch.iter_mut().for_each(|c| c[r] = 0.0);
            }
        }
        let refs: Vec<&[f64]> = ch.iter().map(|c| &c[..]).collect();
        let d = find_dropouts(&refs);
        assert_eq!(d.all_zero, expected);
        // Within a run of zeros every row also repeats the one before: counted once, as zero.
        assert!(d.repeated.is_empty(), "{:?}", &d.repeated[..d.repeated.len().min(5)]);
    }

    #[test]
    fn quantized_channels_often_zero_give_no_false_dropouts() {
        let n = 200_000;
        let ch: Vec<Vec<f64>> = (0..3).map(|c| quantized(n, 40 + c as u64)).collect();
        let refs: Vec<&[f64]> = ch.iter().map(|c| &c[..]).collect();
        // About n / 7^3 = 583 rows are all zero by chance, and as many repeat: no dropouts.
        assert!(find_dropouts(&refs).is_empty());
    }

    #[test]
    fn repeated_rows_are_found() {
        // Four channels of 7 x 7 levels: about n / 49^4 = 0.01 rows repeat by chance.
        let n = 50_000;
        let mut ch: Vec<Vec<f64>> = (0..4)
            .map(|c| {
                quantized(n, 90 + c as u64).iter().zip(quantized(n, 190 + c as u64)).map(|(a, b)| a * 7.0 + b).collect()
            })
            .collect();
        for r in (1_000..n).step_by(1_000) {
            for c in &mut ch {
                c[r] = c[r - 1];
            }
        }
        let refs: Vec<&[f64]> = ch.iter().map(|c| &c[..]).collect();
        let d = find_dropouts(&refs);
        assert_eq!(d.repeated, (1_000..n).step_by(1_000).collect::<Vec<_>>());
    }

    #[test]
    fn blocks_of_any_size_give_the_whole_record_answer() {
        // Zero runs, single repeats and a repeat right after a zero run, fed in blocks of 1, 7
        // and 1000 rows: the verdict and the marked rows are those of the whole record.
        let n = 30_000;
        // 49 levels per channel; channel 0 never zero by chance.
        let mut ch: Vec<Vec<f64>> = (0..3)
            .map(|c| {
                quantized(n, 300 + c as u64)
                    .iter()
                    .zip(quantized(n, 400 + c as u64))
                    .map(|(a, b)| a * 7.0 + b)
                    .collect()
            })
            .collect();
        ch[0].iter_mut().for_each(|v| *v += 0.5);
        for r in (500..n).step_by(700) {
            for c in &mut ch {
                c[r] = c[r - 1];
            }
        }
        for r in (1_000..n).step_by(3_000) {
            for k in 0..5 {
                ch.iter_mut().for_each(|c| c[r + k] = 0.0);
            }
        }
        let refs: Vec<&[f64]> = ch.iter().map(|c| &c[..]).collect();
        let whole = find_dropouts(&refs);
        assert!(!whole.all_zero.is_empty() && !whole.repeated.is_empty());
        for size in [1usize, 7, 1000] {
            let mut tally = DropoutTally::new(3);
            for from in (0..n).step_by(size) {
                let to = (from + size).min(n);
                tally.push_block(&refs.iter().map(|c| &c[from..to]).collect::<Vec<_>>());
            }
            assert_eq!(tally.rows(), n as u64);
            let mut marker = DropoutMarker::new(tally.verdict());
            let mut d = Dropouts::default();
            for from in (0..n).step_by(size) {
                let to = (from + size).min(n);
                marker.mark_block(&refs.iter().map(|c| &c[from..to]).collect::<Vec<_>>(), |i, kind| match kind {
                    DropoutKind::AllZero => d.all_zero.push(from + i),
                    DropoutKind::Repeated => d.repeated.push(from + i),
                });
            }
            assert_eq!(d, whole, "blocks of {size}");
        }
    }
}
