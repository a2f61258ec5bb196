// Paintings in gilded frames, benches and brass stanchions.

#include "core/scene/museum/context.hpp"
#include "core/scene/museum/shapes.hpp"

#include <glm/gtc/matrix_transform.hpp>

namespace vitrine::scene::museum {

namespace {

using namespace plan;

struct Hanging {
    glm::vec3 center; // on the wall surface
    glm::vec3 inward; // wall normal, into the room
    glm::vec2 size;   // canvas width, height
    int painting;     // quadrant of the atlas
};

// A canvas 4 cm off the wall inside a moulded gilded frame.
void painting(MeshBuilder& b, const Museum& m, const Hanging& h) {
    glm::vec3 n = h.inward, v(0, 1, 0), u = glm::cross(v, n); // u × v = n: the canvas faces the room
    glm::vec3 corner = h.center - u * (0.5f * h.size.x) - v * (0.5f * h.size.y);
    Frame canvas{corner + n * 0.04f, u, v, {0.0f, h.size.y}};
    b.material(m.mat.paintings[h.painting]);
    rect(b, canvas, h.size.x, h.size.y, glm::vec2(1.0f / h.size.x, 1.0f / h.size.y), 4, 4);
    // The frame: a profile swept counter-clockwise around the canvas; x points away from the picture.
    b.material(m.mat.gilded);
    const glm::vec2 profile[] = {{0.13f, 0.0f},  {0.12f, 0.04f}, {0.105f, 0.055f}, {0.09f, 0.06f}, {0.06f, 0.075f},
                                 {0.03f, 0.07f}, {0.0f, 0.05f},  {-0.02f, 0.05f},  {-0.02f, 0.04f}};
    Frame f{corner + n * 0.01f, u, v};
    const glm::vec3 path[] = {f.at(0, 0), f.at(h.size.x, 0), f.at(h.size.x, h.size.y), f.at(0, h.size.y)};
    sweep(b, path, true, n, profile, false, false, 2.0f);
}

void bench(MeshBuilder& b, const Museum& m, glm::vec3 at, bool alongX) {
    glm::vec3 half = alongX ? glm::vec3(0.9f, 0.0f, 0.22f) : glm::vec3(0.22f, 0.0f, 0.9f);
    b.material(m.mat.walnut);
    box(b, at + glm::vec3(-half.x, 0.42f, -half.z), at + glm::vec3(half.x, 0.48f, half.z), 1.0f);
    b.material(m.mat.bronze);
    for (float s : {-0.75f, 0.75f}) {
        glm::vec3 c = at + (alongX ? glm::vec3(s, 0, 0) : glm::vec3(0, 0, s));
        glm::vec3 leg = alongX ? glm::vec3(0.03f, 0.0f, half.z - 0.03f) : glm::vec3(half.x - 0.03f, 0.0f, 0.03f);
        box(b, c - leg, c + leg + glm::vec3(0, 0.42f, 0), 1.0f);
    }
}

// Brass posts with a thin bar between them: keeps visitors off the big painting (and aliases).
void stanchions(MeshBuilder& b, const Museum& m, float z, std::initializer_list<float> xs) {
    b.material(m.mat.brass);
    std::vector<glm::vec3> bar;
    for (float x : xs) {
        b.transform(glm::translate(glm::mat4(1.0f), {x, 0.0f, z}));
        const glm::vec2 post[] = {{0.0f, 0.0f},   {0.12f, 0.0f},   {0.12f, 0.025f}, {0.03f, 0.05f},
                                  {0.018f, 0.1f}, {0.018f, 0.88f}, {0.035f, 0.92f}, {0.0f, 0.95f}};
        lathe(b, post, 16, glm::vec2(1.0f));
        bar.push_back({x, 0.9f, z});
    }
    b.transform(glm::mat4(1.0f));
    std::vector<glm::vec2> tube = circleProfile(0.008f, 8);
    sweep(b, bar, false, {0, 0, 1}, tube, true, true, 1.0f);
}

} // namespace

void buildDecor(Museum& m) {
    MeshBuilder b("paintings_and_benches");
    const glm::vec3 north(0, 0, -1), west(1, 0, 0), east(-1, 0, 0), hallNorth(0, 0, -1);
    const Hanging hangings[] = {
        {{0.0f, 2.3f, kNorthZ1}, north, {2.4f, 1.6f}, 0},   {{-kNorthX, 2.1f, 10.5f}, west, {1.6f, 1.2f}, 1},
        {{-kNorthX, 2.1f, 14.5f}, west, {1.3f, 1.6f}, 2},   {{kNorthX, 2.1f, 10.5f}, east, {1.3f, 1.6f}, 3},
        {{kNorthX, 2.1f, 14.5f}, east, {1.6f, 1.2f}, 1},    {{-5.0f, 2.6f, kHallZ}, hallNorth, {1.5f, 1.9f}, 2},
        {{5.0f, 2.6f, kHallZ}, hallNorth, {1.5f, 1.9f}, 3},
    };
    for (const Hanging& h : hangings)
        painting(b, m, h);
    bench(b, m, {0.0f, 0.0f, 12.4f}, true);
    bench(b, m, {-8.0f, 0.0f, -5.7f}, true);
    bench(b, m, {8.0f, 0.0f, -5.7f}, true);
    bench(b, m, {-22.4f, 0.0f, 4.2f}, true);
    bench(b, m, {26.6f, 0.0f, 0.0f}, false);
    stanchions(b, m, kNorthZ1 - 1.1f, {-1.8f, -0.6f, 0.6f, 1.8f});
    m.place(b, "paintings_and_benches");
}

} // namespace vitrine::scene::museum
