#!/usr/bin/env python3
"""Writes shaders/common/ggx_albedo.h: the directional albedo E(NoV, r) of vitrine's GGX specular lobe with F = 1.

E(v) = integral over the hemisphere of D(h) V(v, l) (n.l) dl, the single-scattering lobe of common/brdf.glsl
(ggxD, smithGgxVisibility: GGX of alpha = max(r^2, 0.002), height-correlated Smith) for a white Fresnel. 1 - E is
the energy that the microfacet model loses to light that would have scattered more than once between the facets;
the multiple-scattering compensation (common/brdf.glsl ggxMultiscatter, [Turquin19]) gives it back, scaled by F0.
E is integrated on a 32 x 32 grid, u = sqrt(NoV) (i / 31) by r (j / 31), each entry by the split sum's estimator
with the half vector drawn from D (NoH): E = mean of 4 V (n.l) (v.h) / (n.h) over a midpoint grid of 512 x 256
(u_h, phi_h), which ibl/brdf_lut.comp's A + B also is; then fitted by a polynomial of total degree 10 in
(2 (u - 0.1) / 0.9 - 1, 2 max(r, 0.045) - 1) over the rows u >= 0.1 (NoV >= 0.01; below it the shaders read
NoV = 0.01: within a few hundredths of a radian of grazing GGX's long tail makes E change faster than a polynomial
follows, and the compensation there is not seen). A polynomial, not the table, as common/sheen_albedo.h (constant arrays indexed at run
time make lavapipe's shader compiler slow). tests/unit/shading/brdf_test.cpp integrates again at points between
the grid's. The same expression serves GLSL and C++ (core/shading/brdf.cpp): the header is a macro. Made here, not
downloaded; rerun to regenerate (about a minute; needs numpy):

    python3 tools/make_ggx_albedo.py [OUT]
"""
import math
import sys

import numpy as np

from horner_macro import horner_macro

SIZE = 32
MIN_ALPHA = 0.002  # common/brdf.glsl kMinGgxAlpha
MIN_R = math.sqrt(MIN_ALPHA)
DEGREE = 10
MIN_U = 0.1  # sqrt of the smallest NoV fitted


def albedo(nov, r, nu=512, nphi=256):
    alpha = max(r * r, MIN_ALPHA)
    a2 = alpha * alpha
    u = (np.arange(nu) + 0.5) / nu
    phi = (np.arange(nphi) + 0.5) / nphi * 2.0 * math.pi
    u, phi = np.meshgrid(u, phi, indexing="ij")
    cos_h = np.sqrt((1.0 - u) / (1.0 + (a2 - 1.0) * u))  # GGX's inverse CDF
    sin_h = np.sqrt(1.0 - cos_h * cos_h)
    h = np.stack([sin_h * np.cos(phi), sin_h * np.sin(phi), cos_h], -1)
    v = np.array([math.sqrt(1.0 - nov * nov), 0.0, nov])
    voh = h @ v
    l = 2.0 * voh[..., None] * h - v
    nol = l[..., 2]
    ok = (nol > 0.0) & (voh > 0.0)
    nol = np.where(ok, nol, 1.0)
    lam_v = nol * np.sqrt(nov * nov * (1.0 - a2) + a2)
    lam_l = nov * np.sqrt(nol * nol * (1.0 - a2) + a2)
    vis = 0.5 / (lam_v + lam_l)
    g = np.where(ok, 4.0 * vis * nol * voh / cos_h, 0.0)
    return float(g.mean())


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "shaders/common/ggx_albedo.h"
    samples = []  # (x, y, E): x = 2 (sqrt(NoV) - MIN_U) / (1 - MIN_U) - 1, y = 2 max(r, MIN_R) - 1
    for i in range(SIZE):
        u = MIN_U + (1.0 - MIN_U) * i / (SIZE - 1)
        nov = u * u
        for j in range(SIZE):
            r = j / (SIZE - 1)
            samples.append((2.0 * i / (SIZE - 1) - 1.0, 2.0 * max(r, MIN_R) - 1.0, albedo(nov, r)))
    terms = [(a, b) for a in range(DEGREE + 1) for b in range(DEGREE + 1 - a)]
    f = np.array([[x ** a * y ** b for a, b in terms] for x, y, _ in samples])
    e = np.array([s[2] for s in samples])
    coef, *_ = np.linalg.lstsq(f, e, rcond=None)
    c = dict(zip(terms, coef))
    fit = f @ coef
    worst = float(np.max(np.abs(fit - e)))
    rel = float(np.max(np.abs(fit / e - 1.0)))
    print("E from %.4f to %.4f; fit: worst |E_fit - E| %.4f, relative %.4f" % (e.min(), e.max(), worst, rel),
          file=sys.stderr)

    expr = horner_macro(c, DEGREE)
    with open(out, "w") as fh:
        fh.write("// Made by tools/make_ggx_albedo.py (read it for what this is); do not edit.\n")
        fh.write("// The GGX specular lobe's directional albedo for F = 1, E(NoV, r) = VITRINE_GGX_ALBEDO(x, y),\n"
                 "// x = 2 (sqrt(max(NoV, %.2f)) - %.1f) / %.1f - 1, y = 2 max(r, %.4f) - 1 (r = sqrt(alpha)): a degree-%d\n"
                 "// polynomial fitted to a %d x %d table of quadratures (E %.4f..%.4f; worst %.4f, relative %.4f). One\n"
                 "// expression for common/brdf.glsl and core/shading/brdf.cpp.\n"
                 % (MIN_U * MIN_U, MIN_U, 1.0 - MIN_U, MIN_R, DEGREE, SIZE, SIZE, e.min(), e.max(), worst, rel))
        fh.write("#ifndef VITRINE_GGX_ALBEDO_H\n#define VITRINE_GGX_ALBEDO_H\n")
        fh.write("#define VITRINE_GGX_ALBEDO(x, y) \\\n    %s\n#endif\n" % expr)


if __name__ == "__main__":
    main()
