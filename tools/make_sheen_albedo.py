#!/usr/bin/env python3
"""Writes shaders/common/sheen_albedo.h: the directional albedo E(NoV, r) of KHR_materials_sheen's lobe.

E(v) = integral over the hemisphere of D_charlie(h) V_charlie(v, l) (n.l) dl, the sheen lobe's reflectance for a
white sheen colour, as common/brdf.glsl evaluates it (sheenCharlieD, sheenVisibility: the spec's Charlie
distribution of alpha = max(r^2, 0.01) with its fitted Charlie visibility). The layering scales the base by
1 - max(sheenColor) E(n.v) (albedo scaling, the spec's). E is integrated on a 32 x 32 grid, u = sqrt(NoV) (i / 31: the
grazing end, where E changes fastest, gets the rows) by r (j / 31), each entry a midpoint-rule integral over
(cos theta_l, phi_l), 192 x 192 over the half hemisphere (the lobe is symmetric in phi), converged to 1e-4; log E is
then fitted by a polynomial of total degree 8 in (2u - 1, 2 max(r, 0.1) - 1), weighted by E (so about the absolute
error). A polynomial, not the table: a 1024- (or 256-) entry constant array indexed at run time made lavapipe's
compute shader compiler take minutes. tests/unit/shading/brdf_test.cpp integrates again at points between the grid's.
The same expression serves GLSL and C++ (core/shading/brdf.cpp): the header is a macro. Made here, not downloaded;
rerun to regenerate (a few minutes):

    python3 tools/make_sheen_albedo.py [OUT]
"""
import math
import sys

from horner_macro import horner_macro

SIZE = 32
MIN_ALPHA = 0.01  # common/brdf.glsl kMinSheenAlpha
MIN_NOV = 0.0005  # the u = 0 row: E at NoV = 0 is a limit; this is as close as the shaders get
MIN_R = 0.1  # sqrt(MIN_ALPHA): below it the lobe is the same
DEGREE = 8


def charlie_lambda(x, alpha):
    t = (1.0 - alpha) ** 2
    a = 21.5473 + (25.3245 - 21.5473) * t
    b = 3.82987 + (3.32435 - 3.82987) * t
    c = 0.19823 + (0.16801 - 0.19823) * t
    d = -1.97760 + (-1.27393 + 1.97760) * t
    e = -4.32054 + (-4.85967 + 4.32054) * t

    def l(y):
        return a / (1.0 + b * y ** c) + d * y + e

    return math.exp(l(x)) if x < 0.5 else math.exp(2.0 * l(0.5) - l(1.0 - x))


def albedo(nov, r, n=192):
    alpha = max(r * r, MIN_ALPHA)
    inv = 1.0 / alpha
    sv = math.sqrt(max(0.0, 1.0 - nov * nov))
    lv = charlie_lambda(nov, alpha)
    total = 0.0
    for i in range(n):
        mu = (i + 0.5) / n
        s = math.sqrt(1.0 - mu * mu)
        vis = 1.0 / ((1.0 + lv + charlie_lambda(mu, alpha)) * 4.0 * mu * nov)
        for j in range(n):
            phi = (j + 0.5) / n * math.pi
            hx, hy, hz = sv + s * math.cos(phi), s * math.sin(phi), nov + mu
            sin2 = max(0.0, 1.0 - hz * hz / (hx * hx + hy * hy + hz * hz))
            total += (2.0 + inv) * sin2 ** (0.5 * inv) / (2.0 * math.pi) * vis * mu
    return total * (1.0 / n) * (math.pi / n) * 2.0


def solve(a, b):
    """Gauss-Jordan with partial pivoting (no numpy here)."""
    m = len(b)
    rows = [row[:] + [b[k]] for k, row in enumerate(a)]
    for c in range(m):
        p = max(range(c, m), key=lambda k: abs(rows[k][c]))
        rows[c], rows[p] = rows[p], rows[c]
        for k in range(m):
            if k != c and rows[k][c] != 0.0:
                f = rows[k][c] / rows[c][c]
                for j in range(c, m + 1):
                    rows[k][j] -= f * rows[c][j]
    return [rows[k][m] / rows[k][k] for k in range(m)]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "shaders/common/sheen_albedo.h"
    samples = []  # (x, y, E): x = 2 sqrt(NoV) - 1, y = 2 max(r, 0.1) - 1
    for i in range(SIZE):
        u = i / (SIZE - 1)
        nov = max(u * u, MIN_NOV)
        for j in range(SIZE):
            r = j / (SIZE - 1)
            samples.append((2.0 * u - 1.0, 2.0 * max(r, MIN_R) - 1.0, albedo(nov, r)))
        print("row", i, file=sys.stderr)
    # log E = sum c_ab x^a y^b over a + b <= DEGREE, least squares weighted by E (so about the absolute error).
    terms = [(a, b) for a in range(DEGREE + 1) for b in range(DEGREE + 1 - a)]
    m = len(terms)
    lhs = [[0.0] * m for _ in range(m)]
    rhs = [0.0] * m
    for x, y, e in samples:
        e = max(e, 1e-4)
        f = [x ** a * y ** b for a, b in terms]
        for p in range(m):
            rhs[p] += e * f[p] * math.log(e)
            for q in range(m):
                lhs[p][q] += e * f[p] * f[q]
    c = dict(zip(terms, solve(lhs, rhs)))

    def fitted(x, y):
        return math.exp(sum(c[a, b] * x ** a * y ** b for a, b in terms))
    worst = max(abs(fitted(x, y) - e) for x, y, e in samples)
    away = max(abs(fitted(x, y) - e) for x, y, e in samples if x >= -0.6)
    print("fit: worst |E_fit - E| %.4f; %.4f where NoV >= 0.04" % (worst, away), file=sys.stderr)
    expr = horner_macro(c, DEGREE)
    with open(out, "w") as f:
        f.write("// Made by tools/make_sheen_albedo.py (read it for what this is); do not edit.\n")
        f.write("// KHR_materials_sheen's directional albedo E(NoV, r) = exp(VITRINE_SHEEN_ALBEDO_LOG(x, y)),\n"
                "// x = 2 sqrt(NoV) - 1, "
                "y = 2 max(r, %.1f) - 1: a degree-%d polynomial fitted to a %d x %d table of quadratures\n"
                "// (worst %.4f, %.4f where NoV >= 0.04). One expression for common/brdf.glsl and\n"
                "// core/shading/brdf.cpp.\n"
                % (MIN_R, DEGREE, SIZE, SIZE, worst, away))
        f.write("#ifndef VITRINE_SHEEN_ALBEDO_H\n#define VITRINE_SHEEN_ALBEDO_H\n")
        f.write("#define VITRINE_SHEEN_ALBEDO_LOG(x, y) \\\n    %s\n#endif\n" % expr)


if __name__ == "__main__":
    main()
