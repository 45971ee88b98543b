#!/usr/bin/env python3
"""Writes the objects that leave marks (paper 000) in data/objects/: a shoe with
a treaded sole, a bare foot, a treaded tyre, a ball and block letters. z up,
metres, faces counter-clockwise seen from outside. Soles (shoe, foot, letters)
have their origin at the centre of the sole, at its lowest point; the ball and
the tyre at their centre (they roll about it). Deterministic; run from the
repository root: python3 scripts/make_marks_objects.py"""
import math
import os

import make_objects

OUT = os.path.join(os.path.dirname(__file__), "..", "data", "objects")


class Obj(make_objects.Obj):
    """make_objects' mesh builder, written at the finer precision marks need."""

    def write(self, name, comment):
        path = os.path.join(OUT, name)
        with open(path, "w") as out:
            out.write(f"# {comment}\n# made by scripts/make_marks_objects.py\n")
            for p in self.v:
                out.write("v %.6f %.6f %.6f\n" % p)
            for f in self.f:
                out.write("f %d %d %d\n" % f)
        print(f"{path}: {len(self.v)} vertices, {len(self.f)} triangles")


def sole(inside, bottom, x0, x1, y0, y1, step, top):
    """A closed solid over the grid cells whose centres are `inside`: the
    underside at bottom(x, y), a flat top at `top`, vertical walls between."""
    nx, ny = round((x1 - x0) / step), round((y1 - y0) / step)
    o = Obj()
    xs = [x0 + i * (x1 - x0) / nx for i in range(nx + 1)]
    ys = [y0 + j * (y1 - y0) / ny for j in range(ny + 1)]
    cell = [[inside(xs[i] + 0.5 * (xs[1] - xs[0]), ys[j] + 0.5 * (ys[1] - ys[0]))
             for j in range(ny)] for i in range(nx)]
    lo, hi = {}, {}

    def v(i, j, upper):
        table = hi if upper else lo
        if (i, j) not in table:
            table[(i, j)] = o.vert((xs[i], ys[j], top if upper else bottom(xs[i], ys[j])))
        return table[(i, j)]

    def used(i, j):
        return 0 <= i < nx and 0 <= j < ny and cell[i][j]

    for i in range(nx):
        for j in range(ny):
            if not cell[i][j]:
                continue
            corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]  # counter-clockwise
            a, b, c, d = (v(*k, False) for k in corners)
            o.quad(a, d, c, b)  # underside, facing down
            a, b, c, d = (v(*k, True) for k in corners)
            o.quad(a, b, c, d)  # top, facing up
            for k, (di, dj) in enumerate([(0, -1), (1, 0), (0, 1), (-1, 0)]):
                if used(i + di, j + dj):
                    continue
                p, q = corners[k], corners[(k + 1) % 4]
                o.quad(v(*p, False), v(*q, False), v(*q, True), v(*p, True))
    return o


def shoe():
    """A 28 cm shoe sole (x forward, heel at -x) with chevron lugs 5 mm deep, a
    heel block, and the toe springing up 1.5 cm over its last 5 cm."""
    length, width = 0.28, 0.10

    def half_width(x):  # x in [-0.14, 0.14]
        t = (x + length / 2) / length
        if t < 0.25:  # heel, round
            return 0.038 * math.sqrt(max(0.0, 1 - ((0.25 - t) / 0.25) ** 2)) + 0.002
        if t < 0.55:  # waist
            return 0.040 - 0.006 * math.sin(math.pi * (t - 0.25) / 0.30)
        s = (t - 0.55) / 0.45  # forefoot and round toe
        return (0.046 - 0.006 * s) * math.sqrt(max(0.0, 1 - s ** 4))

    def inside(x, y):
        return abs(y) < half_width(x)

    def bottom(x, y):
        z = 0.0
        toe = x - (length / 2 - 0.05)
        if toe > 0:
            z += 0.015 * (toe / 0.05) ** 2
        t = (x + length / 2) / length
        if 0.30 < t < 0.42:  # the gap in front of the heel block
            z += 0.006
        phase = (x * 1.0 + abs(y) * 0.8) / 0.016  # chevrons pointing forward
        if phase - math.floor(phase) < 0.35:
            z += 0.005
        return z

    return sole(inside, bottom, -length / 2, length / 2, -width / 2, width / 2, 0.0028, 0.05)


def foot():
    """A 26 cm bare right foot: heel, the arch lifted on the inside (+y), the
    ball, and five toes whose pads press apart from the ball."""
    toes = [(0.095, 0.030, 0.016), (0.104, 0.005, 0.011), (0.099, -0.014, 0.010),
            (0.090, -0.029, 0.009), (0.078, -0.041, 0.009)]  # x, y, radius

    def in_toe(x, y):
        return any((x - tx) ** 2 + (y - ty) ** 2 < r * r for tx, ty, r in toes)

    def sole_half(x):
        t = (x + 0.13) / 0.20
        if t < 0 or t > 1:
            return None
        if t < 0.3:
            w = 0.033 * math.sqrt(max(0.0, 1 - ((0.3 - t) / 0.3) ** 2)) + 0.001
            return (-w, w)
        if t < 0.65:  # the arch narrows on the inside
            return (-0.036, 0.034 - 0.022 * math.sin(math.pi * (t - 0.3) / 0.35))
        s = (t - 0.65) / 0.35
        return (-0.040 * math.sqrt(max(0.0, 1 - s ** 3)), 0.045 * math.sqrt(max(0.0, 1 - s ** 3)))

    def inside(x, y):
        span = sole_half(x)
        return in_toe(x, y) or (span is not None and span[0] < y < span[1])

    def bottom(x, y):
        if in_toe(x, y) and not (sole_half(x) and sole_half(x)[0] < y < sole_half(x)[1]):
            return 0.002
        t = (x + 0.13) / 0.20
        arch = 0.0
        if 0.3 < t < 0.7 and y > -0.01:  # the arch, highest on the inside
            arch = 0.014 * math.sin(math.pi * (t - 0.3) / 0.4) * min(1.0, (y + 0.01) / 0.03)
        return arch

    return sole(inside, bottom, -0.135, 0.125, -0.05, 0.05, 0.0025, 0.06)


def mirrored(o):
    """The mirror image across the x-z plane (a left foot from a right one)."""
    m = Obj()
    m.v = [(x, -y, z) for x, y, z in o.v]
    m.f = [(a, c, b) for a, b, c in o.f]  # mirroring turns faces inside out
    return m


def tyre():
    """A 66 cm tyre, 20 cm wide, axle along y, origin at its centre, with
    transverse tread blocks 12 mm deep in two staggered rows."""
    radius, half, groove = 0.33, 0.10, 0.012
    na, nw = 240, 24
    o = Obj()

    def r_at(a, w):
        row = 0 if w < 0 else 0.5
        phase = (a / (2 * math.pi) * 40 + row) % 1.0
        edge = abs(w) > half - 0.015  # rounded shoulders
        return radius - (groove if phase < 0.4 else 0.0) - (0.008 if edge else 0.0)

    ring = [[o.vert((r_at(2 * math.pi * i / na, -half + 2 * half * j / nw) * math.sin(2 * math.pi * i / na),
                     -half + 2 * half * j / nw,
                     r_at(2 * math.pi * i / na, -half + 2 * half * j / nw) * math.cos(2 * math.pi * i / na)))
             for j in range(nw + 1)] for i in range(na)]
    for i in range(na):
        k = (i + 1) % na
        for j in range(nw):
            o.quad(ring[i][j], ring[k][j], ring[k][j + 1], ring[i][j + 1])
    for side, j in ((-1, 0), (1, nw)):  # side walls closed by a fan
        centre = o.vert((0.0, -half if side < 0 else half, 0.0))
        for i in range(na):
            k = (i + 1) % na
            if side < 0:
                o.tri(centre, ring[k][j], ring[i][j])
            else:
                o.tri(centre, ring[i][j], ring[k][j])
    return o


def ball(radius=0.1, rings=24, segments=48):
    o = Obj()
    top = o.vert((0.0, 0.0, radius))
    rows = []
    for i in range(1, rings):
        th = math.pi * i / rings
        rows.append([o.vert((radius * math.sin(th) * math.cos(2 * math.pi * j / segments),
                             radius * math.sin(th) * math.sin(2 * math.pi * j / segments),
                             radius * math.cos(th))) for j in range(segments)])
    bottom = o.vert((0.0, 0.0, -radius))
    for j in range(segments):
        k = (j + 1) % segments
        o.tri(top, rows[0][j], rows[0][k])
        o.tri(bottom, rows[-1][k], rows[-1][j])
    for r in range(len(rows) - 1):
        for j in range(segments):
            k = (j + 1) % segments
            o.quad(rows[r][j], rows[r + 1][j], rows[r + 1][k], rows[r][k])
    return o


FONT = {  # 5 x 7, top row first
    "S": ["01111", "10000", "10000", "01110", "00001", "00001", "11110"],
    "A": ["01110", "10001", "10001", "11111", "10001", "10001", "10001"],
    "N": ["10001", "11001", "10101", "10011", "10001", "10001", "10001"],
    "D": ["11110", "10001", "10001", "10001", "10001", "10001", "11110"],
    "M": ["10001", "11011", "10101", "10101", "10001", "10001", "10001"],
    "U": ["10001", "10001", "10001", "10001", "10001", "10001", "01110"],
    "O": ["01110", "10001", "10001", "10001", "10001", "10001", "01110"],
    "W": ["10001", "10001", "10001", "10101", "10101", "11011", "10001"],
}


def word(text, pixel=0.02, depth=0.04):
    """Block letters 14 cm high, their undersides flat at z = 0."""
    width = len(text) * 6 - 1
    on = set()
    for n, ch in enumerate(text):
        for row, bits in enumerate(FONT[ch]):
            for col, bit in enumerate(bits):
                if bit == "1":
                    on.add((n * 6 + col, 6 - row))

    def inside(x, y):
        return (math.floor(x / pixel + width / 2), math.floor(y / pixel + 3.5)) in on

    return sole(inside, lambda x, y: 0.0, -width / 2 * pixel, width / 2 * pixel,
                -3.5 * pixel, 3.5 * pixel, pixel, depth)


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    shoe().write("shoe.obj", "shoe sole with chevron tread, 28 cm, x forward, origin under the sole")
    foot().write("foot.obj", "bare right foot, 26 cm, x forward, origin under the sole")
    mirrored(foot()).write("foot_left.obj", "bare left foot, 26 cm, x forward, origin under the sole")
    tyre().write("tyre.obj", "treaded tyre, 66 cm, axle along y, origin at the centre")
    ball().write("ball.obj", "ball, 20 cm, origin at the centre")
    for w in ("SAND", "MUD", "SNOW"):
        word(w).write(f"letters_{w.lower()}.obj", f"block letters '{w}', 14 cm high, origin under them")
