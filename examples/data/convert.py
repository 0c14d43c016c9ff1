#!/usr/bin/env python3
"""Converts the trajectories in ../../../shared/data (JSON) into the formats
bireg_fit reads. Standard library only; run from this folder:

    python3 convert.py /path/to/shared/data

so3_xio_imu_window.json      -> so3_xio_imu_window.csv   (matrix format, t in s)
se3_deepmimic_walk_root.json -> se3_deepmimic_walk.tum   (TUM format, t in s)
"""
import json
import math
import os
import sys


def quaternion(r):
    """Unit quaternion (w, x, y, z) of a rotation matrix (largest component first)."""
    trace = r[0][0] + r[1][1] + r[2][2]
    candidates = [trace, r[0][0], r[1][1], r[2][2]]
    k = candidates.index(max(candidates))
    if k == 0:
        s = 2 * math.sqrt(1 + trace)
        q = (s / 4, (r[2][1] - r[1][2]) / s, (r[0][2] - r[2][0]) / s, (r[1][0] - r[0][1]) / s)
    elif k == 1:
        s = 2 * math.sqrt(1 + r[0][0] - r[1][1] - r[2][2])
        q = ((r[2][1] - r[1][2]) / s, s / 4, (r[0][1] + r[1][0]) / s, (r[0][2] + r[2][0]) / s)
    elif k == 2:
        s = 2 * math.sqrt(1 - r[0][0] + r[1][1] - r[2][2])
        q = ((r[0][2] - r[2][0]) / s, (r[0][1] + r[1][0]) / s, s / 4, (r[1][2] + r[2][1]) / s)
    else:
        s = 2 * math.sqrt(1 - r[0][0] - r[1][1] + r[2][2])
        q = ((r[1][0] - r[0][1]) / s, (r[0][2] + r[2][0]) / s, (r[1][2] + r[2][1]) / s, s / 4)
    return q if q[0] >= 0 else tuple(-x for x in q)


def main(source):
    imu = json.load(open(os.path.join(source, "so3_xio_imu_window.json")))
    with open("so3_xio_imu_window.csv", "w") as out:
        out.write("# x-IMU on-board orientation, 0.75 s window, 128 Hz (see README.md)\n")
        out.write("# t [s], R00, R01, R02, R10, R11, R12, R20, R21, R22\n")
        for t, r in zip(imu["t_raw"], imu["f"]):
            out.write(", ".join([repr(t)] + [repr(x) for row in r for x in row]) + "\n")

    walk = json.load(open(os.path.join(source, "se3_deepmimic_walk_root.json")))
    with open("se3_deepmimic_walk.tum", "w") as out:
        out.write("# DeepMimic humanoid walk, pelvis pose, y up (see README.md)\n")
        out.write("# timestamp [s] tx ty tz [m] qx qy qz qw\n")
        for t, g in zip(walk["t_raw"], walk["f"]):
            w, x, y, z = quaternion([row[:3] for row in g[:3]])
            values = [t, g[0][3], g[1][3], g[2][3], x, y, z, w]
            out.write(" ".join(repr(v) for v in values) + "\n")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "../../../shared/data")
