// Made by tools/make_sheen_albedo.py (read it for what this is); do not edit.
// KHR_materials_sheen's directional albedo E(NoV, r) = exp(VITRINE_SHEEN_ALBEDO_LOG(x, y)),
// x = 2 sqrt(NoV) - 1, y = 2 max(r, 0.1) - 1: a degree-8 polynomial fitted to a 32 x 32 table of quadratures
// (worst 0.0246, 0.0072 where NoV >= 0.04). One expression for common/brdf.glsl and
// core/shading/brdf.cpp.
#ifndef VITRINE_SHEEN_ALBEDO_H
#define VITRINE_SHEEN_ALBEDO_H
#define VITRINE_SHEEN_ALBEDO_LOG(x, y) \
    (((((((((4.229068489e-01f) * (x) + (3.016983426e-02f) * (y) + -6.134816580e-02f) * (x) + ((3.620398820e-02f) * \
    (y) + 2.234318159e-01f) * (y) + -1.392678317e+00f) * (x) + (((-1.607146826e+00f) * (y) + 1.511076141e+00f) * (y) \
    + 3.597234177e-01f) * (y) + -3.861122038e-02f) * (x) + ((((2.538676276e+00f) * (y) + -3.794500086e+00f) * (y) + \
    5.145877067e-01f) * (y) + 8.789140324e-01f) * (y) + 5.332579840e-01f) * (x) + (((((-1.980602566e+00f) * (y) + \
    3.931888637e+00f) * (y) + 2.054644370e-01f) * (y) + -2.891962816e+00f) * (y) + 7.933619166e-01f) * (y) + \
    -1.881672805e-01f) * (x) + ((((((-8.262430980e-01f) * (y) + 6.060637056e-01f) * (y) + -1.390198949e+00f) * (y) + \
    3.367194617e+00f) * (y) + -2.019654146e+00f) * (y) + 4.785156535e-01f) * (y) + -5.536389600e-01f) * (x) + \
    (((((((2.690650500e+00f) * (y) + -5.250237655e+00f) * (y) + 3.112938594e+00f) * (y) + -1.421152753e+00f) * (y) + \
    1.434241836e+00f) * (y) + -1.136796214e+00f) * (y) + 1.041721425e+00f) * (y) + -1.353454619e+00f) * (x) + \
    ((((((((-6.524908106e-01f) * (y) + 2.401820419e+00f) * (y) + -2.362105366e+00f) * (y) + 2.880571640e-01f) * (y) \
    + 3.572493620e-01f) * (y) + -1.660767623e-01f) * (y) + -1.279352222e-01f) * (y) + 6.474163379e-01f) * (y) + \
    -1.004853624e+00f)
#endif
