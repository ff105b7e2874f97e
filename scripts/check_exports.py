"""Loads every filter export of `gyrolab allan --export` with the stack's own reader or the closest
available one and checks its keys and values against hand conversions (docs/EXPORTS.md):

- Kalibr, VINS, ROS covariances: PyYAML (VINS's `%YAML:1.0` directive line is OpenCV's, not YAML 1.1:
  dropped before PyYAML reads the file, as it is for OpenVINS);
- OpenVINS, VINS, ORB-SLAM3: OpenCV's FileStorage (opencv-python-headless), the reader these stacks use;
- Basalt: json;
- PX4 `param set` file and QGroundControl `.params`: a parser written from PX4's documentation
  (`param set NAME VALUE` lines of the NuttX shell; QGC's tab-separated `vehicle component name value
  type` rows, `#` comments).

The record is white noise of known density on a gyro (rad/s) and an accelerometer (m/s^2) channel:
the exported white-noise densities must hold the simulated truth within 5 %, and every stack must
hold the same value converted by hand (continuous -> per sample x sqrt(rate), random walk x
sqrt(rate) for PX4's per-step rad/s^2, variance = sigma^2 for ROS). Usage:
check_exports.py PATH/TO/gyrolab
"""

import json
import math
import os
import subprocess
import sys
import tempfile

import cv2
import numpy as np
import yaml

RATE = 200.0  # not PX4's 100 Hz step rate, so the two conventions differ
N_GYRO = 2.0e-3  # rad/s/sqrt(Hz)
N_ACC = 3.0e-2  # m/s^2/sqrt(Hz)
FAILURES = []


def check(cond, what):
    if not cond:
        FAILURES.append(what)
        print("FAIL:", what)


def close(a, b, rel=1e-9):
    return a is not None and b is not None and abs(a - b) <= rel * abs(b)


def yaml_without_directive(path):
    with open(path, encoding="utf-8") as f:
        text = f.read()
    lines = text.splitlines()
    if lines and lines[0].startswith("%YAML:"):
        lines = lines[1:]
    return yaml.safe_load("\n".join(lines))


def px4_param_file(path):
    """PX4 `param set NAME VALUE` lines (docs: 'Parameters & Configurations', NuttX shell)."""
    out = {}
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            parts = line.split()
            assert parts[:2] == ["param", "set"] and len(parts) == 4, line
            out[parts[2]] = float(parts[3])
    return out


def qgc_params(path):
    """QGroundControl .params: `# ...` comments, rows vehicle<TAB>component<TAB>name<TAB>value<TAB>type."""
    out = {}
    with open(path, encoding="utf-8") as f:
        for line in f:
            if not line.strip() or line.startswith("#"):
                continue
            cells = line.rstrip("\n").split("\t")
            assert len(cells) == 5, line
            assert cells[4] == "9", line  # MAV_PARAM_TYPE_REAL32
            out[cells[2]] = float(cells[3])
    return out


def main():
    gyrolab = os.path.abspath(sys.argv[1])
    rng = np.random.default_rng(36)
    n = 200_000
    gyro = rng.standard_normal(n) * N_GYRO * math.sqrt(RATE)
    acc = 9.81 + rng.standard_normal(n) * N_ACC * math.sqrt(RATE)
    with tempfile.TemporaryDirectory() as d:
        csv = os.path.join(d, "imu.csv")
        with open(csv, "w", encoding="utf-8") as f:
            f.write("time_s,gyro_x [rad/s],accel_x [m/s^2]\n")
            for i in range(n):
                f.write(f"{i / RATE:.3f},{gyro[i]:.17g},{acc[i]:.17g}\n")
        stacks = ["kalibr", "openvins", "vins", "orbslam3", "basalt", "px4", "px4-qgc", "ros-covariance"]
        ext = {"basalt": "json", "px4": "txt", "px4-qgc": "params"}
        paths = {s: os.path.join(d, f"{s}.{ext.get(s, 'yaml')}") for s in stacks}
        args = [gyrolab, "allan", csv, "--json"]
        for s in stacks:
            args += ["--export", f"{s}={paths[s]}"]
        run = subprocess.run(args, capture_output=True, text=True, check=False)
        check(run.returncode == 0, f"gyrolab allan exit {run.returncode}: {run.stderr}")
        doc = json.loads(run.stdout)

        kalibr = yaml.safe_load(open(paths["kalibr"], encoding="utf-8"))
        ng = kalibr["gyroscope_noise_density"]
        kg = kalibr["gyroscope_random_walk"]
        na = kalibr["accelerometer_noise_density"]
        ka = kalibr["accelerometer_random_walk"]
        check(close(kalibr["update_rate"], RATE), "kalibr update_rate")
        # Independent value: the simulated truth.
        check(abs(ng / N_GYRO - 1) < 0.05, f"kalibr gyro noise density {ng} vs truth {N_GYRO}")
        check(abs(na / N_ACC - 1) < 0.05, f"kalibr accel noise density {na} vs truth {N_ACC}")
        # The same as the JSON's Kalibr entries of the gyro channel (rad units).
        gyro_json = [c for c in doc["channels"] if c["channel"].startswith("gyro")][0]
        check(close(ng, gyro_json["noise"]["kalibr"]["gyroscope_noise_density"]), "kalibr file vs JSON")

        ov_fs = cv2.FileStorage(paths["openvins"], cv2.FILE_STORAGE_READ)
        imu0 = ov_fs.getNode("imu0")
        for key, want in [("gyroscope_noise_density", ng), ("gyroscope_random_walk", kg),
                          ("accelerometer_noise_density", na), ("accelerometer_random_walk", ka),
                          ("update_rate", RATE)]:
            check(close(imu0.getNode(key).real(), want), f"openvins (OpenCV) {key}")
        check(imu0.getNode("T_i_b").isSeq(), "openvins T_i_b")
        ov = yaml_without_directive(paths["openvins"])["imu0"]
        check(close(ov["gyroscope_noise_density"], ng), "openvins (PyYAML) gyroscope_noise_density")

        vins = yaml_without_directive(paths["vins"])
        vins_fs = cv2.FileStorage(paths["vins"], cv2.FILE_STORAGE_READ)
        # Per IMU sample, as VINS-Fusion's integration_base.h propagates them: N sqrt(2 f), K sqrt(f).
        for key, want in [("gyr_n", ng * math.sqrt(2 * RATE)), ("gyr_w", kg * math.sqrt(RATE)),
                          ("acc_n", na * math.sqrt(2 * RATE)), ("acc_w", ka * math.sqrt(RATE))]:
            check(close(vins[key], want), f"vins (PyYAML) {key}")
            check(close(vins_fs.getNode(key).real(), want, 1e-9), f"vins (OpenCV) {key}")

        orb = cv2.FileStorage(paths["orbslam3"], cv2.FILE_STORAGE_READ)
        for key, want in [("IMU.NoiseGyro", ng), ("IMU.GyroWalk", kg), ("IMU.NoiseAcc", na),
                          ("IMU.AccWalk", ka)]:
            node = orb.getNode(key)
            check(node.isReal(), f"orbslam3 {key} is a real (ORB-SLAM3's ParseIMUParamFile refuses other types)")
            check(close(node.real(), want), f"orbslam3 {key}")
        node = orb.getNode("IMU.Frequency")
        check(node.isInt(), "orbslam3 IMU.Frequency is an integer (ParseIMUParamFile refuses a real)")
        check(node.real() == round(RATE), "orbslam3 IMU.Frequency")

        basalt = json.load(open(paths["basalt"], encoding="utf-8"))["value0"]
        check(close(basalt["imu_update_rate"], RATE), "basalt imu_update_rate")
        for key, want in [("gyro_noise_std", ng), ("gyro_bias_std", kg), ("accel_noise_std", na),
                          ("accel_bias_std", ka)]:
            check(len(basalt[key]) == 3 and all(close(v, want) for v in basalt[key]), f"basalt {key}")

        root = math.sqrt(RATE)
        step = math.sqrt(100.0)  # PX4 EKF2's default prediction step rate (EKF2_PREDICT_US = 10000)
        for name, params in [("px4", px4_param_file(paths["px4"])), ("px4-qgc", qgc_params(paths["px4-qgc"]))]:
            for key, want in [("EKF2_GYR_NOISE", ng * step), ("EKF2_GYR_B_NOISE", kg * step),
                              ("EKF2_ACC_NOISE", na * step), ("EKF2_ACC_B_NOISE", ka * step)]:
                check(close(params.get(key), want), f"{name} {key} = {params.get(key)} vs {want}")

        ros = yaml.safe_load(open(paths["ros-covariance"], encoding="utf-8"))
        av = ros["angular_velocity_covariance"]
        la = ros["linear_acceleration_covariance"]
        check(len(av) == 9 and close(av[0], (ng * root) ** 2) and av[4] == av[0] and av[8] == av[0]
              and av[1] == 0.0, "ros angular_velocity_covariance")
        check(len(la) == 9 and close(la[0], (na * root) ** 2), "ros linear_acceleration_covariance")
        check(ros["orientation_covariance"][0] == -1.0, "ros orientation_covariance[0] = -1")

        # --inflate 10: every continuous value x 10, every variance x 100, recorded in the header.
        inflated = os.path.join(d, "inflated.yaml")
        ros10 = os.path.join(d, "ros10.yaml")
        run = subprocess.run([gyrolab, "allan", csv, "--inflate", "10", "--export", f"kalibr={inflated}",
                              "--export", f"ros-covariance={ros10}"], capture_output=True, text=True, check=False)
        check(run.returncode == 0, f"--inflate exit {run.returncode}: {run.stderr}")
        k10 = yaml.safe_load(open(inflated, encoding="utf-8"))
        check(close(k10["gyroscope_noise_density"], 10 * ng), "inflate x10 kalibr")
        r10 = yaml.safe_load(open(ros10, encoding="utf-8"))
        check(close(r10["angular_velocity_covariance"][0], 100 * av[0], 1e-8), "inflate x10 ros variance x100")
        check("x 10" in open(inflated, encoding="utf-8").read(), "inflation recorded in the header")

        # A target that cannot be written: no file of the run is written, exit 2.
        bad = os.path.join(d, "missing", "x.yaml")
        fresh = os.path.join(d, "fresh.yaml")
        run = subprocess.run([gyrolab, "allan", csv, "--export", f"kalibr={fresh}", "--export", f"vins={bad}"],
                             capture_output=True, text=True, check=False)
        check(run.returncode != 0 and not os.path.exists(fresh), "all or none")
    if FAILURES:
        print(f"check_exports: {len(FAILURES)} failure(s)")
        sys.exit(1)
    print("check_exports: every export loaded by its reader and equal to the hand conversions")


if __name__ == "__main__":
    main()
