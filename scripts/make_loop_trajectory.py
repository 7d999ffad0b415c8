#!/usr/bin/env python3
"""Writes a TUM-format body trajectory (world_from_body) that circles the Vicon-room scene
several times with the camera looking outward, for `pkslam simulate --trajectory`.

Usage: make_loop_trajectory.py OUT.txt [--laps 2] [--lap-seconds 25] [--radius 1.2]
The loop-closing tests and the issue-6 experiments use the defaults."""
import argparse
import math


# EuRoC cam0 body_from_camera (the simulator's camera geometry, sensor.yaml T_BS).
BODY_FROM_CAMERA = ([
    [0.014865542982048563, -0.999880929698284, 0.004140296794206974, -0.0216401454975],
    [0.9995572490081694, 0.014967213324960649, 0.025715529947981965, -0.064676986768],
    [-0.025774436697419814, 0.0037561883579469834, 0.9996607271779513, 0.00981073058949],
    [0.0, 0.0, 0.0, 1.0]])


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def rigid_inverse(m):
    r = [[m[j][i] for j in range(3)] for i in range(3)]
    t = [-sum(r[i][k] * m[k][3] for k in range(3)) for i in range(3)]
    return [r[0] + [t[0]], r[1] + [t[1]], r[2] + [t[2]], [0.0, 0.0, 0.0, 1.0]]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def normalised(v):
    n = math.sqrt(sum(x * x for x in v))
    return [x / n for x in v]


def quaternion(r):
    """Rotation matrix -> (qx, qy, qz, qw)."""
    w = math.sqrt(max(0.0, 1.0 + r[0][0] + r[1][1] + r[2][2])) / 2.0
    if w > 1e-3:
        return ((r[2][1] - r[1][2]) / (4 * w), (r[0][2] - r[2][0]) / (4 * w),
                (r[1][0] - r[0][1]) / (4 * w), w)
    i = max(range(3), key=lambda d: r[d][d])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1.0 + r[i][i] - r[j][j] - r[k][k]) * 2.0
    q = [0.0, 0.0, 0.0, (r[k][j] - r[j][k]) / s]
    q[i] = s / 4.0
    q[j] = (r[j][i] + r[i][j]) / s
    q[k] = (r[k][i] + r[i][k]) / s
    return tuple(q)


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("out")
    p.add_argument("--laps", type=float, default=2.0)
    p.add_argument("--lap-seconds", type=float, default=25.0)
    p.add_argument("--radius", type=float, default=1.2)
    p.add_argument("--extra-seconds", type=float, default=2.0,
                   help="beyond the last lap, so the end revisits the start")
    p.add_argument("--rate", type=float, default=200.0)
    a = p.parse_args()
    duration = a.laps * a.lap_seconds + a.extra_seconds
    camera_from_body = rigid_inverse(BODY_FROM_CAMERA)
    with open(a.out, "w") as f:
        f.write("# timestamp tx ty tz qx qy qz qw (world_from_body)\n")
        n = int(round(duration * a.rate)) + 1
        for k in range(n):
            t = k / a.rate
            theta = 2 * math.pi * t / a.lap_seconds
            centre = [a.radius * math.cos(theta), a.radius * math.sin(theta),
                      1.4 + 0.1 * math.sin(3 * theta)]
            # Outward, turned 25 deg towards the direction of travel, slightly down.
            yaw = theta + math.radians(25)
            forward = normalised([math.cos(yaw), math.sin(yaw), -0.15])
            right = normalised(cross(forward, [0.0, 0.0, 1.0]))
            down = cross(forward, right)
            world_from_camera = [[right[i], down[i], forward[i], centre[i]] for i in range(3)]
            world_from_camera.append([0.0, 0.0, 0.0, 1.0])
            world_from_body = matmul(world_from_camera, camera_from_body)
            q = quaternion(world_from_body)
            tx, ty, tz = (world_from_body[i][3] for i in range(3))
            f.write(f"{t:.6f} {tx:.9f} {ty:.9f} {tz:.9f} {q[0]:.9f} {q[1]:.9f} {q[2]:.9f} "
                    f"{q[3]:.9f}\n")


if __name__ == "__main__":
    main()
