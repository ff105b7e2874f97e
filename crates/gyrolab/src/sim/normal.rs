//! Standard normal draws in bulk: value for value, and word for word of the random stream, those
//! of `rand_distr::StandardNormal` on the same generator, at about half the cost.
//!
//! Source: the ziggurat method of Marsaglia & Tsang, "The Ziggurat Method for Generating Random
//! Variables", J. Stat. Software 5(8), 2000, as `rand_distr` 0.4 implements it (256 layers, one
//! 64-bit word per attempt: its low 8 bits pick the layer i, its high 52 bits give u in [-1, 1),
//! and x = u X_i is returned at once when |x| < X_(i+1), which is about 99 % of draws).
//!
//! This module performs that common case itself, on words read from the stream 1024 at a time
//! (a ChaCha stream's bytes, little-endian, are the words `next_u64` returns one at a time), and
//! hands every other case to `rand_distr` with the stream positioned at the same word: the
//! values and the words consumed are then `rand_distr`'s own. The layer bounds X_i are
//! `rand_distr`'s (a private table): read out of it once, by drawing with a word that makes
//! u = 2^-20, so that the value returned is exactly 2^-20 X_i. A test checks draws against
//! `rand_distr` on the same stream.

use std::sync::OnceLock;

use rand::RngCore;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// Words read from the stream at a time.
const WORDS: usize = 1024;
/// Exponent bits that put 52 mantissa bits into [2, 4) (rand_distr's conversion).
const EXPONENT_2_TO_4: u64 = 1024 << 52;

/// The layers of the ziggurat: the multiplier X_i and the bound X_(i+1) of each layer i (a bound
/// of 0 sends every draw of that layer to rand_distr; all values finite).
struct Layers {
    multiplier: [f64; 256],
    bound: [f64; 256],
}

/// The layers, read from rand_distr on first use.
fn layers() -> &'static Layers {
    static LAYERS: OnceLock<Layers> = OnceLock::new();
    LAYERS.get_or_init(|| {
        let mut x = [0.0; 256];
        for (i, xi) in x.iter_mut().enumerate() {
            *xi = layer_width(i);
        }
        let mut bound = [0.0; 256];
        // The top layer (i = 255) keeps bound 0: its bound X_256 is 0 in rand_distr, so it
        // never takes the common case there either; and its width X_255 cannot be read this way
        // (NaN), so layer 254 goes to rand_distr too.
        for i in 0..255 {
            // A width that could not be read (NaN) sends its layers to rand_distr.
            bound[i] = if x[i + 1].is_nan() { 0.0 } else { x[i + 1] };
        }
        // Finite multipliers only: a layer with bound 0 then never takes the common case.
        for xi in &mut x {
            if xi.is_nan() {
                *xi = 0.0;
            }
        }
        Layers { multiplier: x, bound }
    })
}

/// X_i of rand_distr's normal ziggurat: the value it returns for the word of layer i with
/// u = 2^-20 (accepted at once for every layer below the top one, since X_(i+1) > 2^-20 X_i),
/// times 2^20; NaN if that word was not accepted at once (the top layer, i = 255).
fn layer_width(i: usize) -> f64 {
    // 2 (1 + m / 2^52) = 3 + 2^-20 for m = 2^51 + 2^31.
    let word = (((1u64 << 51) + (1u64 << 31)) << 12) | i as u64;
    let mut one_word = OneWord { word, calls: 0 };
    let x: f64 = StandardNormal.sample(&mut one_word);
    if one_word.calls == 1 && x.is_finite() {
        x * 1_048_576.0
    } else {
        f64::NAN
    }
}

/// Fills `dest` with the little-endian bytes of `rng`'s next words (as a block generator does).
fn fill_by_words(rng: &mut impl RngCore, dest: &mut [u8]) {
    for chunk in dest.chunks_mut(8) {
        let w = rng.next_u64().to_le_bytes();
        chunk.copy_from_slice(&w[..chunk.len()]);
    }
}

/// A generator that returns one given word, then words accepted at once (layer 0, u = 0: the
/// value 0), and counts the words taken.
struct OneWord {
    word: u64,
    calls: u32,
}

impl RngCore for OneWord {
    fn next_u32(&mut self) -> u32 {
        self.next_u64() as u32
    }

    fn next_u64(&mut self) -> u64 {
        self.calls = self.calls.saturating_add(1);
        if self.calls == 1 {
            self.word
        } else {
            // 2 (1 + 2^51 / 2^52) - 3 = 0.
            (1u64 << 51) << 12
        }
    }

    fn fill_bytes(&mut self, dest: &mut [u8]) {
        fill_by_words(self, dest);
    }

    fn try_fill_bytes(&mut self, dest: &mut [u8]) -> Result<(), rand::Error> {
        self.fill_bytes(dest);
        Ok(())
    }
}

/// Standard normal draws from a ChaCha stream (see the module documentation).
#[derive(Debug, Clone)]
pub(super) struct NormalStream {
    rng: ChaCha8Rng,
    /// Words read from the stream and not used yet: `words[next..]`.
    words: Vec<u64>,
    next: usize,
    bytes: Vec<u8>,
}

impl NormalStream {
    /// Draws from `rng`, from its current position on.
    pub(super) fn new(rng: ChaCha8Rng) -> NormalStream {
        NormalStream { rng, words: Vec::new(), next: 0, bytes: vec![0; 8 * WORDS] }
    }

    /// Fills `out` with the next draws.
    pub(super) fn fill(&mut self, out: &mut [f64]) {
        let layers = layers();
        let mut filled = 0;
        while filled < out.len() {
            if self.next == self.words.len() {
                self.read_words();
            }
            // The common case, word after word.
            let n = (out.len() - filled).min(self.words.len() - self.next);
            let mut accepted = 0;
            for (x, &word) in out[filled..filled + n].iter_mut().zip(&self.words[self.next..self.next + n]) {
                let i = (word & 0xff) as usize;
                let u = f64::from_bits((word >> 12) | EXPONENT_2_TO_4) - 3.0;
                let value = u * layers.multiplier[i];
                if value.abs() >= layers.bound[i] {
                    break;
                }
                *x = value;
                accepted += 1;
            }
            self.next += accepted;
            filled += accepted;
            if accepted < n {
                // Any other case: rand_distr, from the same word on.
                let mut rest = WordsThenStream { words: &self.words[self.next..], used: 0, rng: &mut self.rng };
                out[filled] = StandardNormal.sample(&mut rest);
                filled += 1;
                self.next += rest.used.min(self.words.len() - self.next);
            }
        }
    }

    /// Replaces the (used up) words with the next `WORDS` of the stream.
    fn read_words(&mut self) {
        self.rng.fill_bytes(&mut self.bytes);
        self.words.clear();
        self.words.extend(
            self.bytes.chunks_exact(8).map(|b| u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]])),
        );
        self.next = 0;
    }
}

/// The words read ahead, then the stream itself.
struct WordsThenStream<'a> {
    words: &'a [u64],
    used: usize,
    rng: &'a mut ChaCha8Rng,
}

impl RngCore for WordsThenStream<'_> {
    fn next_u32(&mut self) -> u32 {
        // rand_distr's normal ziggurat takes whole words only; a half word is never asked for.
        self.next_u64() as u32
    }

    fn next_u64(&mut self) -> u64 {
        let w = match self.words.get(self.used) {
            Some(&w) => w,
            None => self.rng.next_u64(),
        };
        self.used += 1;
        w
    }

    fn fill_bytes(&mut self, dest: &mut [u8]) {
        fill_by_words(self, dest);
    }

    fn try_fill_bytes(&mut self, dest: &mut [u8]) -> Result<(), rand::Error> {
        self.fill_bytes(dest);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn draws_equal_rand_distr_on_the_same_stream() {
        for (seed, stream) in [(1u64, 0u64), (7, 0), (123_456_789, 3)] {
            let mut reference = ChaCha8Rng::seed_from_u64(seed);
            reference.set_stream(stream);
            let mut bulk = NormalStream::new(reference.clone());
            let mut drawn = Vec::new();
            // Uneven requests, so that requests end inside the words read ahead and fallbacks
            // cross the end of them.
            for n in [1usize, 5, 1000, 4096, 3, 100_000, 777, 200_001] {
                let mut part = vec![0.0; n];
                bulk.fill(&mut part);
                drawn.extend(part);
            }
            let want: Vec<f64> = (0..drawn.len()).map(|_| StandardNormal.sample(&mut reference)).collect();
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
            assert_eq!(bits(&drawn), bits(&want), "seed {seed}");
            // The streams are at the same place afterwards (words read ahead included).
            let mut after = vec![0.0; 10];
            bulk.fill(&mut after);
            let want_after: Vec<f64> = (0..10).map(|_| StandardNormal.sample(&mut reference)).collect();
            assert_eq!(bits(&after), bits(&want_after));
        }
    }

    #[test]
    fn hand_offs_past_the_words_read_ahead_go_on_with_the_stream() {
        // The last word read ahead is one rand_distr does not accept at once: layer 0 with u
        // near 1 (the tail: two or more further words) or layer 100 with u near 1 (the wedge
        // test: one or more further words). Layer 5 with u = 0 is accepted at once (value 0).
        let near_one = ((1u64 << 52) - 1) << 12;
        let accepted = ((1u64 << 51) << 12) | 5;
        for last in [near_one, near_one | 100] {
            let mut rng = ChaCha8Rng::seed_from_u64(5);
            let mut bulk = NormalStream::new(rng.clone());
            bulk.words = vec![accepted, last];
            bulk.next = 0;
            let mut drawn = vec![0.0; 50];
            bulk.fill(&mut drawn);
            let read_ahead = [accepted, last];
            let mut reference = WordsThenStream { words: &read_ahead, used: 0, rng: &mut rng };
            let want: Vec<f64> = (0..50).map(|_| StandardNormal.sample(&mut reference)).collect();
            assert!(reference.used > 3, "the hand-off took words from the stream");
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
            assert_eq!(bits(&drawn), bits(&want), "last word {last:#x}");
        }
    }

    #[test]
    fn layer_widths_are_read_for_every_layer_below_the_top() {
        let layers = layers();
        // X_1 is the ziggurat's tail start r = 3.654152885361008796 (Marsaglia & Tsang, 256 layers).
        assert!((layers.multiplier[1] - 3.654_152_885_361_009).abs() < 1e-15);
        for i in 0..254 {
            assert!(layers.bound[i] > 0.0 && layers.bound[i] < layers.multiplier[i], "layer {i}");
            assert_eq!(layers.bound[i], layers.multiplier[i + 1]);
        }
        // X_255 cannot be read (the top layer never accepts at once): the two top layers always
        // go to rand_distr (1 draw in 128).
        assert_eq!(layer_width(255).to_bits(), f64::NAN.to_bits());
        assert_eq!(layers.multiplier[255], 0.0);
        assert_eq!((layers.bound[254], layers.bound[255]), (0.0, 0.0));
    }
}
