//! The noise files of `--kalibr-yaml` and `--imu-utils-yaml`: Kalibr's imu.yaml and imu_utils'
//! file from the Allan analyses of a run, one file per topic when a recording has several (their
//! names then end in the topic), each marked MOTION when a channel moved. Nothing is written here:
//! the front end writes every file of the run together.

use gyrolab_eval::allan::AllanOutcome;
use gyrolab_eval::filter_export::{recording_motion, with_motion};
use gyrolab_eval::recording::per_topic_path;
use gyrolab_eval::{EvalError, EvalResult};
use gyrolab_report::allan::{imu_utils_yaml, kalibr_yaml};
use std::path::{Path, PathBuf};

/// A file of a run: where it goes and its bytes.
pub type NoiseFile = (PathBuf, Vec<u8>);

/// The Kalibr (`kalibr`) and imu_utils (`imu_utils`) files of `outcomes`, with the writers'
/// warnings. A topic whose curves give no noise term is an error naming it (no file is made).
pub fn stack_files(
    outcomes: &[AllanOutcome],
    kalibr: Option<&Path>,
    imu_utils: Option<&Path>,
) -> EvalResult<(Vec<NoiseFile>, Vec<String>)> {
    let mut files = Vec::new();
    let mut warnings = Vec::new();
    let several = outcomes.len() > 1;
    let motion = recording_motion(outcomes);
    for (path, is_imu_utils) in [(kalibr, false), (imu_utils, true)] {
        let Some(path) = path else { continue };
        let writer = if is_imu_utils { imu_utils_yaml } else { kalibr_yaml };
        for outcome in outcomes {
            // One file per topic when there are several: imu.yaml -> imu_<topic>.yaml.
            let target = match (&outcome.topic, several) {
                (Some(t), true) => per_topic_path(path, &t.topic),
                _ => path.to_path_buf(),
            };
            let file = writer(&outcome.analyses, 1.0 / outcome.sample_interval_s).ok_or_else(|| {
                let whose = outcome.topic.as_ref().map_or(String::new(), |t| format!("topic {}: ", t.topic));
                EvalError::conflict(format!("{whose}no noise terms could be read from the curves (give the gyro channels a unit such as --unit rad/s, or calibrate outputs with --cal or --scale-factor, and use --kind oadev); no output file was written"))
            })?;
            files.push((target, with_motion(file.text, &motion).into_bytes()));
            warnings.extend(file.warnings);
        }
    }
    Ok((files, warnings))
}
