//! Noise-parameter files for state estimators ("filter stacks"), each in the stack's own keys,
//! units, file format and time convention (docs/EXPORTS.md; conversions in docs/METHODS.md,
//! "Filter exports"). Sources of each convention:
//! - Kalibr: wiki "IMU Noise Model" (continuous-time densities; sigma_d = sigma_c sqrt(rate) for
//!   white noise, sigma_bd = sigma_b / sqrt(rate) for a random walk);
//! - OpenVINS: `kalibr_imu_chain.yaml` of its configs (`%YAML:1.0`, `imu0:` with Kalibr's keys,
//!   read with OpenCV FileStorage);
//! - VINS-Fusion / VINS-Mono: `acc_n`, `gyr_n`, `acc_w`, `gyr_w` in the `%YAML:1.0` config,
//!   per IMU sample as VINS-Fusion's midpoint propagation takes them
//!   (`vins_estimator/src/factor/integration_base.h` at be55a937, lines 30-36 and 118-134: the
//!   noise matrix holds GYR_N^2 twice and GYR_W^2 without dt, V has 0.5 dt on both gyro noises
//!   and dt on the walks, so the angle variance grows by 0.5 GYR_N^2 dt^2 a sample and the bias
//!   variance by GYR_W^2 dt^2): GYR_N = N sqrt(2 f), GYR_W = K sqrt(f), f the sample rate;
//! - ORB-SLAM3: `IMU.NoiseGyro`, `IMU.NoiseAcc`, `IMU.GyroWalk`, `IMU.AccWalk` (continuous,
//!   Tracking.cc `ParseIMUParamFile` and Settings.cc `readIMU` multiply the noises by
//!   sqrt(IMU.Frequency) and divide the walks by it); `IMU.Frequency` an integer (the parser
//!   before 1.0 refuses a real);
//! - Basalt: calibration JSON `gyro_noise_std`, `accel_noise_std` (continuous; its
//!   `dicrete_time_*_noise_std()` multiply by sqrt(imu_update_rate)), `gyro_bias_std`,
//!   `accel_bias_std` (continuous random-walk densities);
//! - PX4 EKF2: `EKF2_GYR_NOISE` rad/s, `EKF2_ACC_NOISE` m/s^2 (the delta-angle variance is
//!   (dt x EKF2_GYR_NOISE)^2), `EKF2_GYR_B_NOISE` rad/s^2, `EKF2_ACC_B_NOISE` m/s^3 (the bias
//!   increment per step is dt x the parameter; `Ekf::predictCovariance` in covariance.cpp, dt the
//!   prediction step, EKF2_PREDICT_US): per step, so from the densities at the step rate f:
//!   N sqrt(f) and K sqrt(f);
//! - ROS `sensor_msgs/Imu`: row-major 3x3 covariances of one message (per-sample variances);
//!   `orientation_covariance[0] = -1` when no orientation is given (the message's comment).

use std::fmt::Write as _;

/// A filter stack gyrolab writes noise parameters for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stack {
    /// Kalibr `imu.yaml`.
    Kalibr,
    /// OpenVINS `kalibr_imu_chain.yaml`.
    Openvins,
    /// VINS-Fusion / VINS-Mono config entries.
    Vins,
    /// ORB-SLAM3 settings entries (`%YAML:1.0`).
    Orbslam3,
    /// Basalt calibration JSON (IMU noise part).
    Basalt,
    /// PX4 parameter file for `param set` (NuttX shell script lines).
    Px4,
    /// QGroundControl `.params` file (tab-separated) of the same PX4 parameters.
    Px4Qgc,
    /// ROS `sensor_msgs/Imu` covariance matrices.
    RosCovariance,
}

/// Every stack, in the order of the documentation.
pub const STACKS: [Stack; 8] = [
    Stack::Kalibr,
    Stack::Openvins,
    Stack::Vins,
    Stack::Orbslam3,
    Stack::Basalt,
    Stack::Px4,
    Stack::Px4Qgc,
    Stack::RosCovariance,
];

impl Stack {
    /// The stack's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Stack::Kalibr => "kalibr",
            Stack::Openvins => "openvins",
            Stack::Vins => "vins",
            Stack::Orbslam3 => "orbslam3",
            Stack::Basalt => "basalt",
            Stack::Px4 => "px4",
            Stack::Px4Qgc => "px4-qgc",
            Stack::RosCovariance => "ros-covariance",
        }
    }

    /// Parses a stack name (case-insensitive).
    pub fn parse(text: &str) -> Option<Stack> {
        let t = text.trim().to_ascii_lowercase();
        STACKS.iter().copied().find(|s| s.name() == t)
    }

    /// The usual extension of the stack's file: `json` (Basalt), `txt` (PX4 `param set`
    /// lines), `params` (QGroundControl), else `yaml`.
    pub fn file_extension(self) -> &'static str {
        match self {
            Stack::Basalt => "json",
            Stack::Px4 => "txt",
            Stack::Px4Qgc => "params",
            _ => "yaml",
        }
    }

    /// Whether the stack's values are per sample or per filter step (discrete time) rather than
    /// densities.
    pub fn per_sample(self) -> bool {
        matches!(self, Stack::Px4 | Stack::Px4Qgc | Stack::RosCovariance)
    }
}

/// How an exported term was obtained.
#[derive(Clone, Debug, PartialEq)]
pub struct TermSource {
    /// `value`, `upper_bound`, `fit_value`, `gmwm`, `gmwm_gauss_markov_bound` or
    /// `gmwm_upper_bound` (gyrolab-eval's `TermEstimate`).
    pub basis: String,
    /// What the basis means for this term, for the file's header (confidence and sidedness of a
    /// bound or interval, the channel it comes from).
    pub detail: String,
}

/// One continuous-time noise term as exported.
#[derive(Clone, Debug, PartialEq)]
pub struct ExportTerm {
    /// The value written, after every factor: gyro white noise rad/s/sqrt(Hz), gyro random walk
    /// rad/s^2/sqrt(Hz), accelerometer white noise m/s^2/sqrt(Hz), accelerometer random walk
    /// m/s^3/sqrt(Hz).
    pub value: f64,
    /// The estimate before any factor, same unit.
    pub estimate: f64,
    /// The overbound factor applied (1 when not overbounded or not needed), when overbounding.
    pub overbound_factor: Option<f64>,
    /// How the estimate was obtained.
    pub source: TermSource,
}

/// The noise parameters of one IMU record, ready to be written for any stack.
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseExport {
    /// The record (file, and topic of a recording).
    pub record: String,
    /// The sample rate, Hz.
    pub rate_hz: f64,
    /// The input was simulated (every file says so).
    pub simulated: bool,
    /// The estimator of the values: `slopes`, `fit` or `gmwm`.
    pub estimator: String,
    /// The factor `--inflate` applied to every value (1: none).
    pub inflation: f64,
    /// Gyro white noise (angle random walk N).
    pub gyro_noise: Option<ExportTerm>,
    /// Gyro random walk (rate random walk K).
    pub gyro_walk: Option<ExportTerm>,
    /// Accelerometer white noise (velocity random walk).
    pub accel_noise: Option<ExportTerm>,
    /// Accelerometer random walk.
    pub accel_walk: Option<ExportTerm>,
    /// The ROS topic, when the record is a topic of a recording.
    pub rostopic: Option<String>,
    /// One `MOTION: the record is not static: ...` line per channel that moved (the stillness
    /// check; analysed because motion was allowed): each goes into every file's header.
    pub motion: Vec<String>,
    /// Terms of the model the values come from that no stack takes (a GMWM flicker floor,
    /// quantization or drift), one line each in every file's header: the values do not represent
    /// them.
    pub unrepresented: Vec<String>,
    /// The writer's version, for the header.
    pub writer: String,
    /// Per-axis values (x, y, z; same unit and factors as the combined term) of gyro noise,
    /// gyro walk, accelerometer noise and accelerometer walk, where the record has that term on
    /// all three axes: written by the stacks that take one value per axis (Basalt); the others
    /// take the combined (largest) value.
    pub per_axis: [Option<[f64; 3]>; 4],
}

/// Per-step rate of PX4's EKF2 prediction by default (EKF2_PREDICT_US = 10000 us).
pub const PX4_DEFAULT_EKF_HZ: f64 = 100.0;

/// The number as text a YAML 1.1 reader (PyYAML), OpenCV FileStorage and JSON all read as a
/// real: scientific notation with a decimal point and a signed exponent (`1.7e-05`, `2.0e+02`),
/// the shortest that reads back to the same f64.
pub fn real_text(v: f64) -> String {
    if !v.is_finite() {
        return ".nan".into();
    }
    // Rust's `{:e}` is the shortest round-trip form: "1.7e-5", "2e2".
    let s = format!("{v:e}");
    let (mantissa, exponent) = s.split_once('e').unwrap_or((s.as_str(), "0"));
    let mantissa = if mantissa.contains('.') { mantissa.to_string() } else { format!("{mantissa}.0") };
    let (sign, digits) = match exponent.strip_prefix('-') {
        Some(d) => ("-", d),
        None => ("+", exponent),
    };
    format!("{mantissa}e{sign}{digits:0>2}")
}

/// A rate whole to within 1e-9 of itself (200.00000000635782 from a clock's stamps), as that
/// whole number; `None` for any other rate.
pub fn whole_rate(v: f64) -> Option<i64> {
    let r = v.round();
    (v.is_finite() && (1.0..1e15).contains(&r) && (v - r).abs() <= 1e-9 * v.abs()).then_some(r as i64)
}

/// The rate as text: a whole rate as an integer (`200`, as Kalibr's and ORB-SLAM3's own files
/// write it; every reader of these files takes an integer where it reads a real), any other as
/// the shortest decimal that reads back to it.
fn rate_text(v: f64) -> String {
    match whole_rate(v) {
        Some(n) => n.to_string(),
        None => format!("{v}"),
    }
}

fn json_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// One line of text with no line breaks (names in comments).
fn one_line(s: &str) -> String {
    s.chars().map(|c| if c.is_control() { ' ' } else { c }).collect()
}

/// What each term is, in the order gyro noise, gyro walk, accel noise, accel walk.
struct Slot<'a> {
    term: Option<&'a ExportTerm>,
    what: &'static str,
    unit: &'static str,
}

impl NoiseExport {
    fn slots(&self) -> [Slot<'_>; 4] {
        [
            Slot {
                term: self.gyro_noise.as_ref(),
                what: "gyro white noise (angle random walk)",
                unit: "rad/s/sqrt(Hz)",
            },
            Slot {
                term: self.gyro_walk.as_ref(),
                what: "gyro bias random walk (rate random walk)",
                unit: "rad/s^2/sqrt(Hz)",
            },
            Slot {
                term: self.accel_noise.as_ref(),
                what: "accelerometer white noise (velocity random walk)",
                unit: "m/s^2/sqrt(Hz)",
            },
            Slot { term: self.accel_walk.as_ref(), what: "accelerometer bias random walk", unit: "m/s^3/sqrt(Hz)" },
        ]
    }

    /// The per-sample (discrete-time) value of a continuous term at `rate_hz`: white noise
    /// sigma_c sqrt(rate) (a standard deviation per sample), random walk sigma_c / sqrt(rate)
    /// (the bias increment per sample).
    pub fn discrete(value: f64, white: bool, rate_hz: f64) -> f64 {
        if white {
            value * rate_hz.sqrt()
        } else {
            value / rate_hz.sqrt()
        }
    }

    /// The header lines (without comment markers) every file carries.
    pub fn header_lines(&self, stack: Stack) -> Vec<String> {
        let mut h = vec![format!("{} noise parameters written by gyrolab {}", stack.name(), self.writer)];
        if self.simulated {
            h.push("SIMULATED: the record analysed is a simulated record, not a measured sensor".into());
        }
        h.extend(self.motion.iter().map(|m| one_line(m)));
        h.push(format!("record: {}", one_line(&self.record)));
        h.push(format!("sample rate: {} Hz", rate_text(self.rate_hz)));
        h.push(format!("estimator: {}", self.estimator));
        h.extend(self.unrepresented.iter().map(|m| format!("NOT REPRESENTED: {}", one_line(m))));
        h.push(if stack == Stack::Vins {
            format!(
                "time convention: per IMU sample at {} Hz, as VINS-Fusion's midpoint propagation takes them \
                 (integration_base.h): gyr_n = N sqrt(2 rate), gyr_w = K sqrt(rate), acc_n and acc_w likewise",
                rate_text(self.rate_hz)
            )
        } else if matches!(stack, Stack::Px4 | Stack::Px4Qgc) {
            format!(
                "time convention: per EKF2 prediction step at {} Hz (density x sqrt(step rate); see below)",
                rate_text(PX4_DEFAULT_EKF_HZ)
            )
        } else if stack.per_sample() {
            format!(
                "time convention: per sample at {} Hz (variance of one message's value: (density x sqrt(rate))^2)",
                rate_text(self.rate_hz)
            )
        } else {
            "time convention: continuous time (noise densities; the stack converts with its rate)".into()
        });
        h.push(if self.inflation == 1.0 {
            "inflation: none (factor 1)".into()
        } else {
            format!(
                "inflation: every value x {} (--inflate), variances x {}",
                self.inflation,
                self.inflation * self.inflation
            )
        });
        for s in self.slots() {
            match s.term {
                Some(t) => {
                    let mut line = format!(
                        "{}: {} {} ({}: {})",
                        s.what,
                        real_text(t.estimate),
                        s.unit,
                        t.source.basis,
                        one_line(&t.source.detail)
                    );
                    if let Some(f) = t.overbound_factor {
                        let _ = write!(line, "; overbound factor {f:.4}");
                    }
                    if t.value != t.estimate {
                        let _ = write!(line, "; written {}", real_text(t.value));
                    }
                    h.push(line);
                }
                None => h.push(format!("{}: not estimated (no such channel with noise terms): not written", s.what)),
            }
        }
        h
    }

    /// The file text for `stack`.
    pub fn render(&self, stack: Stack) -> String {
        match stack {
            Stack::Kalibr => self.kalibr(),
            Stack::Openvins => self.openvins(),
            Stack::Vins => self.vins(),
            Stack::Orbslam3 => self.orbslam3(),
            Stack::Basalt => self.basalt(),
            Stack::Px4 => self.px4(false),
            Stack::Px4Qgc => self.px4(true),
            Stack::RosCovariance => self.ros_covariance(),
        }
    }

    fn comment_header(&self, stack: Stack, prefix: &str) -> String {
        let mut s = String::new();
        for l in self.header_lines(stack) {
            let _ = writeln!(s, "{prefix}{l}");
        }
        s
    }

    /// `key: value   # unit` lines for continuous keys (missing terms as comments).
    fn yaml_entries(&self, keys: [&str; 4], indent: &str) -> String {
        let mut s = String::new();
        for (key, slot) in keys.iter().zip(self.slots()) {
            match slot.term {
                Some(t) => {
                    let _ = writeln!(s, "{indent}{key}: {}   # {}, {}", real_text(t.value), slot.unit, t.source.basis);
                }
                None => {
                    let _ = writeln!(s, "{indent}# {key}: not written ({} not estimated)", slot.what);
                }
            }
        }
        s
    }

    fn kalibr(&self) -> String {
        let mut s = self.comment_header(Stack::Kalibr, "# ");
        s.push_str(&self.yaml_entries(
            [
                "gyroscope_noise_density",
                "gyroscope_random_walk",
                "accelerometer_noise_density",
                "accelerometer_random_walk",
            ],
            "",
        ));
        let _ = writeln!(s, "update_rate: {}", rate_text(self.rate_hz));
        match &self.rostopic {
            Some(t) => {
                let _ = writeln!(s, "rostopic: {}", one_line(t));
            }
            None => s.push_str(
                "# rostopic: not known from this record; /imu0 is Kalibr's example: set yours\nrostopic: /imu0\n",
            ),
        }
        s
    }

    fn openvins(&self) -> String {
        let mut s = String::from("%YAML:1.0 # OpenVINS reads this file with OpenCV FileStorage\n");
        s.push_str(&self.comment_header(Stack::Openvins, "# "));
        s.push_str("imu0:\n  T_i_b:\n");
        for r in 0..4 {
            let row: Vec<&str> = (0..4).map(|c| if r == c { "1.0" } else { "0.0" }).collect();
            let _ = writeln!(s, "    - [{}]", row.join(", "));
        }
        s.push_str(&self.yaml_entries(
            [
                "gyroscope_noise_density",
                "gyroscope_random_walk",
                "accelerometer_noise_density",
                "accelerometer_random_walk",
            ],
            "  ",
        ));
        let _ = writeln!(s, "  rostopic: {}", self.rostopic.as_deref().map_or("/imu0".into(), one_line));
        s.push_str("  time_offset: 0.0\n");
        let _ = writeln!(s, "  update_rate: {}", rate_text(self.rate_hz));
        s.push_str(
            "  # intrinsics not estimated by gyrolab: identity (OpenVINS's \"kalibr\" model)\n  model: \"kalibr\"\n",
        );
        for key in ["Tw", "R_IMUtoGYRO", "Ta", "R_IMUtoACC"] {
            let _ = writeln!(s, "  {key}:");
            for r in 0..3 {
                let row: Vec<&str> = (0..3).map(|c| if r == c { "1.0" } else { "0.0" }).collect();
                let _ = writeln!(s, "    - [{}]", row.join(", "));
            }
        }
        s.push_str("  Tg:\n");
        for _ in 0..3 {
            s.push_str("    - [0.0, 0.0, 0.0]\n");
        }
        s
    }

    /// VINS-Fusion's values per IMU sample (see the module documentation): white noise
    /// N sqrt(2 f), random walk K sqrt(f), f the sample rate.
    pub fn vins_values(&self) -> [Option<f64>; 4] {
        let f = self.rate_hz;
        let factors = [(2.0 * f).sqrt(), f.sqrt(), (2.0 * f).sqrt(), f.sqrt()];
        let slots = self.slots();
        std::array::from_fn(|i| slots[i].term.map(|t| t.value * factors[i]))
    }

    fn vins(&self) -> String {
        let mut s = String::from("%YAML:1.0\n");
        s.push_str(&self.comment_header(Stack::Vins, "# "));
        s.push_str(
            "# The IMU entries of a VINS-Fusion / VINS-Mono config: paste them into yours (its other keys are\n\
             # the cameras'). Per IMU sample, as vins_estimator/src/factor/integration_base.h propagates them\n\
             # (midpoint step: angle variance + 0.5 gyr_n^2 dt^2, bias variance + gyr_w^2 dt^2 a sample), so\n\
             # gyr_n = density x sqrt(2 x rate) and gyr_w = random walk x sqrt(rate); the densities are in the\n\
             # header above. One value for every axis (VINS takes one): the largest of the axes.\n",
        );
        let keys = ["gyr_n", "gyr_w", "acc_n", "acc_w"];
        let units = ["rad/s", "rad/s^2", "m/s^2", "m/s^3"];
        for (((key, value), slot), unit) in keys.iter().zip(self.vins_values()).zip(self.slots()).zip(units) {
            match (value, slot.term) {
                (Some(v), Some(t)) => {
                    let _ = writeln!(s, "{key}: {}   # {unit} per sample, {}", real_text(v), t.source.basis);
                }
                _ => {
                    let _ = writeln!(s, "# {key}: not written ({} not estimated)", slot.what);
                }
            }
        }
        s.push_str("# g_norm: your local gravity, m/s^2 (not estimated by gyrolab)\n");
        s
    }

    fn orbslam3(&self) -> String {
        let mut s = String::from("%YAML:1.0\n");
        s.push_str(&self.comment_header(Stack::Orbslam3, "# "));
        s.push_str("# The IMU entries of an ORB-SLAM3 settings file (continuous time: ORB-SLAM3 multiplies the\n# noises by sqrt(IMU.Frequency) and divides the walks by it).\n");
        s.push_str(&self.yaml_entries(["IMU.NoiseGyro", "IMU.GyroWalk", "IMU.NoiseAcc", "IMU.AccWalk"], ""));
        // An integer: ORB-SLAM3's parser before 1.0 (Tracking.cc ParseIMUParamFile) refuses a real.
        let whole = self.rate_hz.round().max(1.0);
        if whole_rate(self.rate_hz).is_none() {
            let _ = writeln!(
                s,
                "# the record's rate is {} Hz; IMU.Frequency is the nearest integer (ORB-SLAM3 before 1.0 reads an integer only)",
                self.rate_hz
            );
        }
        let _ = writeln!(s, "IMU.Frequency: {}", whole as i64);
        s
    }

    fn basalt(&self) -> String {
        let mut s = String::from("{\n  \"gyrolab_header\": [\n");
        let lines = self.header_lines(Stack::Basalt);
        for (i, l) in lines.iter().enumerate() {
            let _ = writeln!(s, "    {}{}", json_string(l), if i + 1 < lines.len() { "," } else { "" });
        }
        s.push_str("  ],\n  \"gyrolab_merge\": \"a fragment of Basalt's calibration: copy the keys of value0 into the value0 of your full calib JSON (cereal reads them by name); per-axis values [x, y, z] where the record has all three axes, else the largest on each\",\n");
        s.push_str("  \"value0\": {\n");
        let mut entries = vec![format!("    \"imu_update_rate\": {}", rate_text(self.rate_hz))];
        for ((key, slot), axes) in ["gyro_noise_std", "gyro_bias_std", "accel_noise_std", "accel_bias_std"]
            .iter()
            .zip(self.slots())
            .zip(self.per_axis)
        {
            if let Some(t) = slot.term {
                // One value per axis (Basalt's Vec3) where the record has all three, else the
                // combined (largest) value on each.
                let [x, y, z] = axes.unwrap_or([t.value; 3]).map(real_text);
                entries.push(format!("    \"{key}\": [{x}, {y}, {z}]"));
            }
        }
        s.push_str(&entries.join(",\n"));
        s.push_str("\n  }\n}\n");
        s
    }

    /// PX4 values per EKF2 prediction step at [`PX4_DEFAULT_EKF_HZ`]: white noise N sqrt(f),
    /// random walk K sqrt(f), f the step rate (not the sensor's rate: EKF2 integrates the IMU
    /// samples over each step).
    fn px4_values(&self, step_hz: f64) -> Vec<(&'static str, Option<f64>, &'static str)> {
        let f = step_hz.sqrt();
        let keys = [
            ("EKF2_GYR_NOISE", "rad/s"),
            ("EKF2_GYR_B_NOISE", "rad/s^2"),
            ("EKF2_ACC_NOISE", "m/s^2"),
            ("EKF2_ACC_B_NOISE", "m/s^3"),
        ];
        keys.iter().zip(self.slots()).map(|(&(k, u), slot)| (k, slot.term.map(|t| t.value * f), u)).collect()
    }

    fn px4(&self, qgc: bool) -> String {
        let stack = if qgc { Stack::Px4Qgc } else { Stack::Px4 };
        let mut s = self.comment_header(stack, "# ");
        let _ = writeln!(
            s,
            "# PX4 EKF2 applies these per prediction step dt (EKF2_PREDICT_US, default 10000 us = {} Hz): delta-angle\n\
             # sigma = dt x EKF2_GYR_NOISE, bias step sigma = dt x EKF2_GYR_B_NOISE, so each value is the continuous density\n\
             # x sqrt(step rate). Written for the default {} Hz step; for another EKF2_PREDICT_US use density x sqrt(1e6 /\n\
             # EKF2_PREDICT_US). At the record's own rate, {} Hz, they would be:",
            rate_text(PX4_DEFAULT_EKF_HZ),
            rate_text(PX4_DEFAULT_EKF_HZ),
            rate_text(self.rate_hz)
        );
        for (k, v, u) in self.px4_values(self.rate_hz) {
            if let Some(v) = v {
                let _ = writeln!(s, "#   {k} = {} {u}", real_text(v));
            }
        }
        if qgc {
            s.push_str("#\n# Vehicle-Id Component-Id Name Value Type\n");
        }
        for (k, v, u) in self.px4_values(PX4_DEFAULT_EKF_HZ) {
            match (v, qgc) {
                (Some(v), true) => {
                    // MAV_PARAM_TYPE_REAL32 = 9
                    let _ = writeln!(s, "1\t1\t{k}\t{}\t9", real_text(v));
                }
                (Some(v), false) => {
                    let _ = writeln!(s, "param set {k} {}", real_text(v));
                }
                (None, _) => {
                    let _ = writeln!(s, "# {k} ({u}): not written (not estimated)");
                }
            }
        }
        s
    }

    fn ros_covariance(&self) -> String {
        let mut s = self.comment_header(Stack::RosCovariance, "# ");
        s.push_str(
            "# sensor_msgs/Imu covariances, row-major 3x3, per sample (the variance of one message's value):\n\
             # diagonal = (density x sqrt(rate))^2; axes combined (same variance on every axis); random walks\n\
             # are not part of the message. orientation_covariance[0] = -1: no orientation estimate.\n",
        );
        let slots = self.slots();
        let matrix = |t: Option<&ExportTerm>| -> String {
            match t {
                Some(t) => {
                    let v = real_text((t.value * self.rate_hz.sqrt()).powi(2));
                    let z = "0.0";
                    format!("[{v}, {z}, {z}, {z}, {v}, {z}, {z}, {z}, {v}]")
                }
                None => "[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]".into(),
            }
        };
        s.push_str("orientation_covariance: [-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]\n");
        if slots[0].term.is_none() {
            s.push_str("# angular_velocity_covariance: all zero = unknown (no gyro noise estimated)\n");
        }
        let _ = writeln!(s, "angular_velocity_covariance: {}   # (rad/s)^2", matrix(slots[0].term));
        if slots[2].term.is_none() {
            s.push_str("# linear_acceleration_covariance: all zero = unknown (no accelerometer noise estimated)\n");
        }
        let _ = writeln!(s, "linear_acceleration_covariance: {}   # (m/s^2)^2", matrix(slots[2].term));
        s
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod propagation;
