#!/usr/bin/env python3
"""Tick-by-tick continuity of the rendered wrench (docs/force-model.md, "Continuity").

Drives the cube over the L-block on smooth device paths at constant speed (those of
tests/libcf/continuity_test.cpp), replays each with cfreplay (proxy on) and prints, per path,
the ticks, the ticks flagged as a discontinuity by design, the unflagged ticks past the bound
  |dF| <= 1.5 k (|dx| + r_A |dtheta|),  |dM| <= r_A |dF| + m g r_A |dtheta|
and the largest share of the bound on an unflagged tick, as a Markdown table.

Usage: scripts/continuity.py [--cfreplay build/tools/cfreplay]
                             [--graph data/graphs/cube_l_block.json]
"""
import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile

K = 2.3  # N/mm: eq. (1)'s K and the coupling's
R_A = 15 * math.sqrt(3)  # mm: the cube's radius about its centre
MG = 0.5 * 9.8  # N
SPEED = 10.0  # mm/s

PATHS = {
    "wall": [(45, 37, 40), (45, 33, 40), (34, 33, 40)],  # pressed 2 mm, slid into the wall
    "face": [(70, 38, 40), (70, 33, 40)],  # down onto the slab, pressed 2 mm
    "edge": [(128, 38, 40), (128, 33, 40)],  # down onto the slab's outer edge
    "corner": [(45, 45, 40), (34, 33, 40)],  # diagonally into the inner corner
    "along z, into the wall": [(40, 37, 20), (40, 33, 20), (34, 33, 60)],
}


def quaternion(tilt_deg, axis):
    h = math.radians(tilt_deg) / 2
    q = [math.cos(h), 0.0, 0.0, 0.0]
    q[1 + "xyz".index(axis)] = math.sin(h)
    return q


def write_path(path, points, tilt_deg, axis, rate):
    q = quaternion(tilt_deg, axis)
    rows, n_tick = ["t,tx,ty,tz,qw,qx,qy,qz"], 0
    for a, b in zip(points, points[1:]):
        n = max(1, round(math.dist(a, b) / SPEED * rate))
        for i in range(n):
            p = [a[j] + (b[j] - a[j]) * i / n for j in range(3)]
            rows.append("%.7f,%.9f,%.9f,%.9f,%.12f,%.12f,%.12f,%.12f"
                        % (n_tick / rate, *p, *q))
            n_tick += 1
    with open(path, "w") as f:
        f.write("\n".join(rows) + "\n")


def angle(q1, q2):
    return 2 * math.acos(min(1.0, abs(sum(a * b for a, b in zip(q1, q2)))))


def judge(traj_csv, out_csv):
    traj = list(csv.DictReader(open(traj_csv)))
    out = list(csv.DictReader(open(out_csv)))
    flagged = past = 0
    worst = 0.0
    for i in range(1, len(out)):
        if out[i]["discontinuities"]:
            flagged += 1
            continue
        a, b = traj[i - 1], traj[i]
        dx = math.dist([float(a[c]) for c in "tx ty tz".split()],
                       [float(b[c]) for c in "tx ty tz".split()])
        dth = angle([float(a[c]) for c in "qw qx qy qz".split()],
                    [float(b[c]) for c in "qw qx qy qz".split()])
        dF = math.dist([float(out[i - 1][c]) for c in ("Fx", "Fy", "Fz")],
                       [float(out[i][c]) for c in ("Fx", "Fy", "Fz")])
        dM = math.dist([float(out[i - 1][c]) for c in ("Mx", "My", "Mz")],
                       [float(out[i][c]) for c in ("Mx", "My", "Mz")])
        bF = 1.5 * K * (dx + R_A * dth) + 1e-9
        bM = R_A * dF + MG * R_A * dth + 1e-6
        share = max(dF / bF, dM / bM)
        worst = max(worst, share)
        past += share > 1
    return len(out), flagged, past, worst


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap.add_argument("--cfreplay", default=os.path.join(root, "build/tools/cfreplay"))
    ap.add_argument("--graph", default=os.path.join(root, "data/graphs/cube_l_block.json"))
    args = ap.parse_args()
    tilts = [(0, "z"), (0.1, "z"), (0.5, "x"), (1, "y"), (2, "z")]
    print("| path | tilt | rate | ticks | flagged | unflagged past the bound | largest share |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as tmp:
        traj, out = os.path.join(tmp, "p.csv"), os.path.join(tmp, "o.csv")
        for name, points in PATHS.items():
            for tilt, axis in tilts:
                for rate in (1000, 10000):
                    write_path(traj, points, tilt, axis, rate)
                    subprocess.run([args.cfreplay, "--graph", args.graph, "--trajectory", traj,
                                    "-o", out], check=True, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
                    n, flagged, past, worst = judge(traj, out)
                    print("| %s | %g deg about %s | %d kHz | %d | %d | %d | %.2f |"
                          % (name, tilt, axis, rate // 1000, n, flagged, past, worst))
    return 0


if __name__ == "__main__":
    sys.exit(main())
