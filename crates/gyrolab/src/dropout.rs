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
    /// Repeats over rows neither all zero nor after an all-zero row.
    rep_skip: (u64, Vec<u64>, u64),
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
            rep_skip: (0, vec![0; channels], 0),
            prev: Vec::new(),
            prev_zero: false,
            hits: vec![false; channels],
        }
    }

    /// Adds the rows of a block, one slice per channel (equal lengths; the rows follow those
    /// of the previous block).
    pub fn push_block(&mut self, channels: &[&[f64]]) {
        let nch = self.zeros.len();
        if channels.len() != nch || nch == 0 {
            return;
        }
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
                for (r, &h) in self.rep_skip.1.iter_mut().zip(&self.hits) {
                    *r += u64::from(h);
                }
                self.rep_skip.2 += u64::from(all_rep);
            }
            self.prev.clear();
            self.prev.extend(channels.iter().map(|c| c[i]));
            self.prev_zero = all_zero;
            self.rows += 1;
        }
    }

    /// Rows tallied.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// The verdict of the module's rule ([`beyond_chance`] for all-zero rows, then for repeated
    /// rows among the rows that remain).
    pub fn verdict(&self) -> DropoutVerdict {
        let all_zero = beyond_chance(self.all_zero, self.rows, &self.zeros);
        let (considered, per, hits) = if all_zero { &self.rep_skip } else { &self.rep };
        DropoutVerdict { all_zero, repeated: beyond_chance(*hits, *considered, per) }
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
    let mut tally = DropoutTally::new(channels.len());
    tally.push_block(&channels);
    let mut d = Dropouts::default();
    DropoutMarker::new(tally.verdict()).mark_block(&channels, |i, kind| match kind {
        DropoutKind::AllZero => d.all_zero.push(i),
        DropoutKind::Repeated => d.repeated.push(i),
    });
    d
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
