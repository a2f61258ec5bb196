// The test corpus tests/data/gltf/corpus/ (written by its make_corpus.py, validated by ctest gltf.validator) against
// numbers worked out independently: node animation between keys against the glTF 2.0 specification's interpolation
// formulas (Appendix C), written here again in double precision; camera projections (issue #29 items 3 and 5).

#include "core/scene/gltf.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace vitrine::scene {
namespace {

using dvec3 = glm::dvec3;
using dvec4 = glm::dvec4; // quaternions as x, y, z, w

// glTF 2.0 Appendix C, "Spherical Linear Interpolation": a = acos|d|, s0 = sin((1 − t)a) / sin a,
// s1 = sign(d) sin(ta) / sin a.
dvec4 specSlerp(dvec4 q0, dvec4 q1, double t) {
    double d = glm::dot(q0, q1);
    double a = std::acos(std::min(std::abs(d), 1.0));
    if (a < 1e-9) return q0;
    double s0 = std::sin((1 - t) * a) / std::sin(a), s1 = (d < 0 ? -1.0 : 1.0) * std::sin(t * a) / std::sin(a);
    return s0 * q0 + s1 * q1;
}

// Appendix C, "Cubic Spline Interpolation": v0, b0 = out-tangent of key k; a1 = in-tangent of key k + 1, v1; td = key
// spacing in seconds.
template <class V> V specCubic(V v0, V b0, V a1, V v1, double td, double t) {
    double t2 = t * t, t3 = t2 * t;
    return (2 * t3 - 3 * t2 + 1) * v0 + td * (t3 - 2 * t2 + t) * b0 + (-2 * t3 + 3 * t2) * v1 + td * (t3 - t2) * a1;
}

glm::dmat4 trs(dvec3 t, dvec4 q, dvec3 s) {
    glm::dquat r(q.w, q.x, q.y, q.z);
    return glm::translate(glm::dmat4(1.0), t) * glm::mat4_cast(r) * glm::scale(glm::dmat4(1.0), s);
}

void expectMatrixNear(const glm::mat4& got, const glm::dmat4& want, double tolerance, const std::string& what) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            EXPECT_NEAR(got[c][r], want[c][r], tolerance) << what << " [" << c << "][" << r << "]";
}

TEST(GltfCorpus, NodeAnimationBetweenKeysFollowsTheSpecFormulas) {
    Scene s = loadGltf(test::dataDir() / "corpus" / "animation.gltf");
    ASSERT_EQ(s.nodes.size(), 2u);
    const double h = std::sqrt(0.5);
    const dvec4 id(0, 0, 0, 1), aboutY(0, h, 0, h), aboutX(h, 0, 0, h);

    // Node 0: LINEAR translation and rotation (slerp), STEP scale; keys at 0, 1, 3 s.
    struct Case {
        double t;
        dvec3 translation;
        dvec4 rotation;
        dvec3 scale;
    };
    for (const Case& c : {Case{0.25, glm::mix(dvec3(0), dvec3(2, 4, -2), 0.25), specSlerp(id, aboutY, 0.25), dvec3(1)},
                          Case{2.0, glm::mix(dvec3(2, 4, -2), dvec3(2, 0, 6), 0.5), specSlerp(aboutY, aboutX, 0.5),
                               dvec3(2, 3, 4)},
                          Case{2.9, glm::mix(dvec3(2, 4, -2), dvec3(2, 0, 6), 0.95), specSlerp(aboutY, aboutX, 0.95),
                               dvec3(2, 3, 4)},
                          Case{5.0, dvec3(2, 0, 6), aboutX, dvec3(0.5)}}) {
        expectMatrixNear(s.evaluate(c.t).nodeWorld[0], trs(c.translation, c.rotation, c.scale), 2e-6,
                         "linear/step node at t=" + std::to_string(c.t));
    }

    // Node 1: CUBICSPLINE translation and rotation, keys at 0 and 2 s (td = 2), tangents per second.
    const dvec3 tv0(0, 0, 0), tb0(3, 0, 1), ta1(1, 2, 0), tv1(4, 1, -2);
    const dvec4 rv0(0, 0, 0, 1), rb0(0, 0.5, 0, 0), ra1(0, 0.2, 0, 0), rv1(0, h, 0, h);
    // (the file's layout: key 0 = in (0), value, out; key 1 = in, value, out (0))
    for (double t : {0.3, 0.5, 1.0, 1.7}) {
        double u = t / 2.0;
        dvec3 tr = specCubic(tv0, tb0, ta1, tv1, 2.0, u);
        dvec4 q = glm::normalize(specCubic(rv0, rb0, ra1, rv1, 2.0, u));
        expectMatrixNear(s.evaluate(t).nodeWorld[1], trs(tr, q, dvec3(1)), 2e-6, "cubic node at t=" + std::to_string(t));
    }
    // Not a straight line: at t = 1 the cubic translation differs from the linear mix of the keys.
    EXPECT_GT(glm::distance(specCubic(tv0, tb0, ta1, tv1, 2.0, 0.5), glm::mix(tv0, tv1, 0.5)), 0.1);
}

// The marker's view-space centre P (asset.extras.expect) through CameraState::projection(): a camera's authored
// aspectRatio never stretches the image (the Sample Viewer's rule). Perspective: NDC = (P.x / (−P.z tan(yfov/2)) /
// frameAspect, −P.y / (−P.z tan(yfov/2))) with Vulkan's y down. Orthographic (xmag 2, ymag 1): ymag kept on a landscape
// frame (xmag = ymag × aspect), xmag kept on a square one (ymag = xmag / aspect).
TEST(GltfCorpus, AuthoredAspectRatioKeepsTheFieldOfViewAndNeverStretches) {
    auto ndc = [](const Scene& s, float frameAspect) {
        CameraState c = s.cameraAt(s.cameraPaths.at(0).name, 0.0);
        glm::vec4 clip = c.projection(frameAspect) * c.view * glm::vec4(s.instances.at(0).worldBounds.center(), 1.0f);
        return glm::vec2(clip) / clip.w;
    };
    Scene persp = loadGltf(test::dataDir() / "corpus" / "camera_aspect.gltf");
    ASSERT_EQ(persp.cameras.at(0).aspectRatio, 1.5f); // kept as authored, for export
    glm::vec2 square = ndc(persp, 1.0f), wide = ndc(persp, 2.0f);
    // The file puts P at 0.6 and 0.4 of the half-height tan(yfov/2) × depth.
    EXPECT_NEAR(square.x, 0.6f, 1e-5f);
    EXPECT_NEAR(square.y, -0.4f, 1e-5f); // not 0.4 × 1.5: the vertical field of view is the authored one
    EXPECT_NEAR(wide.x, 0.3f, 1e-5f);
    EXPECT_NEAR(wide.y, -0.4f, 1e-5f);

    Scene ortho = loadGltf(test::dataDir() / "corpus" / "camera_ortho.gltf");
    ASSERT_EQ(ortho.cameras.at(0).projection, Projection::Orthographic);
    glm::vec2 o1 = ndc(ortho, 1.0f), o2 = ndc(ortho, 2.0f), oHalf = ndc(ortho, 0.5f);
    // P = (1.2, 0.5). Square: xmag 2 kept, ymag 2. 2:1: ymag 1 kept, xmag 2. 1:2: xmag 2 kept, ymag 4.
    EXPECT_NEAR(o1.x, 0.6f, 1e-5f);
    EXPECT_NEAR(o1.y, -0.25f, 1e-5f);
    EXPECT_NEAR(o2.x, 0.6f, 1e-5f);
    EXPECT_NEAR(o2.y, -0.5f, 1e-5f);
    EXPECT_NEAR(oHalf.x, 0.6f, 1e-5f);
    EXPECT_NEAR(oHalf.y, -0.125f, 1e-5f);
}

// The +X face of morph_cube.gltf's cube sits at x = 0.5 + weight × 1 (its one target moves that face by 1 in x).
float plusXFace(const Scene& s, const std::vector<Vertex>& vertices) {
    float x = -1e9f;
    for (const Vertex& v : vertices)
        x = std::max(x, v.position.x);
    (void)s;
    return x;
}

TEST(GltfCorpus, MorphTargetsAtDefaultAndAnimatedWeights) {
    Scene still = loadGltf(test::dataDir() / "corpus" / "morph_cube.gltf");
    ASSERT_EQ(still.meshes.at(0).weights, std::vector<float>{0.5f});
    ASSERT_EQ(still.primitives.at(0).targetCount, 1u);
    EXPECT_FLOAT_EQ(plusXFace(still, still.vertices), 1.0f); // rest pose: weight 0.5 applied
    EXPECT_FLOAT_EQ(still.bounds.max.x, 1.0f);
    EXPECT_FLOAT_EQ(still.bounds.min.x, -0.5f); // the other faces stay
    std::vector<Vertex> v(still.primitives[0].vertexCount);
    still.morphVertices(0, {1.0f}, v);
    EXPECT_FLOAT_EQ(plusXFace(still, v), 1.5f);
    still.morphVertices(0, {0.0f}, v);
    EXPECT_FLOAT_EQ(plusXFace(still, v), 0.5f);

    Scene moving = loadGltf(test::dataDir() / "corpus" / "morph_animated.gltf");
    EXPECT_FLOAT_EQ(plusXFace(moving, moving.vertices), 0.5f); // weight 0 at rest
    for (double t : {0.0, 0.5, 1.0, 1.5, 2.0, 3.0}) {
        ScenePose pose = moving.evaluate(t);
        ASSERT_EQ(pose.meshWeights.size(), 1u);
        float w = static_cast<float>(std::clamp(t / 2.0, 0.0, 1.0)); // LINEAR 0 -> 1 over [0, 2] s, clamped
        ASSERT_EQ(pose.meshWeights[0].size(), 1u);
        EXPECT_NEAR(pose.meshWeights[0][0], w, 1e-6f) << t;
        moving.morphVertices(0, pose.meshWeights[0], v);
        EXPECT_NEAR(plusXFace(moving, v), 0.5f + w, 1e-6f) << t;
    }

    // Export writes the targets back (base = weights 0, the weights, the weight animation).
    auto file = test::scratchDir() / "morph_animated.glb";
    exportGlb(moving, file);
    Scene back = loadGltf(file);
    EXPECT_EQ(back.meshes.at(0).weights, moving.meshes[0].weights);
    EXPECT_NEAR(back.evaluate(1.0).meshWeights.at(0).at(0), 0.5f, 1e-6f);
    back.morphVertices(0, {1.0f}, v);
    EXPECT_NEAR(plusXFace(back, v), 1.5f, 1e-6f);
}

// skin_bend.gltf: joint 1 at (0, 1) turns θ = 90° × min(t, 1) about +Z. Linear blend skinning written out here: a
// vertex (x, y) of joint 1 goes to (x cos θ − (y − 1) sin θ, 1 + x sin θ + (y − 1) cos θ); joint 0 leaves it; the
// row at y = 1 is the mean of the two.
glm::dvec2 cpuSkinned(glm::dvec2 p, double theta) {
    glm::dvec2 j1(p.x * std::cos(theta) - (p.y - 1) * std::sin(theta), 1 + p.x * std::sin(theta) + (p.y - 1) * std::cos(theta));
    if (p.y < 1.0) return p;
    if (p.y == 1.0) return 0.5 * (p + j1);
    return j1;
}

TEST(GltfCorpus, SkinTwoBoneBendMatchesCpuSkinning) {
    Scene s = loadGltf(test::dataDir() / "corpus" / "skin_bend.gltf");
    ASSERT_EQ(s.skins.size(), 1u);
    ASSERT_TRUE(s.primitives.at(0).skinned);
    const uint32_t bar = 1;
    ASSERT_EQ(s.nodes.at(bar).skin, 0);
    ASSERT_EQ(s.vertices.size(), 10u);
    EXPECT_TRUE(s.instances.at(0).dynamic); // its joints are animated: no lightmap
    std::vector<Vertex> v(10);
    for (double t : {0.0, 0.25, 0.5, 1.0, 2.0}) {
        double theta = 0.5 * 3.14159265358979 * std::min(t, 1.0);
        s.skinPrimitive(0, s.jointMatrices(bar, s.evaluate(t)), v);
        for (size_t i = 0; i < v.size(); ++i) {
            glm::dvec2 bind(s.skinVertices[i].position);
            glm::dvec2 want = cpuSkinned(bind, theta);
            EXPECT_NEAR(v[i].position.x, want.x, 2e-6) << "vertex " << i << " t=" << t;
            EXPECT_NEAR(v[i].position.y, want.y, 2e-6) << "vertex " << i << " t=" << t;
            EXPECT_NEAR(v[i].position.z, 0.0, 1e-6);
        }
    }
    EXPECT_NEAR(v[9].position.x, -1.0f, 1e-6f); // the tip (0.1, 2) at t >= 1
    EXPECT_NEAR(v[9].position.y, 1.1f, 1e-6f);
    // The rest pose (joints as the nodes have them, θ = 0) is the straight bar.
    for (size_t i = 0; i < v.size(); ++i)
        EXPECT_EQ(s.vertices[i].position, s.skinVertices[i].position);

    // Export keeps the skin: JOINTS_0, WEIGHTS_0, the skin and its joints, the same bend.
    auto file = test::scratchDir() / "skin_bend.glb";
    exportGlb(s, file);
    Scene back = loadGltf(file);
    ASSERT_EQ(back.skins.size(), 1u);
    back.skinPrimitive(0, back.jointMatrices(bar, back.evaluate(1.0)), v);
    EXPECT_NEAR(v[9].position.x, -1.0f, 1e-6f);
    EXPECT_NEAR(v[9].position.y, 1.1f, 1e-6f);
}

TEST(GltfCorpus, MeshQuantizationIntegerAndNormalisedAttributes) {
    Scene s = loadGltf(test::dataDir() / "corpus" / "quantized.gltf");
    ASSERT_EQ(s.vertices.size(), 3u);
    // SHORT positions as integers (not normalised), the node's 0.01 scale in its transform.
    EXPECT_EQ(s.vertices[0].position, glm::vec3(100, 0, 0));
    EXPECT_EQ(s.vertices[1].position, glm::vec3(0, 200, 0));
    EXPECT_EQ(s.vertices[2].position, glm::vec3(0, 0, -300));
    glm::vec4 world = s.instances.at(0).world * glm::vec4(s.vertices[2].position, 1.0f);
    EXPECT_NEAR(world.z, -3.0f, 1e-5f);
    // Normalised BYTE 127 → 1; normalised UNSIGNED_SHORT c / 65535.
    EXPECT_EQ(s.vertices[0].normal, glm::vec3(0, 0, 1));
    EXPECT_FLOAT_EQ(s.vertices[0].uv0.x, 1.0f);
    EXPECT_FLOAT_EQ(s.vertices[0].uv0.y, 32768.0f / 65535.0f);
    EXPECT_FLOAT_EQ(s.vertices[2].uv0.y, 1.0f);
}

} // namespace
} // namespace vitrine::scene
