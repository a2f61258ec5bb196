"""A fitted polynomial as one C/GLSL expression, for the headers tools/make_sheen_albedo.py and tools/make_ggx_albedo.py
write (a macro of x and y that common/brdf.glsl and core/shading/brdf.cpp both expand)."""
import textwrap


def horner_macro(c, degree):
    """sum c[a, b] x^a y^b over a + b <= degree, as Horner in x of Horner in y, wrapped for a multi-line #define."""
    def poly_y(a):
        s = "%.9ef" % c[a, degree - a]
        for b in range(degree - a - 1, -1, -1):
            s = "(%s) * (y) + %.9ef" % (s, c[a, b])
        return s
    expr = poly_y(degree)
    for a in range(degree - 1, -1, -1):
        expr = "(%s) * (x) + %s" % (expr, poly_y(a))
    return " \\\n    ".join(textwrap.wrap("(%s)" % expr, 112, break_long_words=False))
