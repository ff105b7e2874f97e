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
    // One pass per test: each channel's hits and the rows hit on every channel; dropouts when
    // those are far more than independent channels would give (`beyond_chance`).
    fn scan(
        channels: &[&[f64]],
        n: usize,
        hit: impl Fn(&[f64], usize) -> bool,
        skip: impl Fn(usize) -> bool,
    ) -> Vec<usize> {
        let mut per = vec![0u64; channels.len()];
        let mut rows = Vec::new();
        let mut considered = 0u64;
        for i in 0..n {
            if skip(i) {
                continue;
            }
            considered += 1;
            let mut all = true;
            for (c, count) in channels.iter().zip(per.iter_mut()) {
                let h = hit(c, i);
                *count += u64::from(h);
                all &= h;
            }
            if all {
                rows.push(i);
            }
        }
        if beyond_chance(rows.len() as u64, considered, &per) {
            rows
        } else {
            Vec::new()
        }
    }
    let all_zero = scan(channels, n, |c, i| c[i] == 0.0, |_| false);
    // Repeats are looked for among the other rows (a run of zeros repeats itself).
    let mut zero_or_after = vec![false; if all_zero.is_empty() { 0 } else { n }];
    for &i in &all_zero {
        zero_or_after[i] = true;
        if i + 1 < n {
            zero_or_after[i + 1] = true;
        }
    }
    let repeated =
        scan(channels, n, |c, i| i > 0 && c[i] == c[i - 1], |i| zero_or_after.get(i).copied().unwrap_or(false));
    Dropouts { all_zero, repeated }
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
}
