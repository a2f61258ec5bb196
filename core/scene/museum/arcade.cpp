// The hall's two arcades: fluted marble columns with moulded bases and capitals, semicircular arches with
// spandrels and archivolts, and the entablature beams above them.

#include "core/scene/museum/context.hpp"
#include "core/scene/museum/shapes.hpp"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

namespace vitrine::scene::museum {

namespace {

using namespace plan;

constexpr float kAbacusHalf = 0.49f;
constexpr float kArchDepth = 0.7f;
constexpr float kBeamBottom = 8.2f;

// A fluted shaft from y0 to y1, radius r0 → r1 (entasis), with concave flutes; analytic normals.
void flutedShaft(MeshBuilder& b, float y0, float y1, float r0, float r1, int flutes, int perFlute, int rings) {
    int segments = flutes * perFlute;
    auto surface = [&](float theta, float y) {
        float t = (y - y0) / (y1 - y0);
        float radius = glm::mix(r0, r1, t * t); // taper mostly near the top
        float phase = theta * flutes / glm::two_pi<float>();
        float flute = std::sin(glm::pi<float>() * (phase - std::floor(phase)));
        float r = radius * (1.0f - 0.05f * flute);
        return glm::vec3(r * std::cos(theta), y, -r * std::sin(theta));
    };
    b.chart();
    std::vector<uint32_t> ids;
    for (int j = 0; j <= rings; ++j) {
        float y = y0 + (y1 - y0) * j / rings;
        for (int k = 0; k <= segments; ++k) {
            float theta = glm::two_pi<float>() * k / segments;
            const float e = 1e-3f;
            glm::vec3 p = surface(theta, y);
            glm::vec3 dTheta = surface(theta + e, y) - surface(theta - e, y);
            glm::vec3 dY = surface(theta, y + e) - surface(theta, y - e);
            glm::vec3 n = glm::normalize(glm::cross(dTheta, dY));
            glm::vec2 chart(theta * r0, y - y0);
            ids.push_back(b.vertex(p, n, glm::vec2(chart.x, -chart.y), chart));
        }
    }
    for (int j = 0; j < rings; ++j) {
        for (int k = 0; k < segments; ++k) {
            uint32_t a = ids[j * (segments + 1) + k];
            b.quad(a, a + 1, a + segments + 2, a + segments + 1);
        }
    }
}

void column(MeshBuilder& b, const Museum& m, const glm::vec3& at) {
    b.transform(glm::translate(glm::mat4(1.0f), at));
    b.material(m.mat.darkMarble);
    box(b, {-0.45f, 0.0f, -0.45f}, {0.45f, 0.25f, 0.45f}, 1.0f);
    b.material(m.mat.columnMarble);
    const glm::vec2 base[] = {{0.42f, 0.25f}, {0.44f, 0.29f}, {0.43f, 0.33f}, {0.39f, 0.36f},
                              {0.36f, 0.38f}, {0.37f, 0.41f}, {0.33f, 0.45f}, {0.32f, 0.46f}};
    lathe(b, base, 48, glm::vec2(1.0f));
    flutedShaft(b, 0.46f, 5.5f, 0.32f, 0.285f, 20, 5, 16);
    const glm::vec2 capital[] = {{0.285f, 5.5f}, {0.30f, 5.52f}, {0.31f, 5.56f}, {0.33f, 5.6f},
                                 {0.38f, 5.66f}, {0.43f, 5.72f}, {0.45f, 5.76f}, {0.45f, 5.8f}};
    lathe(b, capital, 48, glm::vec2(1.0f));
    box(b, {-kAbacusHalf, 5.8f, -kAbacusHalf}, {kAbacusHalf, kSpring, kAbacusHalf}, 1.0f);
    b.transform(glm::mat4(1.0f));
}

// Where the ray from c at angle theta leaves the rectangle [x0, x1] × [c.y, top].
glm::vec2 rayToRect(glm::vec2 c, float theta, float x0, float x1, float top) {
    glm::vec2 d(std::cos(theta), std::sin(theta));
    float t = 1e30f;
    if (d.x > 1e-6f) t = std::min(t, (x1 - c.x) / d.x);
    if (d.x < -1e-6f) t = std::min(t, (x0 - c.x) / d.x);
    if (d.y > 1e-6f) t = std::min(t, (top - c.y) / d.y);
    return c + d * t;
}

// One bay of an arcade: the spandrel wall with a semicircular opening between x0 and x1 on row z, its
// soffit, and an archivolt moulding on each face.
void bay(MeshBuilder& b, const Museum& m, float x0, float x1, float z) {
    glm::vec2 c(0.5f * (x0 + x1), kSpring);
    float r = 0.5f * (x1 - x0) - kAbacusHalf;
    // Angles: uniform, plus the rectangle's corners so that the outer edge follows them exactly.
    std::vector<float> angles;
    const int steps = 24;
    for (int i = 0; i <= steps; ++i)
        angles.push_back(glm::pi<float>() * i / steps);
    float corner = std::atan2(kBeamBottom - kSpring, x1 - c.x);
    angles.insert(angles.end(), {corner, glm::pi<float>() - corner});
    std::sort(angles.begin(), angles.end());

    b.material(m.mat.hallStone);
    for (float side : {1.0f, -1.0f}) {
        float zf = z + side * 0.5f * kArchDepth;
        glm::vec3 n(0, 0, side);
        b.chart();
        std::vector<uint32_t> inner, outer;
        for (float a : angles) {
            glm::vec2 pi = c + r * glm::vec2(std::cos(a), std::sin(a));
            glm::vec2 po = rayToRect(c, a, x0, x1, kBeamBottom);
            inner.push_back(b.vertex({pi.x, pi.y, zf}, n, glm::vec2(pi.x, -pi.y), pi));
            outer.push_back(b.vertex({po.x, po.y, zf}, n, glm::vec2(po.x, -po.y), po));
        }
        for (size_t i = 0; i + 1 < angles.size(); ++i) {
            if (side > 0)
                b.quad(inner[i], outer[i], outer[i + 1], inner[i + 1]);
            else
                b.quad(inner[i], inner[i + 1], outer[i + 1], outer[i]);
        }
    }
    // The soffit: the underside of the arch, facing its centre.
    b.chart();
    std::vector<uint32_t> front, back;
    for (float a : angles) {
        glm::vec2 p = c + r * glm::vec2(std::cos(a), std::sin(a));
        glm::vec3 n(-std::cos(a), -std::sin(a), 0.0f);
        float s = a * r;
        front.push_back(b.vertex({p.x, p.y, z + 0.5f * kArchDepth}, n, glm::vec2(s, 0.0f), glm::vec2(s, 0.0f)));
        back.push_back(
            b.vertex({p.x, p.y, z - 0.5f * kArchDepth}, n, glm::vec2(s, kArchDepth), glm::vec2(s, kArchDepth)));
    }
    for (size_t i = 0; i + 1 < angles.size(); ++i)
        b.quad(front[i], front[i + 1], back[i + 1], back[i]);

    b.material(m.mat.columnMarble);
    const glm::vec2 band[] = {{-0.11f, 0.0f}, {0.11f, 0.0f}, {0.11f, 0.03f}, {0.06f, 0.055f}, {-0.11f, 0.055f}};
    for (float side : {1.0f, -1.0f}) {
        float zf = z + side * 0.5f * kArchDepth;
        std::vector<glm::vec3> path = arc({c.x, c.y, zf}, {1, 0, 0}, {0, 1, 0}, r + 0.11f, 0.0f, glm::pi<float>(), 32);
        sweep(b, path, false, {0, 0, side}, band, true, true, 1.0f);
        // Keystone.
        box(b, {c.x - 0.16f, c.y + r - 0.06f, zf - (side > 0 ? 0.0f : 0.08f)},
            {c.x + 0.16f, c.y + r + 0.42f, zf + (side > 0 ? 0.08f : 0.0f)}, 1.0f);
    }
}

void beam(MeshBuilder& b, const Museum& m, float z) {
    b.material(m.mat.hallStone);
    box(b, {-kHallX, kBeamBottom, z - 0.45f}, {kHallX, kHallH, z + 0.45f}, 1.0f);
    b.material(m.mat.columnMarble);
    box(b, {-kHallX, kBeamBottom - 0.06f, z - 0.48f}, {kHallX, kBeamBottom + 0.04f, z + 0.48f}, 1.0f);
    box(b, {-kHallX, kBeamBottom + 0.55f, z - 0.52f}, {kHallX, kBeamBottom + 0.65f, z + 0.52f}, 1.0f);
}

} // namespace

void buildArcades(Museum& m) {
    MeshBuilder columns("hall_columns"), arches("hall_arcades");
    for (float z : {-kColumnZ, kColumnZ}) {
        for (int i = 0; i < kColumns; ++i)
            column(columns, m, {kColumnX0 + i * kColumnStep, 0.0f, z});
        for (int i = 0; i + 1 < kColumns; ++i) {
            float xa = kColumnX0 + i * kColumnStep;
            bay(arches, m, xa, xa + kColumnStep, z);
        }
        // Between the last columns and the end walls: a flat lintel on the capitals.
        arches.material(m.mat.hallStone);
        float xEnd = kColumnX0 + (kColumns - 1) * kColumnStep;
        box(arches, {-kHallX, kSpring, z - 0.35f}, {kColumnX0 + kAbacusHalf, kBeamBottom, z + 0.35f}, 1.0f);
        box(arches, {xEnd - kAbacusHalf, kSpring, z - 0.35f}, {kHallX, kBeamBottom, z + 0.35f}, 1.0f);
        beam(arches, m, z);
    }
    m.place(columns, "hall_columns");
    m.place(arches, "hall_arcades");
}

} // namespace vitrine::scene::museum
