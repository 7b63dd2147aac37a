#!/usr/bin/env python3
"""A static IMU recorded as a ROS 1 bag (uncompressed chunks) and as its `rostopic echo -p` CSV,
for the bag row of bench/run-benchmarks.sh: white noise at RATE Hz for HOURS, stamps 1/RATE s apart
from Unix time 1.7e9 s, received 0.2 ms later. The bag is laid out as ROS 1 bag format 2.0 writes
it (bag header padded to 4096 bytes, chunks of 10000 messages with their connection record, then
the index). Needs python3-numpy.

Usage: make_ros_imu.py BAG CSV [--hours H] [--rate HZ]"""
import argparse
import struct

import numpy as np

TOPIC, TYPE, FRAME = b"/imu/data", b"sensor_msgs/Imu", b"imu_link"
MD5 = b"6a62c6daae103f4ff57a132d6f95cec2"
PER_CHUNK = 10000


def field(name, value):
    return struct.pack("<I", len(name) + 1 + len(value)) + name + b"=" + value


def record(header, data):
    return struct.pack("<I", len(header)) + header + struct.pack("<I", len(data)) + data


def op(o):
    return field(b"op", bytes([o]))


CONNECTION = record(op(7) + field(b"conn", struct.pack("<I", 0)) + field(b"topic", TOPIC),
                    field(b"topic", TOPIC) + field(b"type", TYPE) + field(b"md5sum", MD5)
                    + field(b"message_definition", b""))

MESSAGE = np.dtype([("hl", "<u4"), ("op", "S8"), ("conn", "S13"), ("time_f", "S9"), ("sec", "<u4"),
                    ("nsec", "<u4"), ("dl", "<u4"), ("seq", "<u4"), ("ssec", "<u4"), ("snsec", "<u4"),
                    ("flen", "<u4"), ("frame", "S8"), ("d", "<f8", (37,))])


def messages(first, n, rate, rng):
    m = np.zeros(n, MESSAGE)
    k = np.arange(first, first + n, dtype=np.int64)
    stamp = 1_700_000_000 * 10**9 + (k * 10**9) // int(rate)
    receive = stamp + 200_000
    m["hl"] = 38
    m["op"] = op(2)
    m["conn"] = field(b"conn", struct.pack("<I", 0))
    m["time_f"] = struct.pack("<I", 13) + b"time="
    m["sec"], m["nsec"] = receive // 10**9, receive % 10**9
    m["dl"] = 16 + len(FRAME) + 37 * 8
    m["seq"] = k
    m["ssec"], m["snsec"] = stamp // 10**9, stamp % 10**9
    m["flen"] = len(FRAME)
    m["frame"] = FRAME
    m["d"][:, 3] = 1.0
    m["d"][:, 13:16] = rng.normal(0, 1e-3, (n, 3))
    m["d"][:, 25:28] = rng.normal(0, 2e-2, (n, 3)) + np.array([0, 0, 9.80665])
    return m, stamp, receive


def csv_lines(m, stamp, receive):
    g, a = m["d"][:, 13:16], m["d"][:, 25:28]
    return "".join(f"{r},{s},{q},imu_link,0.0,0.0,0.0,1.0,{x!r},{y!r},{z!r},{u!r},{v!r},{w!r}\n"
                   for r, s, q, (x, y, z), (u, v, w) in zip(receive.tolist(), m["seq"].tolist(), stamp.tolist(),
                                                         g.tolist(), a.tolist()))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("bag")
    p.add_argument("csv")
    p.add_argument("--hours", type=float, default=24)
    p.add_argument("--rate", type=float, default=200)
    a = p.parse_args()
    total = int(round(a.hours * 3600 * a.rate))
    rng = np.random.default_rng(5)
    chunks = []
    with open(a.bag, "wb") as bag, open(a.csv, "w") as csv:
        csv.write("%time,field.header.seq,field.header.stamp,field.header.frame_id,field.orientation.x,"
                  "field.orientation.y,field.orientation.z,field.orientation.w,field.angular_velocity.x,"
                  "field.angular_velocity.y,field.angular_velocity.z,field.linear_acceleration.x,"
                  "field.linear_acceleration.y,field.linear_acceleration.z\n")
        bag.write(b"#ROSBAG V2.0\n" + b"\0" * 4096)  # the bag header, written last
        for first in range(0, total, PER_CHUNK):
            n = min(PER_CHUNK, total - first)
            m, stamp, receive = messages(first, n, a.rate, rng)
            data = CONNECTION + m.tobytes()
            chunks.append((bag.tell(), n))
            bag.write(record(op(5) + field(b"compression", b"none") + field(b"size", struct.pack("<I", len(data))),
                             data))
            csv.write(csv_lines(m, stamp, receive))
        index_pos = bag.tell()
        bag.write(CONNECTION)
        for pos, n in chunks:
            bag.write(record(op(6) + field(b"ver", struct.pack("<I", 1)) + field(b"chunk_pos", struct.pack("<Q", pos))
                             + field(b"start_time", struct.pack("<Q", 0)) + field(b"end_time", struct.pack("<Q", 0))
                             + field(b"count", struct.pack("<I", 1)), struct.pack("<II", 0, n)))
        head = (op(3) + field(b"index_pos", struct.pack("<Q", index_pos)) + field(b"conn_count", struct.pack("<I", 1))
                + field(b"chunk_count", struct.pack("<I", len(chunks))))
        bag.seek(13)
        bag.write(record(head, b" " * (4096 - 8 - len(head))))


if __name__ == "__main__":
    main()
