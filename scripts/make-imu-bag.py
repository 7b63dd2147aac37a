#!/usr/bin/python3
"""Writes the start of a six-axis IMU CSV (rwcalc simulate --layout imu) as a ROS 1 bag of
sensor_msgs/Imu messages on /imu/data, with ROS's own writer (Debian's python3-rosbag, which pulls
ROS libraries the build does not need): gyro columns in deg/s become rad/s, accelerometer columns in g
or m/s^2 become m/s^2; header.stamp is 1.7e9 s + k/rate, the receive time 0.2 ms later; bz2 chunks.

Usage: scripts/make-imu-bag.py CSV[.gz] BAG [SECONDS]   (SECONDS: how much of the record, default 600)
data/imu/README.md gives the command that made data/imu/mems_imu_sim_10min.bag."""
import gzip
import math
import sys

import rosbag
import rospy
from sensor_msgs.msg import Imu

G = 9.80665


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    source, target = sys.argv[1], sys.argv[2]
    seconds = float(sys.argv[3]) if len(sys.argv) == 4 else 600.0
    opener = gzip.open if source.endswith(".gz") else open
    rate = None
    with opener(source, "rt") as f, rosbag.Bag(target, "w", compression="bz2") as bag:
        for line in f:
            if line.startswith("# rate_hz:"):
                rate = float(line.split(":", 1)[1])
            if not line.startswith("#"):
                break
        columns = line.strip().split(",")
        if rate is None or len(columns) != 6 or not columns[0].startswith("gyro_x_dps"):
            sys.exit(f"{source}: not a record of rwcalc simulate --layout imu (rate_hz and six columns expected)")
        accel = G if columns[3].endswith("_g") else 1.0
        for k, line in enumerate(f):
            if k >= seconds * rate:
                break
            v = [float(x) for x in line.split(",")]
            m = Imu()
            m.header.seq = k
            m.header.frame_id = "imu_link"
            ns = round(k * 1e9 / rate)
            m.header.stamp = rospy.Time(1_700_000_000 + ns // 1_000_000_000, ns % 1_000_000_000)
            m.orientation_covariance[0] = -1.0  # no orientation (REP 145)
            m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z = (math.radians(x) for x in v[:3])
            m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z = (x * accel for x in v[3:])
            bag.write("/imu/data", m, m.header.stamp + rospy.Duration(0, 200_000))


if __name__ == "__main__":
    main()
