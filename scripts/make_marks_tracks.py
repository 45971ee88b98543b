#!/usr/bin/env python3
"""Writes the track files of the marks scenes that have many keyframes
(drift marks --track; see docs/marks.md) into data/scenes/: a barefoot walk
across wind ripples (paper 000, fig. 13), tyre tracks in mud (fig. 16) and
objects dragged on sand (fig. 14). Deterministic; run from the repository
root: python3 scripts/make_marks_tracks.py"""
import math
import os

OUT = os.path.join(os.path.dirname(__file__), "..", "data", "scenes")


def keyframe(t, p, rotation=None):
    s = "[[objects.keyframes]]\ntime = %.3f\nposition = [%.4f, %.4f, %.4f]\n" % (t, *p)
    if rotation:
        s += "rotation = [%.3f, %.3f, %.3f]\n" % rotation
    return s


def walk(path, comment, material, start, heading, prints, spacing, lift, sink,
         meshes=("foot_left.obj", "foot.obj"), pitch=0.0, extra=""):
    """Footprints alternating left and right from `start` (CRS x, y) along
    `heading` (degrees counter-clockwise from east), `spacing` metres apart,
    each its own object following the ground: down, held, lifted; soles
    pitched by `pitch` degrees (toe up) to lie on a slope."""
    out = [f"# {comment}\n# made by scripts/make_marks_tracks.py\nstep = 0.05\n{extra}"]
    if material:
        out.append(f'material = "{material}"\n')
    h = math.radians(heading)
    along, across = (math.cos(h), math.sin(h)), (-math.sin(h), math.cos(h))
    for k in range(prints):
        left = k % 2 == 0
        side = 0.09 if left else -0.09
        x = start[0] + k * spacing * along[0] + side * across[0]
        y = start[1] + k * spacing * along[1] + side * across[1]
        t = 0.4 * k
        out.append("\n[[objects]]\nmesh = \"../objects/%s\"\nfollow_ground = true\n"
                   % (meshes[0] if left else meshes[1]))
        turn = (heading, pitch, 0.0) if heading or pitch else None
        for dt, z in ((0.0, lift), (0.15, -sink), (0.35, -sink), (0.5, lift)):
            out.append(keyframe(t + dt, (x, y, z), turn))
    with open(os.path.join(OUT, path), "w") as f:
        f.write("".join(out))
    print(os.path.join(OUT, path))


def tyres(path):
    """A pair of tyres 1.5 m apart rolling 3 m east through mud, 3 cm deep,
    keyframes every 10 cm (the roll is about +y: pitch = -distance / radius)."""
    radius, sink = 0.33, 0.03
    out = ["# Tyre tracks in mud (paper 000, fig. 16): two treaded tyres rolling east.\n"
           "# made by scripts/make_marks_tracks.py\nstep = 0.1\nmaterial = \"mud\"\n"]
    for y in (-1.17, -2.67):
        out.append("\n[[objects]]\nmesh = \"../objects/tyre.obj\"\n")
        for k in range(31):
            x = 0.4 + 0.1 * k
            out.append(keyframe(0.1 * k, (x, y, radius - sink),
                                (0.0, -math.degrees((x - 0.4) / radius), 0.0)))
    with open(os.path.join(OUT, path), "w") as f:
        f.write("".join(out))
    print(os.path.join(OUT, path))


if __name__ == "__main__":
    walk("marks_walk_ripples.toml",
         "Bare footprints across wind ripples (paper 000, fig. 13): five steps east,\n"
         "# across the crests of a ripple field from drift dunes (wind from the west).",
         "sand", (0.45, -1.54), 0.0, 5, 0.6, 0.05, 0.02)
    walk("marks_walk_snow.toml",
         "Shoe prints up a snow slope on Yarigatake: eight steps north (uphill) on\n"
         "# 20 cm of snow from drift snow fall; material from the snow-depth raster.",
         None, (746633.0, 4032748.5), 90.0, 8, 0.55, 0.05, 0.10,
         meshes=("shoe.obj", "shoe.obj"), pitch=15.0)
    tyres("marks_tyres.toml")
