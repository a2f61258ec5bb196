// A small patrol robot: seven rigid parts in a node hierarchy, walking an ellipse along the hall's north
// aisle with swinging legs and arms and a head that looks around. Dynamic: no lightmap, probes only.

#include "core/scene/museum/context.hpp"
#include "core/scene/museum/shapes.hpp"

#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

namespace vitrine::scene::museum {

namespace {

constexpr float kLoop = 32.0f;    // seconds per lap
constexpr float kStepRate = 1.0f; // strides per second
constexpr glm::vec3 kCenter(0.0f, 0.0f, 3.3f);
constexpr glm::vec2 kRadii(9.0f, 0.5f);

void limb(MeshBuilder& b, const Museum& m, float upper, float lower, float r) {
    b.material(m.mat.robotDark);
    sphere(b, r * 1.15f, 12, 16, 1.0f); // joint at the origin
    b.material(m.mat.robotWhite);
    const glm::vec2 top[] = {{0.0f, -upper}, {r, -upper}, {r * 1.1f, -0.5f * upper}, {r, -0.03f}, {0.0f, -0.03f}};
    lathe(b, top, 16, glm::vec2(1.0f));
    b.material(m.mat.robotDark);
    b.transform(glm::translate(glm::mat4(1.0f), {0.0f, -upper, 0.0f}));
    sphere(b, r * 0.95f, 10, 14, 1.0f);
    b.material(m.mat.robotWhite);
    const glm::vec2 bottom[] = {
        {0.0f, -lower}, {r * 0.8f, -lower}, {r * 0.95f, -0.5f * lower}, {r * 0.85f, -0.03f}, {0.0f, -0.03f}};
    lathe(b, bottom, 16, glm::vec2(1.0f));
    b.transform(glm::mat4(1.0f));
}

AnimationSampler sampler(Interpolation mode = Interpolation::Linear) {
    AnimationSampler s;
    s.interpolation = mode;
    return s;
}

} // namespace

void buildRobot(Museum& m) {
    Rng rng = m.rng.fork(77);
    float stride = rng.uniform(0.38f, 0.48f); // swing amplitude (radians): the gait differs with the seed
    float phase = rng.uniform(0.0f, 1.0f);

    uint32_t root = m.addNode("robot", Transform{});
    auto part = [&](MeshBuilder& b, const char* name, glm::vec3 at, uint32_t parent) {
        Transform t;
        t.translation = at;
        return m.place(b, name, t, false, static_cast<int32_t>(parent));
    };
    MeshBuilder pelvisMesh("robot_pelvis"), torsoMesh("robot_torso"), headMesh("robot_head");
    pelvisMesh.material(m.mat.robotDark);
    box(pelvisMesh, {-0.16f, -0.06f, -0.1f}, {0.16f, 0.08f, 0.1f}, 1.0f);
    uint32_t pelvis = part(pelvisMesh, "robot_pelvis", {0.0f, 0.86f, 0.0f}, root);

    torsoMesh.material(m.mat.robotWhite);
    auto chest = [](float s, float t) {
        float theta = glm::two_pi<float>() * s, y = 0.1f + 0.48f * t;
        float r = 0.16f + 0.05f * std::sin(glm::pi<float>() * (0.3f + 0.7f * t));
        return glm::vec3(r * std::cos(theta), y, -0.75f * r * std::sin(theta));
    };
    surface(torsoMesh, chest, 32, 10, glm::vec2(1.2f, 0.5f), glm::vec2(1.0f));
    torsoMesh.material(m.mat.robotDark);
    box(torsoMesh, {-0.12f, 0.58f, -0.08f}, {0.12f, 0.62f, 0.08f}, 1.0f);
    uint32_t torso = part(torsoMesh, "robot_torso", {0.0f, 0.0f, 0.0f}, pelvis);

    headMesh.material(m.mat.robotWhite);
    headMesh.transform(glm::scale(glm::translate(glm::mat4(1.0f), {0.0f, 0.12f, 0.0f}), {1.0f, 0.85f, 0.95f}));
    sphere(headMesh, 0.13f, 20, 32, 1.0f);
    headMesh.transform(glm::mat4(1.0f));
    headMesh.material(m.mat.robotEye);
    box(headMesh, {-0.09f, 0.11f, 0.1f}, {0.09f, 0.15f, 0.13f}, 1.0f); // the glowing visor, facing +z
    headMesh.material(m.mat.robotDark);
    const glm::vec2 neck[] = {{0.04f, -0.02f}, {0.04f, 0.03f}};
    lathe(headMesh, neck, 12, glm::vec2(1.0f));
    uint32_t headNode = part(headMesh, "robot_head", {0.0f, 0.64f, 0.0f}, torso);

    uint32_t limbs[4];
    const char* names[4] = {"robot_leg_l", "robot_leg_r", "robot_arm_l", "robot_arm_r"};
    for (int i = 0; i < 4; ++i) {
        MeshBuilder b(names[i]);
        bool leg = i < 2;
        limb(b, m, leg ? 0.4f : 0.27f, leg ? 0.38f : 0.25f, leg ? 0.07f : 0.05f);
        if (leg) {
            b.material(m.mat.robotDark);
            box(b, {-0.06f, -0.86f, -0.07f}, {0.06f, -0.8f, 0.14f}, 1.0f); // foot
        }
        float side = (i % 2 == 0) ? 1.0f : -1.0f;
        glm::vec3 at = leg ? glm::vec3(side * 0.1f, 0.0f, 0.0f) : glm::vec3(side * 0.24f, 0.56f, 0.0f);
        limbs[i] = part(b, names[i], at, leg ? pelvis : torso);
    }

    // One looping animation: the root follows the ellipse facing its direction of travel (+z forward), the
    // pelvis bobs twice per stride, legs and arms swing in opposition, the head looks around.
    Animation a;
    a.name = "robot_patrol";
    a.loop = true;
    AnimationSampler move = sampler(), turn = sampler(), bob = sampler(), look = sampler();
    AnimationSampler swing[4] = {sampler(), sampler(), sampler(), sampler()};
    for (int k = 0; k <= 128; ++k) {
        float t = kLoop * k / 128.0f, u = glm::two_pi<float>() * t / kLoop;
        glm::vec3 p = kCenter + glm::vec3(kRadii.x * std::cos(u), 0.0f, kRadii.y * std::sin(u));
        glm::vec3 velocity(-kRadii.x * std::sin(u), 0.0f, kRadii.y * std::cos(u));
        float yaw = std::atan2(velocity.x, velocity.z);
        move.times.push_back(t);
        move.values.push_back(glm::vec4(p, 0.0f));
        glm::quat q = glm::angleAxis(yaw, glm::vec3(0, 1, 0));
        if (k > 0 && glm::dot(q, toQuat(turn.values.back())) < 0.0f) q = -q; // keep slerp on the short arc
        turn.times.push_back(t);
        turn.values.push_back(toVec4(q));
    }
    for (int k = 0; k <= 512; ++k) {
        float t = kLoop * k / 512.0f, w = glm::two_pi<float>() * (kStepRate * t + phase);
        bob.times.push_back(t);
        bob.values.push_back(glm::vec4(0.0f, 0.86f + 0.02f * std::abs(std::sin(w)), 0.0f, 0.0f));
        for (int i = 0; i < 4; ++i) {
            float sign = (i == 0 || i == 3) ? 1.0f : -1.0f; // left leg with right arm
            float amplitude = i < 2 ? stride : 0.7f * stride;
            swing[i].times.push_back(t);
            swing[i].values.push_back(toVec4(glm::angleAxis(sign * amplitude * std::sin(w), glm::vec3(1, 0, 0))));
        }
        look.times.push_back(t);
        look.values.push_back(
            toVec4(glm::angleAxis(0.5f * std::sin(glm::two_pi<float>() * t / 8.0f), glm::vec3(0, 1, 0))));
    }
    a.samplers = {move, turn, bob, look, swing[0], swing[1], swing[2], swing[3]};
    a.channels = {{root, AnimationPath::Translation, 0},   {root, AnimationPath::Rotation, 1},
                  {pelvis, AnimationPath::Translation, 2}, {headNode, AnimationPath::Rotation, 3},
                  {limbs[0], AnimationPath::Rotation, 4},  {limbs[1], AnimationPath::Rotation, 5},
                  {limbs[2], AnimationPath::Rotation, 6},  {limbs[3], AnimationPath::Rotation, 7}};
    m.scene.animations.push_back(std::move(a));
}

} // namespace vitrine::scene::museum
