// The exhibits, chosen to span the material space: a mirror sphere behind a thin railing, a gold amphora
// under a layer of dirt, a brushed-steel ring, a rough stone bust, velvet draped over a table, a lacquered
// walnut chest, and an engraved silver medallion whose fine normal map aliases. The amphora, the ring and the
// medallion stand in glass cases.

#include "core/scene/museum/context.hpp"
#include "core/scene/museum/shapes.hpp"

#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

namespace vitrine::scene::museum {

namespace {

const glm::vec3 kY(0, 1, 0);

void pedestal(MeshBuilder& b, const Museum& m, float height, float half = 0.3f) {
    b.material(m.mat.darkMarble);
    box(b, {-half - 0.05f, 0.0f, -half - 0.05f}, {half + 0.05f, 0.08f, half + 0.05f}, 1.0f);
    box(b, {-half - 0.05f, height - 0.06f, -half - 0.05f}, {half + 0.05f, height, half + 0.05f}, 1.0f);
    b.material(m.mat.plasterWhite);
    box(b, {-half, 0.08f, -half}, {half, height - 0.06f, half}, 1.0f);
}

// A glass case over an exhibit, standing on its pedestal's top (y = base) with a half width `half` and height
// `height`: a closed box 2 mm above the slab (so its floor never fights the slab's depth), a child of the exhibit's
// node. No lightmap UVs: glass is transparent.
void glassCase(Museum& m, uint32_t exhibit, float base, float half, float height) {
    MeshBuilder b("vitrine");
    b.material(m.mat.glass);
    box(b, {-half, base + 0.002f, -half}, {half, base + height, half}, 1.0f);
    m.place(b, m.scene.nodes[exhibit].name + "_vitrine", Transform{}, false, static_cast<int32_t>(exhibit));
}

Transform placement(Museum& m, glm::vec3 at, float yaw) {
    Transform t;
    t.translation = at;
    // A little seed-dependent turn: exhibits are never placed quite the same way twice.
    t.rotation = glm::angleAxis(yaw + m.rng.uniform(-0.12f, 0.12f), kY);
    return t;
}

void mirrorSphere(Museum& m, glm::vec3 at) {
    MeshBuilder b("exhibit_mirror_sphere");
    pedestal(b, m, 1.0f);
    b.material(m.mat.brass);
    const glm::vec2 cup[] = {{0.0f, 1.0f},   {0.12f, 1.0f}, {0.13f, 1.02f},
                             {0.09f, 1.06f}, {0.1f, 1.12f}, {0.14f, 1.16f}};
    lathe(b, cup, 32, glm::vec2(1.0f));
    b.material(m.mat.chrome);
    b.transform(glm::translate(glm::mat4(1.0f), {0.0f, 1.49f, 0.0f}));
    sphere(b, 0.35f, 64, 128, 1.0f);
    b.transform(glm::mat4(1.0f));
    m.place(b, "exhibit_mirror_sphere", placement(m, at, 0.0f));

    // Brass railing: posts, two rails and a hundred 14 mm balusters — thin enough to alias.
    MeshBuilder r("sphere_railing");
    r.material(m.mat.brass);
    const float radius = 1.3f;
    for (int i = 0; i < 12; ++i) {
        float a = glm::two_pi<float>() * i / 12;
        r.transform(glm::translate(glm::mat4(1.0f), {radius * std::cos(a), 0.0f, radius * std::sin(a)}));
        const glm::vec2 post[] = {{0.0f, 0.0f},    {0.05f, 0.0f},  {0.05f, 0.02f}, {0.025f, 0.04f},
                                  {0.025f, 0.88f}, {0.035f, 0.9f}, {0.0f, 0.93f}};
        lathe(r, post, 12, glm::vec2(1.0f));
    }
    r.transform(glm::mat4(1.0f));
    const int balusters = 102;
    for (int i = 0; i < balusters; ++i) {
        float a = glm::two_pi<float>() * (i + 0.5f) / balusters;
        r.transform(glm::translate(glm::mat4(1.0f), {radius * std::cos(a), 0.0f, radius * std::sin(a)}));
        const glm::vec2 bar[] = {{0.0f, 0.02f}, {0.007f, 0.02f}, {0.007f, 0.88f}, {0.0f, 0.88f}};
        lathe(r, bar, 6, glm::vec2(1.0f));
    }
    r.transform(glm::mat4(1.0f));
    for (auto [height, thickness] : {std::pair{0.9f, 0.022f}, std::pair{0.45f, 0.012f}, std::pair{0.04f, 0.012f}}) {
        std::vector<glm::vec3> path =
            arc({0, height, 0}, {1, 0, 0}, {0, 0, -1}, radius, 0.0f, glm::two_pi<float>(), 96);
        path.pop_back();
        std::vector<glm::vec2> profile = circleProfile(thickness, 10);
        sweep(r, path, true, kY, profile, true, true, 1.0f);
    }
    Transform t;
    t.translation = at;
    m.place(r, "sphere_railing", t);
}

void goldAmphora(Museum& m, glm::vec3 at) {
    MeshBuilder b("exhibit_gold_amphora");
    pedestal(b, m, 0.9f);
    b.material(m.mat.dirtyGold);
    const glm::vec2 control[] = {{0.0f, 0.0f},    {0.09f, 0.0f},   {0.1f, 0.02f},   {0.075f, 0.06f},
                                 {0.12f, 0.14f},  {0.19f, 0.26f},  {0.21f, 0.36f},  {0.19f, 0.46f},
                                 {0.12f, 0.56f},  {0.07f, 0.63f},  {0.062f, 0.69f}, {0.085f, 0.73f},
                                 {0.09f, 0.745f}, {0.065f, 0.75f}, {0.05f, 0.7f},   {0.0f, 0.68f}};
    std::vector<glm::vec2> profile = smoothProfile(control, 48);
    for (glm::vec2& p : profile)
        p = glm::vec2(std::max(p.x, 0.0f), p.y + 0.9f);
    profile.front().x = profile.back().x = 0.0f;
    lathe(b, profile, 80, glm::vec2(2.0f));
    // Two handles: swept tubes from the shoulder to the neck.
    for (float side : {1.0f, -1.0f}) {
        std::vector<glm::vec3> path;
        for (int i = 0; i <= 16; ++i) {
            float a = glm::pi<float>() * i / 16;
            path.push_back(
                {side * (0.2f + 0.07f * std::sin(a)), 0.9f + 0.43f + 0.22f * (0.5f - 0.5f * std::cos(a)), 0.0f});
        }
        std::vector<glm::vec2> tube = circleProfile(0.014f, 10);
        sweep(b, path, false, {0, 0, side}, tube, true, true, 2.0f);
    }
    uint32_t node = m.place(b, "exhibit_gold_amphora", placement(m, at, 0.3f));
    glassCase(m, node, 0.9f, 0.34f, 0.95f);
}

void brushedRing(Museum& m, glm::vec3 at) {
    MeshBuilder b("exhibit_brushed_ring");
    pedestal(b, m, 0.9f);
    b.material(m.mat.brushedSteel);
    const glm::vec2 base[] = {{0.0f, 0.9f}, {0.16f, 0.9f}, {0.16f, 0.93f}, {0.12f, 0.96f}, {0.0f, 0.96f}};
    lathe(b, base, 48, glm::vec2(1.0f));
    std::vector<glm::vec3> path = arc({0.0f, 0.96f + 0.33f, 0.0f}, {1, 0, 0}, {0, 1, 0}, 0.33f, -glm::half_pi<float>(),
                                      1.5f * glm::pi<float>(), 96);
    path.pop_back();
    std::vector<glm::vec2> tube = circleProfile(0.06f, 32);
    sweep(b, path, true, {0, 0, 1}, tube, true, true, 1.0f);
    uint32_t node = m.place(b, "exhibit_brushed_ring", placement(m, at, -0.4f));
    glassCase(m, node, 0.9f, 0.4f, 0.95f);
}

// A head: an ellipsoid with nose, brow, eye sockets, chin and ears pushed and pulled along its normal.
glm::vec3 head(float s, float t) {
    float theta = glm::two_pi<float>() * s, phi = glm::pi<float>() * t;
    glm::vec3 d(std::sin(phi) * std::cos(theta), -std::cos(phi), -std::sin(phi) * std::sin(theta));
    float r = 1.0f / std::sqrt(glm::dot(d * d, 1.0f / glm::vec3(0.095f * 0.095f, 0.125f * 0.125f, 0.112f * 0.112f)));
    auto bump = [&](glm::vec3 f, float width) { return std::exp(-(1.0f - glm::dot(d, glm::normalize(f))) / width); };
    r += 0.026f * bump({0, -0.12f, 1}, 0.006f) + 0.016f * bump({0, -0.32f, 1}, 0.008f);
    r += 0.008f * bump({0, 0.22f, 1}, 0.03f) + 0.012f * bump({0, -0.75f, 0.66f}, 0.02f);
    r -= 0.012f * (bump({0.38f, 0.08f, 0.92f}, 0.006f) + bump({-0.38f, 0.08f, 0.92f}, 0.006f));
    r += 0.012f * (bump({1, 0, 0}, 0.008f) + bump({-1, 0, 0}, 0.008f));
    r += 0.0025f * std::sin(31.0f * d.x) * std::sin(27.0f * d.y) * std::sin(23.0f * d.z); // chisel marks
    return glm::vec3(0.0f, 1.43f, 0.01f) + d * r;
}

void stoneBust(Museum& m, glm::vec3 at) {
    MeshBuilder b("exhibit_stone_bust");
    pedestal(b, m, 1.1f, 0.22f);
    b.material(m.mat.roughStone);
    // Modelled life-size on a 1.1 m pedestal, shown a third larger, as monumental busts are.
    b.transform(glm::translate(glm::mat4(1.0f), {0.0f, 1.1f, 0.0f}) * glm::scale(glm::mat4(1.0f), glm::vec3(1.35f)) *
                glm::translate(glm::mat4(1.0f), {0.0f, -1.1f, 0.0f}));
    surface(b, head, 72, 48, glm::vec2(0.65f, 0.35f), glm::vec2(2.0f));
    auto shoulders = [](float s, float t) {
        float theta = glm::two_pi<float>() * s, phi = glm::half_pi<float>() * (1.0f + t);
        glm::vec3 d(std::sin(phi) * std::cos(theta), -std::cos(phi), -std::sin(phi) * std::sin(theta));
        return glm::vec3(0.0f, 1.1f, 0.0f) + d * glm::vec3(0.24f, 0.17f, 0.12f);
    };
    surface(b, shoulders, 64, 16, glm::vec2(1.0f, 0.3f), glm::vec2(2.0f));
    const glm::vec2 neck[] = {{0.058f, 1.22f}, {0.05f, 1.3f}, {0.052f, 1.37f}};
    lathe(b, neck, 32, glm::vec2(2.0f));
    b.transform(glm::mat4(1.0f));
    m.place(b, "exhibit_stone_bust", placement(m, at, glm::half_pi<float>()));
}

void drapedTable(Museum& m, glm::vec3 at, float phase) {
    MeshBuilder b("exhibit_velvet_table");
    b.material(m.mat.walnut);
    box(b, {-0.6f, 0.72f, -0.4f}, {0.6f, 0.76f, 0.4f}, 1.0f);
    for (float x : {-0.52f, 0.47f}) {
        for (float z : {-0.32f, 0.27f})
            box(b, {x, 0.0f, z}, {x + 0.05f, 0.72f, z + 0.05f}, 1.0f);
    }
    b.material(m.mat.velvet);
    auto cloth = [phase](float s, float t) {
        glm::vec2 q(-0.88f + 1.76f * s, 0.68f - 1.36f * t);
        glm::vec2 e = glm::clamp(q, glm::vec2(-0.6f, -0.4f), glm::vec2(0.6f, 0.4f));
        float d = glm::length(q - e);
        glm::vec2 dir = d > 0.0f ? (q - e) / d : glm::vec2(0.0f);
        const float rho = 0.03f, bend = glm::half_pi<float>() * rho;
        float out = d < bend ? rho * std::sin(d / rho) : rho;
        float drop = d < bend ? rho * (1.0f - std::cos(d / rho)) : rho + (d - bend);
        out += 0.035f * smoothstep(0.0f, 0.25f, d) * std::sin(glm::two_pi<float>() * (q.x + q.y) / 0.13f + phase);
        return glm::vec3(e.x + dir.x * out, 0.765f + 0.002f * std::sin(9.0f * q.x) - drop, e.y + dir.y * out);
    };
    surface(b, cloth, 72, 56, glm::vec2(1.76f, 1.36f), glm::vec2(1.0f));
    m.place(b, "exhibit_velvet_table", placement(m, at, 0.0f));
}

void lacqueredChest(Museum& m, glm::vec3 at) {
    MeshBuilder b("exhibit_lacquered_chest");
    b.material(m.mat.darkMarble);
    box(b, {-0.5f, 0.0f, -0.35f}, {0.5f, 0.3f, 0.35f}, 1.0f);
    b.material(m.mat.lacqueredWood);
    box(b, {-0.42f, 0.3f, -0.26f}, {0.42f, 0.74f, 0.26f}, 1.2f);
    box(b, {-0.44f, 0.74f, -0.28f}, {0.44f, 0.8f, 0.28f}, 1.2f);
    auto lid = [](float s, float t) {
        float a = glm::pi<float>() * t;
        return glm::vec3(-0.44f + 0.88f * s, 0.8f + 0.07f * std::sin(a), 0.28f * std::cos(a));
    };
    surface(b, lid, 8, 24, glm::vec2(0.88f, 0.7f), glm::vec2(1.2f));
    b.material(m.mat.brass);
    for (float x : {-0.3f, 0.3f})
        box(b, {x - 0.025f, 0.3f, -0.265f}, {x + 0.025f, 0.805f, 0.265f}, 1.0f);
    box(b, {-0.06f, 0.6f, 0.26f}, {0.06f, 0.72f, 0.27f}, 1.0f);
    m.place(b, "exhibit_lacquered_chest", placement(m, at, -0.5f));
}

void engravedMedallion(Museum& m, glm::vec3 at) {
    MeshBuilder b("exhibit_engraved_medallion");
    pedestal(b, m, 1.0f, 0.25f);
    b.material(m.mat.bronze);
    box(b, {-0.1f, 1.0f, -0.08f}, {0.1f, 1.09f, 0.08f}, 1.0f);
    b.material(m.mat.engravedSilver);
    b.transform(glm::rotate(glm::translate(glm::mat4(1.0f), {0.0f, 1.34f, 0.0f}), -0.2f, glm::vec3(1, 0, 0)));
    const float radius = 0.25f, half = 0.015f;
    const int rings = 32, segments = 96;
    // Both faces map the disc onto [0,1]² (the rosette); the rim is a band.
    for (float side : {1.0f, -1.0f}) {
        b.chart();
        std::vector<uint32_t> ids;
        for (int j = 0; j <= rings; ++j) {
            for (int k = 0; k <= segments; ++k) {
                float r = radius * j / rings, a = glm::two_pi<float>() * k / segments;
                glm::vec2 p(r * std::cos(a), r * std::sin(a));
                glm::vec2 uv(0.5f + 0.5f * side * p.x / radius, 0.5f - 0.5f * p.y / radius);
                ids.push_back(b.vertex({p.x, p.y, side * half}, {0, 0, side}, uv, p));
            }
        }
        for (int j = 0; j < rings; ++j) {
            for (int k = 0; k < segments; ++k) {
                uint32_t a = ids[j * (segments + 1) + k], c = a + segments + 1;
                if (side > 0)
                    b.quad(a, c, c + 1, a + 1);
                else
                    b.quad(a, a + 1, c + 1, c);
            }
        }
    }
    b.chart();
    std::vector<uint32_t> front, back;
    for (int k = 0; k <= segments; ++k) {
        float a = glm::two_pi<float>() * k / segments;
        glm::vec3 n(std::cos(a), std::sin(a), 0.0f);
        glm::vec2 chart(a * radius, 0.0f);
        front.push_back(b.vertex(n * radius + glm::vec3(0, 0, half), n, glm::vec2(0.5f), chart));
        back.push_back(
            b.vertex(n * radius - glm::vec3(0, 0, half), n, glm::vec2(0.5f), chart + glm::vec2(0.0f, 2 * half)));
    }
    for (int k = 0; k < segments; ++k)
        b.quad(front[k], back[k], back[k + 1], front[k + 1]);
    b.transform(glm::mat4(1.0f));
    uint32_t node = m.place(b, "exhibit_engraved_medallion", placement(m, at, -glm::half_pi<float>()));
    glassCase(m, node, 1.0f, 0.28f, 0.75f);
}

} // namespace

void buildExhibits(Museum& m) {
    mirrorSphere(m, {0.0f, 0.0f, 1.0f});
    goldAmphora(m, {-6.0f, 0.0f, 1.0f});
    brushedRing(m, {6.0f, 0.0f, 1.0f});
    stoneBust(m, {-22.4f, 0.0f, 0.0f});
    drapedTable(m, {-22.4f, 0.0f, -3.3f}, m.rng.uniform(0.0f, glm::two_pi<float>()));
    lacqueredChest(m, {22.4f, 0.0f, -2.0f});
    engravedMedallion(m, {22.4f, 0.0f, 2.0f});
}

} // namespace vitrine::scene::museum
