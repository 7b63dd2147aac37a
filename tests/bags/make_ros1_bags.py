#!/usr/bin/python3
"""Writes rosbag_bz2.bag and rosbag_lz4.bag here with Debian's python3-rosbag (ROS's own writer,
not rwcalc's): 120 sensor_msgs/Imu messages on /imu/data at 200 Hz, stamps from 1.7e9 s, received
0.25 ms later, and 12 std_msgs/String messages on /status. The channels follow a formula that
tests/test_bag.cpp computes again: gyro axis a at sample k is 1e-3 sin(0.1 k + a), accelerometer
axis a is 1e-2 cos(0.07 k + a) (+ 9.80665 on z). Run once; the outputs are committed (python3-rosbag
pulls ROS libraries, which the build does not need)."""
import math

import rosbag
import rospy
from sensor_msgs.msg import Imu
from std_msgs.msg import String

for compression in ("bz2", "lz4"):
    with rosbag.Bag(f"rosbag_{compression}.bag", "w", compression=compression, chunk_threshold=16000) as bag:
        for k in range(120):
            m = Imu()
            m.header.seq = k
            m.header.frame_id = "imu_link"
            m.header.stamp = rospy.Time(1_700_000_000 + k // 200, (k % 200) * 5_000_000)
            m.orientation.w = 1.0
            m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z = (
                1e-3 * math.sin(0.1 * k + a) for a in range(3))
            m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z = (
                1e-2 * math.cos(0.07 * k + a) + (9.80665 if a == 2 else 0.0) for a in range(3))
            bag.write("/imu/data", m, m.header.stamp + rospy.Duration(0, 250_000))
            if k % 10 == 0:
                bag.write("/status", String(data="ok"), m.header.stamp)
