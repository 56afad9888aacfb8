#!/usr/bin/env python3
"""Writes the scripted trajectories of data/trajectories/ for cfreplay (docs/spec.md, section 5b).

    python3 tools/cfreplay/make_trajectories.py [--rate 1000] [--out data/trajectories]

Every file is a CSV with the header t,tx,ty,tz,qw,qx,qy,qz (s, mm, unit quaternion of R,
x_B = R x_A + t), one row per servo tick (1 kHz by default). The levels are read from the
models in data/models/, not typed in: the cube's half size from cube.off, the floor height
and the inner walls from the faces of l_block.off and corner_block.off (the lowest +y face
above the bottom is the floor; the +x / +z faces nearest the origin are the inner walls).
A resting contact keeps its faces DIST = 0.5 mm apart (inside the 1 mm threshold), so
eq. (1) gives K (eps - 0.5) = 1.15 N per PC at the defaults.

Scenarios (the cube A against the L-block or the corner block B):
  cube_lblock_guarded.csv   guarded move down onto the floor, then rest        (MT1, MT2.a)
  cube_lblock_slide.csv     land, then slide along the floor and stop          (MT2.a/c, stick/slip)
  cube_lblock_corner.csv    land, slide into the inner corner, slide along it  (MT4, MT2.b)
  cube_lblock_rotate.csv    land, tip about a bottom edge and back             (MT3, MT2)
  cube_lblock_break.csv     from the corner, leave the wall, then lift off     (MT5, none)
  cube_corner_seat.csv      corner block: land, slide into x wall, then z wall (three f-f)
  cube_lblock_press.csv     a device pressing: from 1 mm above the floor to 10 mm inside it,
                            hold, slide 15 mm while pressed, pull out (for the proxy, docs/spec.md, section 6b:
                            `cfreplay --proxy off` renders nothing but gravity once A is
                            deeper than 1 mm)
"""
import argparse
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
MODELS = os.path.join(ROOT, "data", "models")
DIST = 0.5  # mm, resting distance of a face to the face it rests on (inside eps = 1 mm)


def read_off(path):
    with open(path) as f:
        toks = []
        for line in f:
            line = line.split("#", 1)[0].strip()
            if line:
                toks.extend(line.split())
    assert toks[0] == "OFF", path
    nv, nf = int(toks[1]), int(toks[2])
    p = 4
    v = []
    for _ in range(nv):
        v.append(tuple(float(x) for x in toks[p:p + 3]))
        p += 3
    faces = []
    for _ in range(nf):
        k = int(toks[p])
        faces.append([int(x) for x in toks[p + 1:p + 1 + k]])
        p += 1 + k
    return v, faces


def planes(v, faces):
    """(unit outward normal, offset) per face, by Newell's method."""
    out = []
    for f in faces:
        n = [0.0, 0.0, 0.0]
        for i in range(len(f)):
            a, b = v[f[i]], v[f[(i + 1) % len(f)]]
            n[0] += (a[1] - b[1]) * (a[2] + b[2])
            n[1] += (a[2] - b[2]) * (a[0] + b[0])
            n[2] += (a[0] - b[0]) * (a[1] + b[1])
        length = math.sqrt(sum(c * c for c in n))
        n = [c / length for c in n]
        out.append((n, sum(n[i] * v[f[0]][i] for i in range(3))))
    return out


def lowest(ps, axis, above):
    """Smallest offset of a face whose normal is +axis, above a given value."""
    return min(d for n, d in ps if n[axis] > 0.999 and d > above)


def quat_about(axis, angle):
    s = math.sin(angle / 2)
    return (math.cos(angle / 2), axis[0] * s, axis[1] * s, axis[2] * s)


def rot(q, p):
    w, x, y, z = q
    # R p for a unit quaternion
    tx, ty, tz = 2 * (y * p[2] - z * p[1]), 2 * (z * p[0] - x * p[2]), 2 * (x * p[1] - y * p[0])
    return (p[0] + w * tx + (y * tz - z * ty), p[1] + w * ty + (z * tx - x * tz), p[2] + w * tz + (x * ty - y * tx))


IDENTITY = (1.0, 0.0, 0.0, 0.0)


class Script:
    """Piecewise trajectory: moves of the translation (linear, smoothstep-free: constant
    speed as a guarded or compliant motion would be) and rotations about a fixed pivot."""

    def __init__(self, t0):
        self.t = tuple(t0)
        self.q = IDENTITY
        self.segments = []  # (duration, f(s) -> (t, q)) with s in [0, 1]

    def move(self, target, duration):
        a, q = self.t, self.q
        b = tuple(target)
        self.segments.append((duration, lambda s, a=a, b=b, q=q: (tuple(a[i] + s * (b[i] - a[i]) for i in range(3)), q)))
        self.t = b

    def hold(self, duration):
        self.move(self.t, duration)

    def rotate(self, axis, angle0, angle1, pivot_A, pivot_W, duration):
        """Turns about the world line through pivot_W along axis, with A's point pivot_A fixed
        there (rotation from the identity orientation by angle0 .. angle1)."""
        def f(s, axis=axis, a0=angle0, a1=angle1, pa=pivot_A, pw=pivot_W):
            q = quat_about(axis, a0 + s * (a1 - a0))
            r = rot(q, pa)
            return (tuple(pw[i] - r[i] for i in range(3)), q)
        self.segments.append((duration, f))
        self.t, self.q = f(1.0)

    def sample(self, rate):
        rows = []
        total = sum(d for d, _ in self.segments)
        n = int(round(total * rate))
        for k in range(n + 1):
            tk = k / rate
            acc = 0.0
            for d, f in self.segments:
                if tk <= acc + d + 1e-12 or f is self.segments[-1][1]:
                    s = min(max((tk - acc) / d, 0.0), 1.0) if d > 0 else 1.0
                    rows.append((tk, *f(s)))
                    break
                acc += d
        return rows


def write(path, rows):
    tmp = path + ".tmp"
    with open(tmp, "w") as out:
        out.write("t,tx,ty,tz,qw,qx,qy,qz\n")
        for t, p, q in rows:
            out.write("%.6f,%.6f,%.6f,%.6f,%.12f,%.12f,%.12f,%.12f\n" % (t, p[0], p[1], p[2], *q))
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rate", type=float, default=1000.0, help="servo rate, Hz (default 1000)")
    ap.add_argument("--out", default=os.path.join(ROOT, "data", "trajectories"))
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    cube_v, _ = read_off(os.path.join(MODELS, "cube.off"))
    h = max(p[0] for p in cube_v)  # half size; the cube is centred on its origin
    lv, lf = read_off(os.path.join(MODELS, "l_block.off"))
    lp = planes(lv, lf)
    floor = lowest(lp, 1, 0.0)   # L-block slab top (y = 20)
    wall = lowest(lp, 0, 0.0)    # inner wall (x = 20)
    cv, cfaces = read_off(os.path.join(MODELS, "corner_block.off"))
    cp = planes(cv, cfaces)
    c_floor, c_wall_x, c_wall_z = lowest(cp, 1, 0.0), lowest(cp, 0, 0.0), lowest(cp, 2, 0.0)

    rest_y = floor + h + DIST     # cube centre height resting on the floor
    corner_x = wall + h + DIST    # cube centre against the inner wall
    scripts = {}

    s = Script((70, rest_y + 10, 40))          # 10 mm above contact...
    s.move((70, rest_y, 40), 0.5)              # ...down at 20 mm/s
    s.hold(0.2)
    scripts["cube_lblock_guarded.csv"] = s

    s = Script((75, rest_y + 2, 40))
    s.move((74, rest_y, 40), 0.1)              # guarded, slightly oblique
    s.hold(0.1)
    s.move((54, rest_y, 45), 1.0)              # slide 20.6 mm at ~20 mm/s
    s.hold(0.2)
    s.move((54.3, rest_y, 45), 0.1)            # ease back: the held static friction relaxes
    s.hold(0.1)
    scripts["cube_lblock_slide.csv"] = s

    s = Script((50, rest_y + 2, 40))
    s.move((50, rest_y, 40), 0.1)
    s.hold(0.1)
    s.move((corner_x, rest_y, 40), 0.7)        # into the inner corner: gain the wall
    s.hold(0.1)
    s.move((corner_x, rest_y, 55), 0.75)       # slide along the corner line
    s.hold(0.1)
    scripts["cube_lblock_corner.csv"] = s

    s = Script((70, rest_y + 2, 40))
    s.move((70, rest_y, 40), 0.1)
    s.hold(0.1)
    pivot_A = (h, -h, 0.0)                      # A's bottom edge at +x (its middle)
    pivot_W = (70 + h, floor + DIST, 40.0)
    s.rotate((0.0, 0.0, 1.0), 0.0, -0.3, pivot_A, pivot_W, 1.0)   # tip up about it
    s.hold(0.1)
    s.rotate((0.0, 0.0, 1.0), -0.3, 0.0, pivot_A, pivot_W, 1.0)   # and back down
    s.hold(0.1)
    scripts["cube_lblock_rotate.csv"] = s

    s = Script((corner_x, rest_y + 2, 40))
    s.move((corner_x, rest_y, 40), 0.1)         # land in the corner
    s.hold(0.1)
    s.move((corner_x + 5, rest_y, 40), 0.25)   # leave the wall
    s.hold(0.1)
    s.move((corner_x + 5, rest_y + 5, 40), 0.25)  # lift off the floor
    s.hold(0.05)
    scripts["cube_lblock_break.csv"] = s

    touch_y = floor + h                         # cube centre when its bottom touches the floor
    s = Script((70, touch_y + 1, 40))
    s.move((70, touch_y - 10, 40), 0.5)         # 1 mm above to 10 mm inside, 22 mm/s
    s.hold(0.3)
    s.move((55, touch_y - 10, 40), 0.6)         # slide 15 mm while pressed, 25 mm/s
    s.hold(0.2)
    s.move((55, touch_y + 5, 40), 0.3)          # pull out
    s.hold(0.1)
    scripts["cube_lblock_press.csv"] = s

    c_rest_y = c_floor + h + DIST
    c_x, c_z = c_wall_x + h + DIST, c_wall_z + h + DIST
    s = Script((60, c_rest_y + 2, 60))
    s.move((60, c_rest_y, 60), 0.1)
    s.hold(0.1)
    s.move((c_x, c_rest_y, 60), 0.5)           # gain the x wall
    s.hold(0.1)
    s.move((c_x, c_rest_y, c_z), 0.5)          # gain the z wall: the three-face seat
    s.hold(0.2)
    scripts["cube_corner_seat.csv"] = s

    for name, sc in scripts.items():
        rows = sc.sample(args.rate)
        write(os.path.join(args.out, name), rows)
        print("%s: %d rows" % (name, len(rows)))


if __name__ == "__main__":
    main()
