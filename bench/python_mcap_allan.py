"""The Python way to IMU noise from a ROS 2 MCAP recording: the `mcap` package's reader, the
`rosbags` CDR deserializer for every sensor_msgs/msg/Imu message, then allantools.oadev (octave
taus, rate data, no bounds) on the six channels. Prints its read and compute split.

usage: python_mcap_allan.py FILE.mcap RATE_HZ
"""
import resource
import sys
import time

import allantools
import numpy as np
from mcap.reader import make_reader
from rosbags.typesys import Stores, get_typestore


def main():
    path, rate = sys.argv[1], float(sys.argv[2])
    ts = get_typestore(Stores.ROS2_HUMBLE)
    t0 = time.perf_counter()
    cols = [[] for _ in range(6)]
    stamps = []
    with open(path, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages():
            if schema is None or schema.name != "sensor_msgs/msg/Imu":
                continue
            m = ts.deserialize_cdr(message.data, "sensor_msgs/msg/Imu")
            stamps.append(m.header.stamp.sec * 1_000_000_000 + m.header.stamp.nanosec)
            g, a = m.angular_velocity, m.linear_acceleration
            for c, v in zip(cols, (g.x, g.y, g.z, a.x, a.y, a.z)):
                c.append(v)
    order = np.argsort(np.asarray(stamps), kind="stable")
    data = [np.asarray(c)[order] for c in cols]
    t1 = time.perf_counter()
    for x in data:
        allantools.oadev(x, rate=rate, data_type="freq", taus="octave")
    t2 = time.perf_counter()
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(f"read_s {t1 - t0:.3f} compute_s {t2 - t1:.3f} messages {len(stamps)} peak_mb {peak_mb:.0f}")


if __name__ == "__main__":
    main()
