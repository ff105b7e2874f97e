//! Model-averaged intervals of the GMWM's linear processes over the candidate models of the model
//! choice (docs/METHODS.md 3.1, "Model averaging").
//!
//! Sources: S. T. Buckland, K. P. Burnham and N. H. Augustin, "Model selection: an integral part
//! of inference", Biometrics 53(2), 1997 (model weights exp(-Delta_m / 2) from an information
//! criterion, Delta_m its excess over the smallest); D. Turek and D. Fletcher, "Model-averaged
//! Wald confidence intervals", Computational Statistics & Data Analysis 56(9), 2012 (the MATA-Wald
//! interval: the limits where the weighted mixture of the candidates' normal sampling distributions
//! reaches alpha / 2 and 1 - alpha / 2). Both papers average a parameter every candidate holds;
//! here a candidate without the process enters as a point mass at zero (this project's convention:
//! the limit of a candidate that fixes the weight at zero with no error), so a term that only some
//! candidates hold gets an interval reaching zero. A term the chosen model leaves out gets an upper
//! bound given that it is there: the 1 - alpha / 2 quantile of the mixture of the candidates
//! holding it alone, their weights renormalised (the point masses of the others dropped; a bound
//! from the whole mixture sits below the holding candidates' median once they weigh under about
//! 0.32 and missed the truth in most records of a term that is there but rarely chosen). Some zeros
//! are structural: the flicker floor is not offered beside Gauss-Markov processes, which stand for
//! it there. Intervals after a model choice that ignore it cover less than their level (the
//! choice drops a term in some records, and the sampling spread of the chosen model's estimate is
//! conditional on that choice); the mixture puts the choice's own uncertainty into the interval.
//!
//! The intervals of the terms the chosen model holds average only the candidates the nesting rule
//! leaves: S. A. Richards, "Dealing with overdispersed data in applied ecology", Journal of Applied
//! Ecology 45(1), 2008, and T. W. Arnold, "Uninformative parameters and model selection using
//! Akaike's Information Criterion", Journal of Wildlife Management 74(6), 2010: a candidate is
//! dropped when a simpler candidate nested in it has a criterion as small or smaller, its extra
//! terms uninformative (a term that lowers the objective by less than its optimism costs). Without
//! the rule the candidates holding a spurious term beside the true ones (quantization beside white
//! noise, a Gauss-Markov process beside a drift) take weight with their wider sampling
//! distributions, and the intervals over-covered (docs/METHODS.md 3.1).

use super::{GmwmBound, GmwmFit, Process};
use statrs::function::erf::erfc;

/// A linear process's weight (squared coefficient) in one candidate's fit and its standard error
/// (from the candidate's sandwich covariance).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Moment {
    /// The process.
    pub process: Process,
    /// Its fitted weight (squared coefficient), (curve unit)^2 per its shape.
    pub weight: f64,
    /// The weight's standard error (NaN when the covariance could not be made).
    pub se: f64,
}

/// The model weights exp(-(c_m - c_min) / 2) of criteria `c_m`, normalised to sum 1 (Buckland,
/// Burnham and Augustin 1997); 0 for a criterion that is not finite, all 0 when none is.
///
/// ```
/// let w = gyrolab::gmwm::model_weights(&[10.0, 12.0, f64::INFINITY]);
/// // exp(-1) / (1 + exp(-1)) = 0.2689...
/// assert!((w[1] - 0.268_941_421_369_995).abs() < 1e-12);
/// assert_eq!(w[2], 0.0);
/// assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
/// ```
pub fn model_weights(criteria: &[f64]) -> Vec<f64> {
    let best = criteria.iter().copied().filter(|c| c.is_finite()).fold(f64::INFINITY, f64::min);
    if !best.is_finite() {
        return vec![0.0; criteria.len()];
    }
    let raw: Vec<f64> = criteria.iter().map(|&c| if c.is_finite() { (-(c - best) / 2.0).exp() } else { 0.0 }).collect();
    let total: f64 = raw.iter().sum();
    raw.iter().map(|r| r / total).collect()
}

/// A mixture of normal distributions (weight, mean, standard deviation) and point masses
/// (weight, location).
#[derive(Default)]
struct Mixture {
    normals: Vec<(f64, f64, f64)>,
    points: Vec<(f64, f64)>,
}

impl Mixture {
    /// The mixture's distribution function at `x`; `strict` counts the point masses below `x` only.
    fn cdf(&self, x: f64, strict: bool) -> f64 {
        let normal: f64 =
            self.normals.iter().map(|&(w, m, s)| w * 0.5 * erfc(-(x - m) / (s * std::f64::consts::SQRT_2))).sum();
        let points: f64 = self.points.iter().filter(|p| if strict { p.1 < x } else { p.1 <= x }).map(|p| p.0).sum();
        normal + points
    }

    /// The smallest x with cdf(x) >= q (q in (0, 1), the weights summing to 1): an atom when the
    /// distribution jumps over q there, else by bisection of the continuous part between atoms.
    fn quantile(&self, q: f64) -> f64 {
        for &(_, at) in &self.points {
            if self.cdf(at, true) < q && self.cdf(at, false) >= q {
                return at;
            }
        }
        let spread = |sign: f64| {
            let normals = self.normals.iter().map(|&(_, m, s)| m + sign * 40.0 * s);
            let points = self.points.iter().map(|p| p.1);
            normals.chain(points).fold(0.0, |a: f64, b| if sign < 0.0 { a.min(b) } else { a.max(b) })
        };
        let (mut lo, mut hi) = (spread(-1.0), spread(1.0));
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if self.cdf(mid, false) >= q {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        hi
    }
}

/// The chosen candidate `chosen` of `fits` with its linear processes' intervals replaced by the
/// model-averaged (MATA-Wald) intervals over the candidates the nesting rule leaves (weights
/// [`model_weights`] of [`nesting_rule`]'s criteria), each parameter's
/// [`GmwmParameter::model_weight`](super::GmwmParameter) set from those weights, and the bounds of
/// the processes it leaves out in [`GmwmFit::left_out`]. A bound is given that the term is there,
/// so every candidate holding it takes part with its plain weight: the rule is not applied, since
/// it drops exactly the candidates that judge the term unsupported. Gauss-Markov parameters keep the
/// chosen model's intervals (their correlation times differ between candidates, so they are not
/// one parameter across them). On the weight scale (squared coefficient), then square-rooted, as
/// the single-model intervals are.
pub(crate) fn model_average(fits: &[(GmwmFit, Vec<Moment>)], chosen: usize) -> GmwmFit {
    let mut out = fits[chosen].0.clone();
    let criteria: Vec<f64> = fits.iter().map(|f| f.0.criterion).collect();
    let all_weights = model_weights(&criteria);
    // One candidate with all the weight (the others' criteria more than about 1,490 above): its
    // own intervals, unchanged.
    if all_weights.iter().filter(|w| **w > 0.0).count() <= 1 {
        return out;
    }
    // The intervals of the terms it holds: the candidates the nesting rule leaves (`nesting_rule`).
    let weights = model_weights(&nesting_rule(fits, chosen));
    let alpha = 1.0 - out.confidence;
    let mut processes: Vec<Process> = Vec::new();
    for m in fits.iter().flat_map(|f| &f.1) {
        if !processes.contains(&m.process) {
            processes.push(m.process);
        }
    }
    let markov_weight: f64 = fits
        .iter()
        .zip(&weights)
        .filter(|(f, _)| f.0.parameters.iter().any(|p| p.process == Process::GaussMarkov))
        .map(|(_, w)| w)
        .sum();
    for p in out.parameters.iter_mut().filter(|p| p.process == Process::GaussMarkov) {
        p.model_weight = markov_weight;
    }
    for process in super::PROCESSES.iter().copied().filter(|p| processes.contains(p)) {
        // `held`: the candidates holding the process, with their model weights.
        let holders = |weights: &[f64]| {
            let mut held = Mixture::default();
            let (mut holding, mut absent) = (0.0, 0.0);
            for ((_, moments), &w) in fits.iter().zip(weights) {
                if w == 0.0 {
                    continue;
                }
                match moments.iter().find(|m| m.process == process) {
                    Some(m) if m.se.is_finite() && m.se > 0.0 => held.normals.push((w, m.weight, m.se)),
                    Some(m) => held.points.push((w, m.weight)),
                    None => {
                        absent += w;
                        continue;
                    }
                }
                holding += w;
            }
            (held, holding, absent)
        };
        match out.parameters.iter_mut().find(|p| p.process == process) {
            Some(p) => {
                let (held, holding, absent) = holders(&weights);
                let mut mixture = Mixture { normals: held.normals.clone(), points: held.points.clone() };
                if absent > 0.0 {
                    mixture.points.push((absent, 0.0));
                }
                p.lower = mixture.quantile(alpha / 2.0).max(0.0).sqrt();
                p.upper = mixture.quantile(1.0 - alpha / 2.0).max(0.0).sqrt();
                p.model_weight = holding;
            }
            None => {
                let (held, holding, _) = holders(&all_weights);
                if holding <= 0.0 {
                    continue;
                }
                // The bound given that the term is there: the candidates holding it, their weights
                // renormalised to sum 1.
                let present = Mixture {
                    normals: held.normals.iter().map(|&(w, m, s)| (w / holding, m, s)).collect(),
                    points: held.points.iter().map(|&(w, at)| (w / holding, at)).collect(),
                };
                let upper = present.quantile(1.0 - alpha / 2.0);
                if upper > 0.0 {
                    out.left_out.push(GmwmBound { process, upper: upper.sqrt(), model_weight: holding });
                }
            }
        }
    }
    out
}

/// The candidates' criteria with the nesting rule applied (Richards 2008; Arnold 2010): a candidate
/// that a strictly simpler candidate nested in it matches or beats on the criterion is set to
/// infinity (weight 0), its extra terms uninformative. The chosen candidate `chosen` is never
/// removed, not even by a simpler one whose criterion ties with it (the model choice keeps the
/// first of candidates within 1e-12 of the smallest).
///
/// A candidate `a` is nested in `b` when a's linear processes are a subset of b's and it holds no
/// more Gauss-Markov processes (b with the extra weights at zero is a), the two not the same.
pub(crate) fn nesting_rule(fits: &[(GmwmFit, Vec<Moment>)], chosen: usize) -> Vec<f64> {
    let structures: Vec<(Vec<Process>, usize)> = fits.iter().map(|f| structure(&f.0)).collect();
    fits.iter()
        .zip(&structures)
        .enumerate()
        .map(|(i, ((fit, _), own))| {
            let c = fit.criterion;
            let dominated = i != chosen
                && fits.iter().zip(&structures).any(|((simpler, _), s)| nested_in(s, own) && simpler.criterion <= c);
            if dominated {
                f64::INFINITY
            } else {
                c
            }
        })
        .collect()
}

/// A candidate's structure: its linear processes and how many Gauss-Markov processes it holds.
fn structure(fit: &GmwmFit) -> (Vec<Process>, usize) {
    let linear = fit.parameters.iter().map(|p| p.process).filter(|p| *p != Process::GaussMarkov).collect();
    let markov = fit.parameters.iter().filter(|p| p.process == Process::GaussMarkov).count();
    (linear, markov)
}

/// Whether structure `a` is a strict simplification of `b`: its linear processes a subset of b's and
/// no more Gauss-Markov processes, not the same.
fn nested_in(a: &(Vec<Process>, usize), b: &(Vec<Process>, usize)) -> bool {
    a.1 <= b.1 && a.0.iter().all(|p| b.0.contains(p)) && (a.0.len() < b.0.len() || a.1 < b.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fit(criterion: f64, params: &[Process]) -> GmwmFit {
        GmwmFit {
            parameters: params
                .iter()
                .map(|&process| super::super::GmwmParameter {
                    process,
                    value: 1.0,
                    lower: 0.5,
                    upper: 1.5,
                    correlation_time: None,
                    model_weight: 1.0,
                })
                .collect(),
            confidence: 0.683,
            scales: 10,
            objective: criterion,
            optimism: 0.0,
            criterion,
            weighted_rms_residual: 1.0,
            quality: crate::noise::FitQuality::Acceptable,
            left_out: Vec::new(),
        }
    }

    /// Two candidates, neither nested in the other, criteria 0 and 1 (weights 0.62246 and
    /// 0.37754): white noise in both (weights 100 +- 2 and 98 +- 3), quantization only in the first,
    /// a random walk only in the second (4 +- 1). The chosen model's white-noise interval is the
    /// mixture's 15.85 % and 84.15 % quantiles, computed independently with Python's
    /// statistics.NormalDist (bisection of the mixture); the random walk's bound is the 84.15 %
    /// quantile given the term is there, the second candidate's alone: sqrt(4 + inv_cdf(0.8415)).
    #[test]
    fn mixture_intervals_and_bounds_by_an_independent_computation() {
        let fits = vec![
            (
                fit(0.0, &[Process::White, Process::Quantization]),
                vec![
                    Moment { process: Process::White, weight: 100.0, se: 2.0 },
                    Moment { process: Process::Quantization, weight: 1.0, se: 0.5 },
                ],
            ),
            (
                fit(1.0, &[Process::White, Process::RandomWalk]),
                vec![
                    Moment { process: Process::White, weight: 98.0, se: 3.0 },
                    Moment { process: Process::RandomWalk, weight: 4.0, se: 1.0 },
                ],
            ),
        ];
        let out = model_average(&fits, 0);
        let white = out.parameter(Process::White).unwrap();
        assert_eq!(white.value, 1.0);
        assert!((white.lower - 9.835_060_649_085_486).abs() < 1e-9, "{white:?}");
        assert!((white.upper - 10.087_186_915_682_034).abs() < 1e-9, "{white:?}");
        assert_eq!(white.model_weight, 1.0);
        assert_eq!(out.left_out.len(), 1);
        let k = out.left_out[0];
        assert_eq!(k.process, Process::RandomWalk);
        assert!((k.upper - 2.236_211_490_168_684_7).abs() < 1e-9, "{k:?}");
        assert!((k.model_weight - 0.377_540_668_798_145_46).abs() < 1e-12);
        // However little the models holding it weigh, the bound given it is there is the same.
        let mut far = fits.clone();
        far[1].0.criterion = 12.0;
        let k = model_average(&far, 0).left_out[0];
        assert!((k.upper - 2.236_211_490_168_684_7).abs() < 1e-9, "{k:?}");
        assert!(k.model_weight < 0.003, "{k:?}");
        // A process only candidates of weight 0 hold (criterion not finite) gets no bound.
        let mut ruled_out = fits.clone();
        ruled_out[1].0.criterion = f64::INFINITY;
        ruled_out.push((fit(0.5, &[Process::White]), vec![Moment { process: Process::White, weight: 99.0, se: 2.0 }]));
        let out = model_average(&ruled_out, 0);
        assert!(out.left_out.is_empty(), "{out:?}");
        assert!(out.parameter(Process::White).unwrap().upper > 1.5, "the averaging ran: {out:?}");
    }

    /// Three candidates, criteria 0, 1 and 2, the random walk in the second (4 +- 1) and third
    /// (6 +- 2): the bound is the 84.15 % quantile of their mixture with the weights exp(-1/2) and
    /// exp(-1) renormalised, by bisection with Python's statistics.NormalDist (sqrt of 6.4630...).
    #[test]
    fn the_bound_of_a_left_out_term_mixes_the_candidates_holding_it() {
        let white = |w: f64| Moment { process: Process::White, weight: w, se: 2.0 };
        let walk = |w: f64, se: f64| Moment { process: Process::RandomWalk, weight: w, se };
        let both = [Process::White, Process::RandomWalk];
        let fits = vec![
            (fit(0.0, &[Process::White]), vec![white(100.0)]),
            (fit(1.0, &both), vec![white(98.0), walk(4.0, 1.0)]),
            (fit(2.0, &both), vec![white(97.0), walk(6.0, 2.0)]),
        ];
        let k = model_average(&fits, 0).left_out[0];
        assert!((k.upper - 2.542_242_150_765_753).abs() < 1e-9, "{k:?}");
        assert!((k.model_weight - 0.493_519_608_944_346).abs() < 1e-12, "{k:?}");
    }

    /// The nesting rule by hand. Candidates: {white, random walk} chosen (criterion 0; 100 +- 2
    /// and 4 +- 1), {white, random walk, quantization} (1.5; 95 +- 6, 4 +- 1, 1 +- 1), {white}
    /// (3; 104 +- 2). The second holds the first, which has the smaller criterion: it is dropped, and
    /// the weights are exp(0) and exp(-1.5) renormalised (0.81757, 0.18243). White noise's interval
    /// is the mixture of N(100, 2) and N(104, 2) at 15.85 % and 84.15 % (bisection with Python's
    /// statistics.NormalDist: sqrt of 98.2691... and 103.2754...; with the second candidate in, the
    /// lower end would be 9.7774); the random walk's lower end is the atom of {white} (0.18 > alpha
    /// / 2), its upper end sqrt(4.8637...); quantization, left out, is bounded given that it is there
    /// from the dropped candidate (the rule does not apply to bounds): sqrt(1 + Phi^-1(0.84150)).
    #[test]
    fn the_nesting_rule_drops_a_candidate_whose_extra_term_does_not_pay() {
        let moment = |process, weight, se| Moment { process, weight, se };
        let (w, k, q) = (Process::White, Process::RandomWalk, Process::Quantization);
        let fits = vec![
            (fit(0.0, &[w, k]), vec![moment(w, 100.0, 2.0), moment(k, 4.0, 1.0)]),
            (fit(1.5, &[w, k, q]), vec![moment(w, 95.0, 6.0), moment(k, 4.0, 1.0), moment(q, 1.0, 1.0)]),
            (fit(3.0, &[w]), vec![moment(w, 104.0, 2.0)]),
        ];
        let criteria = nesting_rule(&fits, 0);
        assert_eq!(criteria, vec![0.0, f64::INFINITY, 3.0]);
        let out = model_average(&fits, 0);
        let white = out.parameter(w).unwrap();
        assert!((white.lower - 9.913_079_280_965_471).abs() < 1e-9, "{white:?}");
        assert!((white.upper - 10.162_450_359_866_316).abs() < 1e-9, "{white:?}");
        assert!((white.model_weight - 1.0).abs() < 1e-12, "{white:?}");
        let walk = out.parameter(k).unwrap();
        assert_eq!(walk.lower, 0.0);
        assert!((walk.upper - 2.205_388_224_947_014).abs() < 1e-9, "{walk:?}");
        assert!((walk.model_weight - 0.817_574_476_193_643_7).abs() < 1e-12, "{walk:?}");
        let bound = out.left_out.iter().find(|b| b.process == q).expect("a bound given presence");
        assert!((bound.upper - 1.414_440_464_905_628).abs() < 1e-9, "{bound:?}");
        // Its weight is the one the bound was made with, before the rule (exp(-0.75) of the three).
        let plain = model_weights(&[0.0, 1.5, 3.0]);
        assert!((bound.model_weight - plain[1]).abs() < 1e-12, "{bound:?}");
    }

    /// A simpler candidate whose criterion ties with the chosen one's does not drop it: both keep
    /// their weight, 1/2 each (the random walk's weight), and the white noise's interval mixes
    /// N(100, 2) and N(104, 2) equally (bisection with Python's statistics.NormalDist: sqrt of
    /// 99.01217 and 104.98783).
    #[test]
    fn the_chosen_candidate_is_never_dropped() {
        let moment = |process, weight, se| Moment { process, weight, se };
        let (w, k) = (Process::White, Process::RandomWalk);
        let fits = vec![
            (fit(0.0, &[w, k]), vec![moment(w, 100.0, 2.0), moment(k, 4.0, 1.0)]),
            (fit(0.0, &[w]), vec![moment(w, 104.0, 2.0)]),
        ];
        assert_eq!(nesting_rule(&fits, 0), vec![0.0, 0.0]);
        // Were the second chosen, the first would go.
        assert_eq!(nesting_rule(&fits, 1), vec![f64::INFINITY, 0.0]);
        let out = model_average(&fits, 0);
        assert!((out.parameter(k).unwrap().model_weight - 0.5).abs() < 1e-12, "{out:?}");
        let white = out.parameter(w).unwrap();
        assert!((white.lower - 9.950_485_851_383_537).abs() < 1e-9, "{white:?}");
        assert!((white.upper - 10.246_356_978_039_369).abs() < 1e-9, "{white:?}");
    }

    /// Nesting counts Gauss-Markov processes: {white, GM} is nested in {white, GM, random walk}
    /// and in {white, GM, GM}; {white, flicker} is not nested in {white, GM}, and no structure is
    /// nested in itself.
    #[test]
    fn nesting_counts_gauss_markov_processes() {
        let (w, gm) = (Process::White, Process::GaussMarkov);
        let s = |p: &[Process]| structure(&fit(0.0, p));
        assert!(nested_in(&s(&[w, gm]), &s(&[w, gm, Process::RandomWalk])));
        assert!(nested_in(&s(&[w, gm]), &s(&[w, gm, gm])));
        assert!(!nested_in(&s(&[w, gm, gm]), &s(&[w, gm, Process::RandomWalk])));
        assert!(!nested_in(&s(&[w, Process::Flicker]), &s(&[w, gm])));
        assert!(!nested_in(&s(&[w, gm]), &s(&[w, gm])));
        assert!(nested_in(&s(&[w]), &s(&[w, gm])));
    }

    /// One normal component: the quantiles are the normal's (Phi^-1(0.975) = 1.959963984540054).
    #[test]
    fn one_normal_gives_its_own_quantiles() {
        let m = Mixture { normals: vec![(1.0, 5.0, 2.0)], points: Vec::new() };
        assert!((m.quantile(0.975) - (5.0 + 2.0 * 1.959_963_984_540_054)).abs() < 1e-9);
        assert!((m.quantile(0.5) - 5.0).abs() < 1e-9);
    }

    /// Weight 0.6 at zero and 0.4 on N(10, 1): the 84.15 % quantile solves 0.6 + 0.4 Phi(x - 10)
    /// = 0.8415, x = 10 + Phi^-1(0.60375) = 10.263066 (Python's
    /// statistics.NormalDist().inv_cdf); the 15.85 % quantile is the atom at 0.
    #[test]
    fn an_atom_at_zero_and_a_normal_by_hand() {
        let m = Mixture { normals: vec![(0.4, 10.0, 1.0)], points: vec![(0.6, 0.0)] };
        assert_eq!(m.quantile(0.1585), 0.0);
        let x = m.quantile(0.8415);
        let phi = 0.5 * erfc(-(x - 10.0) / std::f64::consts::SQRT_2);
        assert!((0.6 + 0.4 * phi - 0.8415).abs() < 1e-12);
        assert!((x - 10.263_065_622_801_887).abs() < 1e-9, "{x}");
        // Below the atom's weight the upper quantile is the atom (an interval's upper end 0).
        let m = Mixture { normals: vec![(0.1, 10.0, 1.0)], points: vec![(0.9, 0.0)] };
        assert_eq!(m.quantile(0.8415), 0.0);
    }
}
