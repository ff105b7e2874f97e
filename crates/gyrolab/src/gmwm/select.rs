//! Model choice of the GMWM: every subset of the linear processes, and models with one or two
//! first-order Gauss-Markov processes whose correlation times are profiled out; the model with the
//! smallest wavelet information criterion is chosen (docs/METHODS.md 3.1, "GMWM").
//!
//! Sources: the criterion is a prediction-accuracy criterion in the sense of the Wavelet
//! Variance Information Criterion (WVIC) of the GMWM authors (S. Guerrier and co-authors, SMAC
//! Group's gmwm tools): the objective plus its optimism, the expected excess of the objective on
//! new data over the objective at the estimate. The optimism is B. Efron's covariance penalty
//! ("The estimation of prediction error: covariance penalties and cross-validation", JASA
//! 99(467), 2004), 2 sum_j Omega_jj cov(nu_hat_j, nu_j(theta_hat)), taken to first order: 2
//! tr(Omega H Sigma), H = D (D' Omega D)^-1 D' Omega the fit's hat matrix and Sigma the wavelet
//! variances' covariance under the fitted model (2 x parameters when Omega = Sigma^-1, the AIC
//! penalty). The GMWM authors estimate the same optimism by simulation instead. The chosen
//! model's intervals of the linear processes are then averaged over the candidates the nesting
//! rule leaves (module `average`).

use super::{average, check, design, finish, fit_estimate, nnls, omega_variances};
use super::{CovarianceGrid, GmwmError, GmwmFit, Process, Shape, ShapeIntegrals, WaveletVariance, PROCESSES, ROUNDS};
use crate::allan::AllanCurve;
use rayon::prelude::*;
use std::sync::{Arc, Mutex};

/// The quadrature of a set of scales and the integrals of the linear processes on it: data
/// independent (they depend on the sample interval, each scale's averaging factor and number of
/// terms, and the processes), so made once per process and shared by every curve of that
/// shape: the channels of one record, the records of one length in a batch, a notebook's
/// repeated calls (issue 56). The last [`KEPT_TABLES`] sets are kept.
type Tables = (Arc<CovarianceGrid>, Arc<ShapeIntegrals>);

/// Sets of scales whose [`Tables`] are kept.
const KEPT_TABLES: usize = 8;

/// The [`Tables`] of `wv` and the linear processes `linear`, made or found.
fn linear_tables(wv: &[WaveletVariance], linear: &[Process]) -> Tables {
    type Key = (u64, Vec<(u64, u64)>, Vec<Process>);
    type Cell = Arc<std::sync::OnceLock<Tables>>;
    static KEPT: Mutex<Vec<(Key, Cell)>> = Mutex::new(Vec::new());
    let tau0 = wv.first().map_or(1.0, |w| w.tau_s / w.m as f64);
    let key: Key = (tau0.to_bits(), wv.iter().map(|w| (w.m, w.terms)).collect(), linear.to_vec());
    // The key's cell, found or added under the list's lock; filled outside it, once: the
    // channels of one record fitted side by side wait for the first to make it (no rayon work
    // runs inside, so a waiting worker cannot be asked for it again).
    let cell: Cell = match KEPT.lock() {
        Ok(mut kept) => match kept.iter().find(|(k, _)| *k == key) {
            Some((_, c)) => c.clone(),
            None => {
                if kept.len() >= KEPT_TABLES {
                    kept.remove(0);
                }
                let c: Cell = Arc::default();
                kept.push((key, c.clone()));
                c
            }
        },
        Err(_) => Arc::default(),
    };
    cell.get_or_init(|| {
        let grid = CovarianceGrid::new(wv);
        let shapes: Vec<Shape> = linear.iter().map(|&p| Shape::Linear(p)).collect();
        let integrals = ShapeIntegrals::new(&grid, &shapes);
        (Arc::new(grid), Arc::new(integrals))
    })
    .clone()
}

/// The most first-order Gauss-Markov processes a model holds in [`gmwm`].
pub const MAX_GAUSS_MARKOV: usize = 2;

/// Grid steps per octave of the correlation-time search (each point then refined within a step).
const GRID_PER_OCTAVE: f64 = 1.0;

/// Two Gauss-Markov processes are searched at least this many grid steps apart (a factor of 4
/// in T): closer, their sum is one process.
const MIN_GAP_STEPS: usize = 2;

/// Golden-section steps of each ln T refinement.
const GOLDEN_STEPS: usize = 24;

/// The GMWM fit with the model chosen by the criterion (objective + optimism, [`GmwmFit`]) over
/// every non-empty subset of the linear processes in `candidates` ([`Process::GaussMarkov`] in
/// it is ignored; see [`select_model_with_gauss_markov`]).
pub fn select_model(wv: &[WaveletVariance], candidates: &[Process], confidence: f64) -> Result<GmwmFit, GmwmError> {
    select_model_with_gauss_markov(wv, candidates, 0, confidence)
}

/// A model fitted for the comparison: its terms and weights, the variances of its Omega, the
/// range of correlation times searched, and which [`ShapeIntegrals`] hold its shapes.
struct Candidate {
    model: Vec<(Shape, f64)>,
    sigma2: Vec<f64>,
    search: (f64, f64),
    integrals: usize,
}

/// Every subset of the linear processes `linear` fitted (subsets whose fit drops the same
/// processes kept once), with the last error when none could be fitted.
fn linear_candidates(
    wv: &[WaveletVariance],
    grid: &CovarianceGrid,
    linear: &[Process],
    confidence: f64,
    integrals: usize,
    out: &mut Vec<Candidate>,
) -> Option<GmwmError> {
    let mut last_err = None;
    let mut seen: Vec<Vec<Process>> = Vec::new();
    // Every subset fitted in parallel, then taken in mask order (the same candidates, in the
    // same order, as one after another).
    let fitted: Vec<_> = (1u32..(1u32 << linear.len()))
        .into_par_iter()
        .map(|mask| {
            let set: Vec<Shape> = linear
                .iter()
                .enumerate()
                .filter(|(i, _)| mask & (1 << i) != 0)
                .map(|(_, &p)| Shape::Linear(p))
                .collect();
            fit_estimate(wv, grid, &set, confidence)
        })
        .collect();
    for fit in fitted {
        match fit {
            Ok((model, sigma2)) => {
                let kept: Vec<Process> = model.iter().map(|m| m.0.process()).collect();
                if kept.is_empty() || seen.contains(&kept) {
                    continue;
                }
                seen.push(kept);
                out.push(Candidate { model, sigma2, search: (0.0, f64::INFINITY), integrals });
            }
            Err(e) => last_err = Some(e),
        }
    }
    last_err
}

/// The GMWM fit with the model chosen by the criterion over the linear models of
/// [`select_model`] and the models of the linear processes in `candidates` (the flicker floor
/// left out: a sum of Gauss-Markov processes stands for bias instability there) plus one to
/// `max_gauss_markov` first-order Gauss-Markov processes. Their correlation times are searched
/// between the first and the last scale: a grid of one per octave (two processes at least two
/// octaves apart), then each ln T refined by golden section within a grid step, again after
/// each reweighting of Omega (at most [`MAX_GAUSS_MARKOV`] processes, whatever is asked); each
/// such model is then offered with every subset of the linear processes searched, the
/// correlation times held (every subset, not only of those the search's fit kept: that fit may
/// keep a drift where a random walk describes the curve as well).
pub fn select_model_with_gauss_markov(
    wv: &[WaveletVariance],
    candidates: &[Process],
    max_gauss_markov: usize,
    confidence: f64,
) -> Result<GmwmFit, GmwmError> {
    let linear: Vec<Process> = candidates.iter().copied().filter(|p| *p != Process::GaussMarkov).collect();
    let (grid, linear_integrals) = linear_tables(wv, &linear);
    let grid = &*grid;
    let mut integrals = vec![linear_integrals];
    let mut all = Vec::new();
    let max_gauss_markov = max_gauss_markov.min(MAX_GAUSS_MARKOV);
    let without_flicker: Vec<Process> = linear.iter().copied().filter(|p| *p != Process::Flicker).collect();
    // The linear models and the searches with 1 and 2 Gauss-Markov processes are independent:
    // made in parallel, then taken in that order.
    let (last_err, searched) = rayon::join(
        || {
            let mut linear_all = Vec::new();
            let err = linear_candidates(wv, grid, &linear, confidence, 0, &mut linear_all);
            (err, linear_all)
        },
        || {
            (1..=max_gauss_markov)
                .into_par_iter()
                .map(|k| {
                    let mut found = Vec::new();
                    let tables = gauss_markov_candidates(wv, grid, &without_flicker, k, confidence, &mut found);
                    (tables, found)
                })
                .collect::<Vec<_>>()
        },
    );
    let (last_err, linear_all) = last_err;
    all.extend(linear_all);
    for (tables, found) in searched {
        let Some(tables) = tables else { continue };
        integrals.push(Arc::new(tables));
        let index = integrals.len() - 1;
        all.extend(found.into_iter().map(|c| Candidate { integrals: index, ..c }));
    }
    let fits: Vec<_> = all
        .par_iter()
        .map(|c| finish(wv, &integrals[c.integrals], &c.model, &c.sigma2, confidence, c.search))
        .collect();
    // Smallest criterion first; a NaN criterion (none is expected) never stays chosen over a number.
    let better = |a: f64, b: f64| a < b - 1e-12 || (b.is_nan() && !a.is_nan());
    let mut best: Option<usize> = None;
    for (i, (fit, _)) in fits.iter().enumerate() {
        if best.is_none_or(|b| better(fit.criterion, fits[b].0.criterion)) {
            best = Some(i);
        }
    }
    match best {
        Some(b) => Ok(average::model_average(&fits, b)),
        None => Err(last_err.unwrap_or(GmwmError::TooFewScales { scales: wv.len(), parameters: 0 })),
    }
}

/// GMWM of an octave Allan curve with the model chosen over every process ([`PROCESSES`] and up
/// to [`MAX_GAUSS_MARKOV`] Gauss-Markov processes).
pub fn gmwm(curve: &AllanCurve, confidence: f64) -> Result<GmwmFit, GmwmError> {
    let wv = super::wavelet_variance(curve)?;
    select_model_with_gauss_markov(&wv, &PROCESSES, MAX_GAUSS_MARKOV, confidence)
}

/// The profile objective of the correlation times `ts` with the linear shapes: the non-negative
/// fit's objective, infinite when it drops a Gauss-Markov process.
fn profile(wv: &[WaveletVariance], linear: &[Shape], ts: &[f64], nu: &[f64], sigma2: &[f64]) -> f64 {
    let mut shapes = linear.to_vec();
    shapes.extend(ts.iter().map(|&t| Shape::GaussMarkov(t)));
    let x = design(wv, &shapes);
    let (kept, _, j) = nnls(&x, nu, sigma2);
    let all_markov = (linear.len()..shapes.len()).all(|c| kept.contains(&c));
    if all_markov {
        j
    } else {
        f64::INFINITY
    }
}

/// The models with `k` Gauss-Markov processes (correlation times searched) and each subset of
/// the linear processes `linear`, added to `out` (their `integrals` index left to the caller),
/// and their shapes' integrals returned; nothing when the record has too few scales or the
/// search's fit does not keep all `k` processes. A subset is offered only when the scales
/// outnumber its parameters (weights and correlation times).
fn gauss_markov_candidates(
    wv: &[WaveletVariance],
    grid: &CovarianceGrid,
    linear: &[Process],
    k: usize,
    confidence: f64,
    out: &mut Vec<Candidate>,
) -> Option<ShapeIntegrals> {
    let n = wv.len();
    check(wv, 2 * k + 1, confidence).ok()?;
    let (lo, hi) = (wv.first()?.tau_s, wv.last()?.tau_s);
    let steps = ((hi / lo).log2() * GRID_PER_OCTAVE).round() as usize;
    if steps < MIN_GAP_STEPS * (k - 1) {
        return None;
    }
    let times: Vec<f64> = (0..=steps).map(|i| lo * 2f64.powf(i as f64 / GRID_PER_OCTAVE)).collect();
    let lin: Vec<Shape> = linear.iter().map(|&p| Shape::Linear(p)).collect();
    let nu: Vec<f64> = wv.iter().map(|w| w.nu2).collect();
    let mut sigma2 = omega_variances(wv, grid, &[]);
    // The grid: every k-tuple of increasing indices at least MIN_GAP_STEPS apart.
    let mut best: Option<(f64, Vec<f64>)> = None;
    for idx in tuples(k, 0, steps) {
        let ts: Vec<f64> = idx.iter().map(|&i| times[i]).collect();
        let j = profile(wv, &lin, &ts, &nu, &sigma2);
        if j.is_finite() && best.as_ref().is_none_or(|b| j < b.0) {
            best = Some((j, ts));
        }
    }
    let mut ts = best?.1;
    let step = std::f64::consts::LN_2 / GRID_PER_OCTAVE;
    let mut model = Vec::new();
    for round in 0..ROUNDS {
        if round > 0 {
            sigma2 = omega_variances(wv, grid, &model);
        }
        for c in 0..k {
            // Two processes stay at least MIN_GAP_STEPS grid steps apart.
            let gap = MIN_GAP_STEPS as f64 * step;
            let below = if c == 0 { lo.ln() } else { ts[c - 1].ln() + gap };
            let above = if c + 1 == k { hi.ln() } else { ts[c + 1].ln() - gap };
            let (a, b) = ((ts[c].ln() - step).max(below), (ts[c].ln() + step).min(above));
            if a >= b {
                continue;
            }
            let mut trial = ts.clone();
            let mut eval = |x: f64| {
                trial[c] = x.exp();
                profile(wv, &lin, &trial, &nu, &sigma2)
            };
            ts[c] = golden_minimum(&mut eval, a, b, ts[c].ln()).exp();
        }
        let mut shapes = lin.clone();
        shapes.extend(ts.iter().map(|&t| Shape::GaussMarkov(t)));
        let x = design(wv, &shapes);
        let (kept, theta, _) = nnls(&x, &nu, &sigma2);
        model = kept.iter().zip(theta).map(|(&c, t)| (shapes[c], t)).collect();
    }
    if model.iter().filter(|m| matches!(m.0, Shape::GaussMarkov(_))).count() < k {
        return None;
    }
    // Every subset of the linear processes searched, not only of those the search's fit kept (it
    // may keep a drift where a random walk describes the curve as well: the two are close at the
    // last scales), the correlation times held; judged by the criterion with the other candidates.
    let markov: Vec<Shape> = model.iter().map(|m| m.0).filter(|s| matches!(s, Shape::GaussMarkov(_))).collect();
    let mut all = lin.clone();
    all.extend(&markov);
    let integrals = ShapeIntegrals::new(grid, &all);
    let mut seen: Vec<Vec<Shape>> = Vec::new();
    for mask in 0u32..(1u32 << lin.len()) {
        let mut shapes: Vec<Shape> =
            lin.iter().enumerate().filter(|(i, _)| mask & (1 << i) != 0).map(|(_, &s)| s).collect();
        shapes.extend(&markov);
        if n <= shapes.len() + k {
            continue;
        }
        let Ok((m, s2)) = fit_estimate(wv, grid, &shapes, confidence) else { continue };
        let kept: Vec<Shape> = m.iter().map(|x| x.0).collect();
        if kept.iter().filter(|x| matches!(x, Shape::GaussMarkov(_))).count() < k || seen.contains(&kept) {
            continue;
        }
        seen.push(kept);
        out.push(Candidate { model: m, sigma2: s2, search: (lo, hi), integrals: usize::MAX });
    }
    Some(integrals)
}

/// Every k-tuple of increasing grid indices from `first` to `last`, at least [`MIN_GAP_STEPS`]
/// apart.
fn tuples(k: usize, first: usize, last: usize) -> Vec<Vec<usize>> {
    if k == 0 {
        return vec![Vec::new()];
    }
    let mut out = Vec::new();
    for i in first..=last {
        for mut rest in tuples(k - 1, i + MIN_GAP_STEPS, last) {
            rest.insert(0, i);
            out.push(rest);
        }
        if i + MIN_GAP_STEPS > last && k > 1 {
            break;
        }
    }
    out
}

/// The minimum of `f` over [a, b] by golden-section search, the ends and `start` also tried (a
/// minimum at an end is returned exactly there).
fn golden_minimum(f: &mut impl FnMut(f64) -> f64, a: f64, b: f64, start: f64) -> f64 {
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let (a0, b0) = (a, b);
    let (mut a, mut b) = (a, b);
    let mut c = b - r * (b - a);
    let mut d = a + r * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..GOLDEN_STEPS {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - r * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + r * (b - a);
            fd = f(d);
        }
    }
    let mut best = (start, f(start));
    for x in [c, d, a0, b0] {
        let fx = if x == c {
            fc
        } else if x == d {
            fd
        } else {
            f(x)
        };
        if fx < best.1 {
            best = (x, fx);
        }
    }
    best.0
}
