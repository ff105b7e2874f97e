//! GMWM against simulated truth beside the slope readings and the five-term fit (bench/gmwm_study.sh;
//! the table goes into docs/METHODS.md section 3.1): three composite models, SEEDS seeds each, the
//! bias and RMSE of each parameter relative to the truth, how often the slope lines resolve it, and
//! the coverage of the GMWM intervals at 68.3 % two-sided.
//!
//! Usage: gmwm_study [SEEDS] [HOURS] (defaults 100 seeds, 10 h at 10 Hz).

use gyrolab::allan::{deviation_from_rate, AllanOptions, DeviationKind, TauList};
use gyrolab::gmwm::{gmwm, Process};
use gyrolab::noise::{fit_noise_model, slope_line_terms};
use gyrolab::sim::{SensorModel, StaticBlock, StaticGenerator, StaticSpec};

/// A term of the study: its process, its truth in base units, and how to read it from the
/// slope lines and the fit (deg/sqrt(s), deg/s, deg/s/sqrt(s), deg, deg/s^2).
#[derive(Clone, Copy)]
struct Term {
    name: &'static str,
    process: Process,
    truth: f64,
}

#[derive(Default, Clone)]
struct Stats {
    n: usize,
    sum: f64,
    sum2: f64,
}

impl Stats {
    fn add(&mut self, rel: f64) {
        self.n += 1;
        self.sum += rel;
        self.sum2 += rel * rel;
    }
    fn text(&self) -> String {
        if self.n == 0 {
            return "-".into();
        }
        let bias = self.sum / self.n as f64;
        let rmse = (self.sum2 / self.n as f64).sqrt();
        format!("{:+.1} % / {:.1} % ({})", 100.0 * bias, 100.0 * rmse, self.n)
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seeds: u64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(100);
    let hours: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(10.0);
    let rate = 10.0;
    let dps_rt_s = |deg_rt_h: f64| deg_rt_h / 60.0;
    let dps = |dph: f64| dph / 3600.0;
    let k_base = |dph_rt_h: f64| dph_rt_h / 3600.0 / 60.0;
    let r_base = |dph_per_h: f64| dph_per_h / 3600.0 / 3600.0;
    type Setup = (&'static str, fn(&mut SensorModel), Vec<Term>);
    let models: Vec<Setup> = vec![
        (
            "A: white + random walk (N 0.25 deg/sqrt(h), K 6 deg/h/sqrt(h))",
            |m| {
                m.arw_deg_rt_h = 0.25;
                m.rrw_deg_h_rt_h = 6.0;
            },
            vec![
                Term { name: "N", process: Process::White, truth: dps_rt_s(0.25) },
                Term { name: "K", process: Process::RandomWalk, truth: k_base(6.0) },
            ],
        ),
        (
            "B: white + bias instability (flicker) + random walk (N 0.25, B 4 deg/h, K 6)",
            |m| {
                m.arw_deg_rt_h = 0.25;
                m.bias_instability_dph = 4.0;
                m.rrw_deg_h_rt_h = 6.0;
            },
            vec![
                Term { name: "N", process: Process::White, truth: dps_rt_s(0.25) },
                Term { name: "B", process: Process::Flicker, truth: dps(4.0) },
                Term { name: "K", process: Process::RandomWalk, truth: k_base(6.0) },
            ],
        ),
        (
            "C: white + quantization + drift (N 0.25, Q 1e-3 deg, R 20 deg/h/h)",
            |m| {
                m.arw_deg_rt_h = 0.25;
                m.angle_quantization_deg = 1e-3 * 12f64.sqrt();
                m.rate_ramp_dph_per_h = 20.0;
            },
            vec![
                Term { name: "N", process: Process::White, truth: dps_rt_s(0.25) },
                Term { name: "Q", process: Process::Quantization, truth: 1e-3 },
                Term { name: "R", process: Process::Drift, truth: r_base(20.0) },
            ],
        ),
    ];
    println!("| model | term | slope lines: bias / RMSE (n resolved) | five-term fit: bias / RMSE (n) | GMWM: bias / RMSE (n) | GMWM 68.3 % coverage |");
    println!("|---|---|---|---|---|---|");
    for (label, set, terms) in &models {
        let mut model = SensorModel::default();
        set(&mut model);
        let spec = StaticSpec { sample_rate_hz: rate, duration_s: hours * 3600.0, ..StaticSpec::default() };
        let mut slope = vec![Stats::default(); terms.len()];
        let mut fit = vec![Stats::default(); terms.len()];
        let mut gm = vec![Stats::default(); terms.len()];
        let mut covered = vec![0usize; terms.len()];
        for seed in 0..seeds {
            let Ok(mut generator) = StaticGenerator::new(&model, &spec, 36_000 + seed) else {
                eprintln!("bad model");
                return;
            };
            let mut rate_samples = Vec::with_capacity(spec.samples() as usize + 1);
            let mut block = StaticBlock::default();
            while generator.next_block(&mut block, 1 << 16) > 0 {
                rate_samples.extend_from_slice(&block.output);
            }
            let opts = AllanOptions {
                kind: DeviationKind::Oadev,
                taus: TauList::Octave,
                confidence: Some(0.683),
                max_factor: None,
            };
            let Ok(curve) = deviation_from_rate(rate_samples, 1.0 / rate, &opts) else { continue };
            let s = slope_line_terms(&curve).ok();
            let f = fit_noise_model(&curve, None).ok();
            let g = gmwm(&curve, 0.683).ok();
            for (i, t) in terms.iter().enumerate() {
                let sv = s.as_ref().and_then(|s| match t.process {
                    Process::White => s.arw.value(),
                    Process::Flicker => s.bias_instability.value(),
                    Process::RandomWalk => s.rrw.value(),
                    Process::Quantization => s.quantization.value(),
                    Process::Drift => s.rate_ramp.value(),
                });
                let fv = f.as_ref().and_then(|f| match t.process {
                    Process::White => f.coefficients.arw_deg_rt_s,
                    Process::Flicker => f.coefficients.bias_instability_dps,
                    Process::RandomWalk => f.coefficients.rrw_deg_s_rt_s,
                    Process::Quantization => f.coefficients.quantization_deg,
                    Process::Drift => f.coefficients.rate_ramp_dps_per_s,
                });
                let gp = g.as_ref().and_then(|g| g.parameter(t.process));
                if let Some(v) = sv {
                    slope[i].add(v / t.truth - 1.0);
                }
                if let Some(v) = fv {
                    fit[i].add(v / t.truth - 1.0);
                }
                if let Some(p) = gp {
                    gm[i].add(p.value / t.truth - 1.0);
                    if p.lower <= t.truth && t.truth <= p.upper {
                        covered[i] += 1;
                    }
                }
            }
        }
        for (i, t) in terms.iter().enumerate() {
            println!(
                "| {label} | {} | {} | {} | {} | {:.1} % of {} |",
                t.name,
                slope[i].text(),
                fit[i].text(),
                gm[i].text(),
                100.0 * covered[i] as f64 / seeds as f64,
                seeds
            );
        }
    }
}
