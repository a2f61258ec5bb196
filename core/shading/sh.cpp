#include "core/shading/sh.hpp"

#include <numbers>

namespace vitrine::shading {

std::array<double, 9> shBasis9(glm::dvec3 d) {
    // sqrt(1/4pi), sqrt(3/4pi), sqrt(15/4pi), sqrt(5/16pi), sqrt(15/16pi)
    const double k0 = 0.28209479177387814, k1 = 0.4886025119029199, k2 = 1.0925484305920792, k3 = 0.31539156525252005,
                 k4 = 0.5462742152960396;
    return {k0,
            k1 * d.y,
            k1 * d.z,
            k1 * d.x,
            k2 * d.x * d.y,
            k2 * d.y * d.z,
            k3 * (3.0 * d.z * d.z - 1.0),
            k2 * d.x * d.z,
            k4 * (d.x * d.x - d.y * d.y)};
}

void shAccumulate(Sh9& sh, glm::dvec3 dir, glm::dvec3 radiance, double weight) {
    auto b = shBasis9(dir);
    for (int i = 0; i < 9; ++i)
        sh.c[i] += radiance * (b[i] * weight);
}

glm::dvec3 shRadiance(const Sh9& sh, glm::dvec3 dir) {
    auto b = shBasis9(dir);
    glm::dvec3 r(0.0);
    for (int i = 0; i < 9; ++i)
        r += sh.c[i] * b[i];
    return r;
}

glm::dvec3 shIrradiance(const Sh9& sh, glm::dvec3 n) {
    auto b = shBasis9(n);
    const double pi = std::numbers::pi;
    const double band[9] = {pi, 2 * pi / 3, 2 * pi / 3, 2 * pi / 3, pi / 4, pi / 4, pi / 4, pi / 4, pi / 4};
    glm::dvec3 e(0.0);
    for (int i = 0; i < 9; ++i)
        e += sh.c[i] * (band[i] * b[i]);
    return e;
}

} // namespace vitrine::shading
