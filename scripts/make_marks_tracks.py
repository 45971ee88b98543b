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


def walk(path, comment, material, x0, y, prints, stride, lift, sink, extra=""):
    """Footprints alternating left and right along +x, each its own object
    following the ground: down, held, lifted."""
    out = [f"# {comment}\n# made by scripts/make_marks_tracks.py\nstep = 0.05\n{extra}"]
    if material:
        out.append(f'material = "{material}"\n')
    for k in range(prints):
        left = k % 2 == 0
        x, side = x0 + k * stride / 2, (0.09 if left else -0.09)
        t = 0.4 * k
        out.append("\n[[objects]]\nmesh = \"../objects/%s\"\nfollow_ground = true\n"
                   % ("foot_left.obj" if left else "foot.obj"))
        out.append(keyframe(t, (x, y + side, lift)))
        out.append(keyframe(t + 0.15, (x, y + side, -sink)))
        out.append(keyframe(t + 0.35, (x, y + side, -sink)))
        out.append(keyframe(t + 0.5, (x, y + side, lift)))
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
         "Bare footprints across wind ripples (paper 000, fig. 13): six steps east,\n"
         "# across the crests of a ripple field from drift dunes (wind from the west).",
         "sand", 0.6, -1.92, 6, 1.1, 0.05, 0.012)
    tyres("marks_tyres.toml")
