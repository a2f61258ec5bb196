#include "core/shading/cubemap.hpp"

#include <cmath>

namespace vitrine::shading {

glm::dvec3 cubeDirection(int face, double u, double v) {
    switch (face) {
    case 0:
        return {1.0, -v, -u};
    case 1:
        return {-1.0, -v, u};
    case 2:
        return {u, 1.0, v};
    case 3:
        return {u, -1.0, -v};
    case 4:
        return {u, -v, 1.0};
    default:
        return {-u, -v, -1.0};
    }
}

glm::dvec3 cubeTexelDirection(int face, int x, int y, int size) {
    double s = 2.0 / size;
    return glm::normalize(cubeDirection(face, (x + 0.5) * s - 1.0, (y + 0.5) * s - 1.0));
}

CubeCoord cubeCoord(glm::dvec3 d) {
    glm::dvec3 a = glm::abs(d);
    if (a.x >= a.y && a.x >= a.z)
        return d.x > 0 ? CubeCoord{0, -d.z / a.x, -d.y / a.x} : CubeCoord{1, d.z / a.x, -d.y / a.x};
    if (a.y >= a.z) return d.y > 0 ? CubeCoord{2, d.x / a.y, d.z / a.y} : CubeCoord{3, d.x / a.y, -d.z / a.y};
    return d.z > 0 ? CubeCoord{4, d.x / a.z, -d.y / a.z} : CubeCoord{5, -d.x / a.z, -d.y / a.z};
}

namespace {
double cornerArea(double x, double y) {
    return std::atan2(x * y, std::sqrt(x * x + y * y + 1.0));
}
} // namespace

double cubeTexelSolidAngle(int x, int y, int size) {
    double s = 2.0 / size;
    double x0 = x * s - 1.0, x1 = x0 + s, y0 = y * s - 1.0, y1 = y0 + s;
    return cornerArea(x0, y0) - cornerArea(x0, y1) - cornerArea(x1, y0) + cornerArea(x1, y1);
}

Sh9 projectCube(int size, const std::function<glm::dvec3(int face, int x, int y)>& radiance) {
    Sh9 sh;
    for (int face = 0; face < 6; ++face)
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x)
                shAccumulate(sh, cubeTexelDirection(face, x, y, size), radiance(face, x, y),
                             cubeTexelSolidAngle(x, y, size));
    return sh;
}

} // namespace vitrine::shading
