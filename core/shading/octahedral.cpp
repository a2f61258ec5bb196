#include "core/shading/octahedral.hpp"

#include <cmath>

namespace vitrine::shading {

namespace {

float signNotZero(float v) {
    return v >= 0.0f ? 1.0f : -1.0f;
}

// Folds the lower hemisphere's triangles onto the corners of the square.
glm::vec2 octWrap(glm::vec2 v) {
    return {(1.0f - std::fabs(v.y)) * signNotZero(v.x), (1.0f - std::fabs(v.x)) * signNotZero(v.y)};
}

} // namespace

glm::vec2 octEncode(glm::vec3 n) {
    n /= std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z);
    glm::vec2 p(n.x, n.y);
    return n.z >= 0.0f ? p : octWrap(p);
}

glm::vec3 octDecode(glm::vec2 e) {
    glm::vec3 n(e.x, e.y, 1.0f - std::fabs(e.x) - std::fabs(e.y));
    if (n.z < 0.0f) {
        glm::vec2 w = octWrap({n.x, n.y});
        n.x = w.x;
        n.y = w.y;
    }
    return glm::normalize(n);
}

} // namespace vitrine::shading
