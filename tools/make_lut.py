#!/usr/bin/env python3
"""Writes data/luts/warm_film.cube, the sample grading LUT color.grade's tests and graphs use.

A 17-point 3D LUT (Adobe/Resolve .cube, red varying fastest) over display-encoded sRGB values: a gentle S-curve
on each channel (smoothstep blended 35 % with identity), shadows pushed toward teal and highlights toward
orange (split toning by luma), and 10 % less saturation. Made here, not downloaded; rerun to regenerate:

    python3 tools/make_lut.py [OUT]
"""
import sys

SIZE = 17


def look(r, g, b):
    def s_curve(v):
        return 0.65 * v + 0.35 * v * v * (3.0 - 2.0 * v)

    r, g, b = s_curve(r), s_curve(g), s_curve(b)
    luma = 0.2126 * r + 0.7152 * g + 0.0722 * b
    shadow = (1.0 - luma) ** 2
    highlight = luma ** 2
    r += 0.04 * highlight - 0.02 * shadow
    g += 0.01 * highlight + 0.01 * shadow
    b += -0.04 * highlight + 0.03 * shadow
    luma = 0.2126 * r + 0.7152 * g + 0.0722 * b
    r, g, b = (luma + 0.9 * (c - luma) for c in (r, g, b))
    return tuple(min(max(c, 0.0), 1.0) for c in (r, g, b))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "data/luts/warm_film.cube"
    lines = ['TITLE "vitrine warm film look (tools/make_lut.py)"', f"LUT_3D_SIZE {SIZE}",
             "DOMAIN_MIN 0.0 0.0 0.0", "DOMAIN_MAX 1.0 1.0 1.0"]
    n = SIZE - 1
    for bi in range(SIZE):
        for gi in range(SIZE):
            for ri in range(SIZE):
                lines.append("%.6f %.6f %.6f" % look(ri / n, gi / n, bi / n))
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
