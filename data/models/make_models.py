#!/usr/bin/env python3
"""Writes the default models of data/models (see docs/models.md). Run from anywhere:
    python3 data/models/make_models.py
Coordinates in mm, y up (gravity along -y; docs/spec.md, section 2), facets counter-clockwise seen
from outside. The OFF files are polygonal; l_block_tri.obj is the L-block triangulated by ear
clipping with the same vertex order and the facets in the same order (polygon k becomes
consecutive triangles), so its features equal l_block.off's index for index."""
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def box(cx, cy, cz, sx, sy, sz):
    x0, y0, z0 = cx - sx / 2, cy - sy / 2, cz - sz / 2
    x1, y1, z1 = x0 + sx, y0 + sy, z0 + sz
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    f = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [2, 3, 7, 6], [1, 2, 6, 5], [0, 4, 7, 3]]
    return v, f


def prism(poly, z0, z1):
    """Extrudes a counter-clockwise xy polygon along z."""
    n = len(poly)
    v = [(x, y, z0) for x, y in poly] + [(x, y, z1) for x, y in poly]
    f = [list(reversed(range(n))), [n + i for i in range(n)]]
    f += [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n)]
    return v, f


def corner_block():
    # Floor 120 x 20 x 120 with walls 20 thick and 80 high along x = 0 and z = 0.
    v = [(0, 0, 0), (120, 0, 0), (120, 0, 120), (0, 0, 120),
         (0, 80, 0), (120, 80, 0), (120, 80, 20), (20, 80, 20), (20, 80, 120), (0, 80, 120),
         (20, 20, 20), (120, 20, 20), (120, 20, 120), (20, 20, 120)]
    f = [[0, 1, 2, 3],            # bottom, -y
         [9, 8, 7, 6, 5, 4],      # top of the walls (L-shaped), +y
         [13, 12, 11, 10],        # top of the floor, +y
         [0, 3, 9, 4],            # x = 0, -x
         [0, 4, 5, 1],            # z = 0, -z
         [1, 5, 6, 11, 12, 2],    # x = 120 (L-shaped), +x
         [3, 2, 12, 13, 8, 9],    # z = 120 (L-shaped), +z
         [10, 7, 8, 13],          # inner wall x = 20, +x
         [10, 11, 6, 7]]          # inner wall z = 20, +z
    return v, f


def hole_block():
    # 80 x 40 x 80 block with a 24 x 24 square hole through it along y. The top and bottom
    # faces are given as four trapezoids each (OFF has no facets with holes).
    v = [(0, 0, 0), (80, 0, 0), (80, 0, 80), (0, 0, 80),
         (0, 40, 0), (80, 40, 0), (80, 40, 80), (0, 40, 80),
         (28, 0, 28), (52, 0, 28), (52, 0, 52), (28, 0, 52),
         (28, 40, 28), (52, 40, 28), (52, 40, 52), (28, 40, 52)]
    f = []
    for i in range(4):
        j = (i + 1) % 4
        f.append([i, j, 8 + j, 8 + i])           # bottom ring, -y
        f.append([4 + i, 12 + i, 12 + j, 4 + j])  # top ring, +y
        f.append([i, 4 + i, 4 + j, j])            # outer side
        f.append([8 + i, 8 + j, 12 + j, 12 + i])  # hole wall, normal into the hole
    return v, f


def fmt(x):
    return ("%.6f" % x).rstrip("0").rstrip(".")


def write_off(name, v, f, comment):
    with open(os.path.join(HERE, name), "w") as out:
        out.write("OFF\n# %s\n%d %d 0\n" % (comment, len(v), len(f)))
        for p in v:
            out.write(" ".join(fmt(c) for c in p) + "\n")
        for poly in f:
            out.write("%d %s\n" % (len(poly), " ".join(map(str, poly))))


def ear_clip(v, poly):
    """Triangulates a planar simple polygon (3D points) counter-clockwise about its normal."""
    import itertools
    n = [0.0, 0.0, 0.0]
    for a, b in zip(poly, poly[1:] + poly[:1]):
        p, q = v[a], v[b]
        n[0] += p[1] * q[2] - p[2] * q[1]
        n[1] += p[2] * q[0] - p[0] * q[2]
        n[2] += p[0] * q[1] - p[1] * q[0]

    def orient(a, b, c):
        u = [v[b][i] - v[a][i] for i in range(3)]
        w = [v[c][i] - v[a][i] for i in range(3)]
        x = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
        return sum(x[i] * n[i] for i in range(3))

    rest, tris = list(poly), []
    while len(rest) > 3:
        for k in range(len(rest)):
            a, b, c = rest[k - 1], rest[k], rest[(k + 1) % len(rest)]
            if orient(a, b, c) <= 0:
                continue
            if any(orient(a, b, p) >= 0 and orient(b, c, p) >= 0 and orient(c, a, p) >= 0
                   for p in rest if p not in (a, b, c)):
                continue
            tris.append([a, b, c])
            rest.pop(k)
            break
        else:
            raise RuntimeError("no ear")
    tris.append(rest)
    return tris


def write_obj(name, v, f, comment):
    with open(os.path.join(HERE, name), "w") as out:
        out.write("# %s\n" % comment)
        for p in v:
            out.write("v " + " ".join(fmt(c) for c in p) + "\n")
        for poly in f:
            for t in ear_clip(v, poly):
                out.write("f " + " ".join(str(i + 1) for i in t) + "\n")


L = [(0, 0), (120, 0), (120, 20), (20, 20), (20, 80), (0, 80)]
write_off("cube.off", *box(0, 0, 0, 30, 30, 30), "A: cube, 30 mm, centred on its origin")
write_off("l_block.off", *prism(L, 0, 80), "B: L-shaped block, 120 x 80 x 80 mm, slab and wall 20 mm thick")
write_off("corner_block.off", *corner_block(), "B: corner block, floor 120 x 20 x 120 mm, two walls 20 mm thick, 80 mm high")
write_off("peg.off", *box(0, 0, 0, 20, 60, 20), "A: square peg 20 x 20 mm, 60 mm long along y, centred on its origin")
write_off("hole_block.off", *hole_block(), "B: block 80 x 40 x 80 mm with a 24 x 24 mm square through-hole along y")
write_obj("l_block_tri.obj", *prism(L, 0, 80), "B: l_block.off triangulated (same vertices, same facet order)")
