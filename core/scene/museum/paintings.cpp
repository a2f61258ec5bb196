// The four procedural paintings of the museum, in one atlas (each material picks a quadrant with its
// texture's UV transform).

#include "core/scene/museum/texture_util.hpp"

#include <cmath>

#include <glm/gtc/constants.hpp>

namespace vitrine::scene::museum {

namespace {

constexpr float kTau = 6.28318530718f;

struct Circle {
    glm::vec2 center;
    float radius;
    glm::vec3 color;
};

struct Composition {
    std::vector<float> xs, ys;    // Mondrian grid lines
    std::vector<glm::vec3> cells; // (xs.size() - 1) × (ys.size() - 1)
    std::vector<Circle> circles;
    float hillPhase = 0.0f;
    glm::vec2 sun{0.65f, 0.42f};
};

Composition compose(Rng& rng) {
    Composition c;
    c.xs = {0.0f, rng.uniform(0.15f, 0.3f), rng.uniform(0.45f, 0.6f), rng.uniform(0.75f, 0.9f), 1.0f};
    c.ys = {0.0f, rng.uniform(0.1f, 0.3f), rng.uniform(0.45f, 0.65f), rng.uniform(0.78f, 0.9f), 1.0f};
    const glm::vec3 palette[4] = {
        {0.80f, 0.78f, 0.72f}, {0.62f, 0.04f, 0.03f}, {0.03f, 0.07f, 0.38f}, {0.82f, 0.62f, 0.04f}};
    for (size_t i = 0; i < (c.xs.size() - 1) * (c.ys.size() - 1); ++i) {
        float r = rng.uniform();
        c.cells.push_back(palette[r < 0.6f ? 0 : r < 0.75f ? 1 : r < 0.88f ? 2 : 3]);
    }
    for (int i = 0; i < 9; ++i) {
        glm::vec3 color(rng.uniform(0.05f, 0.8f), rng.uniform(0.05f, 0.6f), rng.uniform(0.05f, 0.7f));
        c.circles.push_back({{rng.uniform(0.15f, 0.85f), rng.uniform(0.15f, 0.85f)}, rng.uniform(0.04f, 0.22f), color});
    }
    c.hillPhase = rng.uniform(0.0f, kTau);
    c.sun = glm::vec2(rng.uniform(0.3f, 0.75f), rng.uniform(0.36f, 0.45f));
    return c;
}

glm::vec3 landscape(float s, float t, const Composition& c, const Fbm& fbm) {
    glm::vec3 color =
        glm::mix(glm::vec3(0.85f, 0.62f, 0.38f), glm::vec3(0.16f, 0.30f, 0.60f), smoothstep(0.5f, 0.0f, t));
    float cloud = fbm.sample(s, 2.0f * t);
    color =
        glm::mix(color, glm::vec3(0.93f, 0.88f, 0.82f), smoothstep(0.55f, 0.75f, cloud) * (t < 0.35f ? 0.9f : 0.2f));
    float ridge = 0.36f + 0.28f * (fbm.sample(s, 0.13f) - 0.5f);
    if (t > ridge) {
        color = glm::mix(glm::vec3(0.30f, 0.33f, 0.42f), glm::vec3(0.18f, 0.20f, 0.28f),
                         glm::min(1.0f, (t - ridge) * 3.0f));
        if (t - ridge < 0.025f && ridge < 0.33f) color = glm::vec3(0.88f, 0.88f, 0.9f); // snow on the peaks
    }
    float hills = 0.6f + 0.05f * std::sin(kTau * 1.5f * s + c.hillPhase) + 0.08f * (fbm.sample(s + 0.5f, 0.77f) - 0.5f);
    if (t > hills) color = glm::vec3(0.10f, 0.20f, 0.05f) * (0.6f + 0.8f * fbm.sample(4 * s, 4 * t));
    if (t > 0.82f) color = glm::vec3(0.33f, 0.30f, 0.09f) * (0.7f + 0.6f * fbm.sample(8 * s, 2 * t));
    return color;
}

glm::vec3 seascape(float s, float t, const Composition& c, const Fbm& fbm) {
    const float horizon = 0.55f;
    float toSun = glm::length(glm::vec2(s, t) - c.sun);
    if (t < horizon) {
        glm::vec3 color =
            glm::mix(glm::vec3(0.95f, 0.50f, 0.22f), glm::vec3(0.22f, 0.18f, 0.42f), smoothstep(horizon, 0.0f, t));
        color += glm::vec3(1.0f, 0.7f, 0.35f) * std::exp(-toSun * 12.0f) * 0.6f;
        if (toSun < 0.055f) color = glm::vec3(1.0f, 0.9f, 0.6f);
        float cloud = fbm.sample(2.0f * s, 6.0f * t);
        return glm::mix(color, glm::vec3(0.45f, 0.25f, 0.3f), smoothstep(0.6f, 0.8f, cloud) * 0.7f);
    }
    float wave = fbm.sample(3.0f * s, 40.0f * t);
    glm::vec3 color = glm::vec3(0.03f, 0.08f, 0.14f) * (0.6f + 0.8f * wave);
    float glitter = std::exp(-std::pow((s - c.sun.x) / 0.06f, 2.0f)) * smoothstep(0.55f, 0.7f, wave);
    return color + glm::vec3(1.0f, 0.75f, 0.4f) * glitter;
}

glm::vec3 mondrian(float s, float t, const Composition& c) {
    const float line = 0.012f;
    for (float x : c.xs) {
        if (std::abs(s - x) < line) return glm::vec3(0.02f);
    }
    for (float y : c.ys) {
        if (std::abs(t - y) < line) return glm::vec3(0.02f);
    }
    size_t i = 0, j = 0;
    while (i + 2 < c.xs.size() && s > c.xs[i + 1])
        ++i;
    while (j + 2 < c.ys.size() && t > c.ys[j + 1])
        ++j;
    return c.cells[j * (c.xs.size() - 1) + i];
}

glm::vec3 circles(float s, float t, const Composition& c, const Fbm& fbm) {
    glm::vec3 color = glm::vec3(0.70f, 0.64f, 0.50f) * (0.85f + 0.3f * fbm.sample(3 * s, 3 * t));
    for (const Circle& k : c.circles) {
        float d = glm::length(glm::vec2(s, t) - k.center);
        if (d < k.radius) color = glm::mix(k.color, color, 0.25f * d / k.radius);
        if (std::abs(d - k.radius) < 0.006f) color = glm::vec3(0.03f);
    }
    if (std::abs((s - t) * 0.7071f) < 0.004f || std::abs((s + 0.6f * t - 0.9f) * 0.857f) < 0.003f)
        color = glm::vec3(0.03f);
    return color;
}

} // namespace

TextureImage paintingAtlas(uint32_t size, Rng rng) {
    TextureImage out = blankImage("paintings", size);
    Composition c = compose(rng);
    Fbm fbm(4, 5, 0.5f, rng), brush(32, 3, 0.5f, rng);
    uint32_t half = size / 2;
    float inv = 1.0f / half;
    for (uint32_t y = 0; y < size; ++y) {
        for (uint32_t x = 0; x < size; ++x) {
            int quadrant = (y >= half ? 2 : 0) + (x >= half ? 1 : 0);
            float s = ((x % half) + 0.5f) * inv, t = ((y % half) + 0.5f) * inv;
            glm::vec3 color = quadrant == 0   ? landscape(s, t, c, fbm)
                              : quadrant == 1 ? seascape(s, t, c, fbm)
                              : quadrant == 2 ? mondrian(s, t, c)
                                              : circles(s, t, c, fbm);
            // Brush strokes: a little variation in every painting; aged varnish warms them.
            color *= glm::vec3(1.0f, 0.97f, 0.9f) * (0.9f + 0.2f * brush.sample(float(x) / size, float(y) / size));
            putColor(out, size_t(y) * size + x, color);
        }
    }
    return out;
}

} // namespace vitrine::scene::museum
