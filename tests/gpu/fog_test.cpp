// fog.volumetric + fog.composite against references computed here, never from the shaders' code:
//   - a closed room lit by the sun through one ceiling window (with one shadow cascade and with four: each march
//     sample must read the cascade that covers it): the in-scattered radiance of rays through the shaft against a fine CPU ray-march whose sun visibility is a ray cast against the room's geometry, with
//     the Henyey-Greenstein phase written out here and the sky's ambient integrated over the sphere by
//     quadrature (the shader uses the phase's zonal-harmonic convolution instead); rays that miss the shaft
//     carry the ambient term alone;
//   - extinction with the sun off: a pixel at distance d is colour·exp(−σd) + A·(1 − exp(−σd)), A the sky's
//     mean radiance (isotropic phase), d from a CPU ray cast;
//   - the depth-aware upsample: a quarter-resolution march composited over a near/far split keeps each side's
//     own fog at the edge;
//   - a coarse (4-step) march with its start offset jittered per frame, accumulated over 55 frames by
//     temporal.accumulate, against the closed-form transmittance of a medium thinning with height.
// Scenes are built in code and loaded through scene.gltf, like the lighting tests.
#include "tests/gpu/lighting_scene.hpp"

#include "core/shading/sh.hpp"
#include "shaders/sky/sky.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace vitrine::test {
namespace {

using nlohmann::json;
using namespace lighting;

class Fog : public GpuTest {};

double henyeyGreenstein(double cosTheta, double g) {
    double d = 1.0 + g * g - 2.0 * g * cosTheta;
    return (1.0 - g * g) / (4.0 * kPi * std::pow(d, 1.5));
}

// The ambient in-scattering along view direction v: the integral over the sphere of the sky's (SH) radiance
// arriving from w times the phase of turning it toward the camera, by the midpoint rule on a latitude-longitude
// grid (the integrand is smooth; 96 x 192 cells agree with a finer grid to ~1e-5).
glm::dvec3 ambientQuadrature(const shading::Sh9& sky, glm::dvec3 v, double g) {
    const int rows = 96, cols = 192;
    glm::dvec3 sum(0.0);
    for (int i = 0; i < rows; ++i) {
        double theta = kPi * (i + 0.5) / rows;
        double dA = (kPi / rows) * (2.0 * kPi / cols) * std::sin(theta);
        for (int j = 0; j < cols; ++j) {
            double phi = 2.0 * kPi * (j + 0.5) / cols;
            glm::dvec3 w(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
            sum += shading::shRadiance(sky, w) * henyeyGreenstein(glm::dot(w, v), g) * dA;
        }
    }
    return sum;
}

// Distance from o (inside the box) along unit d to the box's walls.
double exitBox(glm::dvec3 o, glm::dvec3 d, glm::dvec3 lo, glm::dvec3 hi) {
    double t = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (d[a] > 1e-12) t = std::min(t, (hi[a] - o[a]) / d[a]);
        if (d[a] < -1e-12) t = std::min(t, (lo[a] - o[a]) / d[a]);
    }
    return t;
}

// ---------------------------------------------------------------------------------------------
// 1. A sun shaft through a window

// The room: x, z in [-3, 3], y in [0, 3], closed but for a 1 m square hole in the ceiling. The sun, 70° up in
// front of the camera, shines through the hole in a slanted shaft; from inside, a point sees the sun exactly when
// its ray toward the sun crosses the ceiling's plane inside the hole (the room is convex, so nothing else can
// block it). The camera stands near the back wall and looks across the shaft. Compared: rays through the shaft
// (over 0.3 m of it) whose answer does not hinge on the shaft's exact edges (moving them by 2 cm, about a shadow
// texel, changes the CPU value by < 10 %: a ray grazing the shaft's side is as sensitive as it is long), and rays
// that pass 10 cm or more from it; rays that see the sky through the hole are skipped. The shadow map has no
// depth or slope bias: they keep lit surfaces from shadowing themselves, but lift the shadow off an occluder,
// which lights a layer of air under the ceiling. The march runs twice, over a shadow map of one cascade and one of
// four (the shaft lies ~2.5-3.5 m away, beyond the first split): each sample must read the cascade that covers it
// (issue 26).
TEST_F(Fog, ShaftMatchesCpuRayMarchAndAmbientOutsideIt) {
    const int W = 64, H = 48;
    const double room = 3.0, height = 3.0, hole = 0.5;
    const double sigma = 0.1, g = 0.5, ambientScale = 0.1;
    const int steps = 256;

    SceneBuilder b("fog_room");
    const uint32_t wall = b.material("wall", glm::vec3(0.5f), 0.0f, 0.2f);
    std::vector<Tri> tris;
    const float r = static_cast<float>(room), h = static_cast<float>(height), o = static_cast<float>(hole);
    addQuad(tris, {0, 0, 0}, {r, 0, 0}, {0, 0, r}, {0, 1, 0});          // floor
    addQuad(tris, {0, h / 2, -r}, {r, 0, 0}, {0, h / 2, 0}, {0, 0, 1}); // walls, facing in
    addQuad(tris, {0, h / 2, r}, {r, 0, 0}, {0, h / 2, 0}, {0, 0, -1});
    addQuad(tris, {-r, h / 2, 0}, {0, 0, r}, {0, h / 2, 0}, {1, 0, 0});
    addQuad(tris, {r, h / 2, 0}, {0, 0, r}, {0, h / 2, 0}, {-1, 0, 0});
    // The ceiling around the hole: two full-width strips and two pieces beside the hole.
    addQuad(tris, {0, h, (r + o) / 2}, {r, 0, 0}, {0, 0, (r - o) / 2}, {0, -1, 0});
    addQuad(tris, {0, h, -(r + o) / 2}, {r, 0, 0}, {0, 0, (r - o) / 2}, {0, -1, 0});
    addQuad(tris, {(r + o) / 2, h, 0}, {(r - o) / 2, 0, 0}, {0, 0, o}, {0, -1, 0});
    addQuad(tris, {-(r + o) / 2, h, 0}, {(r - o) / 2, 0, 0}, {0, 0, o}, {0, -1, 0});
    b.node("room", static_cast<int32_t>(b.mesh("room", tris, wall)));
    b.camera({0.0f, 1.5f, 2.7f}, {0.0f, 1.2f, -3.0f}, 1.0f);
    b.sun({0.2f, 1.0f, -0.3f});
    auto glb = b.write();

    json nodes = baseNodes(glb);
    nodes["shadow"] = {{"type", "shadow.directional"},
                       {"in", {{"scene", "scene.scene"}, {"camera", "scene.camera"}}},
                       {"params", {{"resolution", 1024}, {"cascades", 1}, {"distance", 12.0}, {"depth_bias", 0.0}, {"slope_bias", 0.0}}}};
    nodes["fog"] = {{"type", "fog.volumetric"},
                    {"in",
                     {{"depth", "gbuffer.depth"},
                      {"shadow_map", "shadow.shadow_map"},
                      {"cascades", "shadow.cascades"},
                      {"sky_sh", "sky.sh"},
                      {"camera", "scene.camera"}}},
                    {"params",
                     {{"density", sigma},
                      {"anisotropy", g},
                      {"ambient_scale", ambientScale},
                      {"steps", steps},
                      {"resolution", 1.0},
                      {"jitter", "off"}}}};
    nodes["shadow4"] = nodes["shadow"];
    nodes["shadow4"]["params"]["cascades"] = 4;
    nodes["fog4"] = nodes["fog"];
    nodes["fog4"]["in"]["shadow_map"] = "shadow4.shadow_map";
    nodes["fog4"]["in"]["cascades"] = "shadow4.cascades";
    auto out = runGraph(graph(nodes, {{"scatter", "fog.scatter"}, {"scatter4", "fog4.scatter"}, {"sh", "sky.sh"}}, W, H));
    const Image* scatters[2] = {&out.at("scatter"), &out.at("scatter4")};
    const int cascadeCounts[2] = {1, 4};
    ASSERT_EQ(scatters[0]->width, W);
    const glm::dvec3 l = glm::normalize(rgb(out.at("sh"), SKY_TEXEL_SUN_DIRECTION, 0));
    const glm::dvec3 sunE = rgb(out.at("sh"), SKY_TEXEL_SUN_ILLUMINANCE, 0);
    const shading::Sh9 sky = readSh(out.at("sh"));
    ASSERT_GT(sunE.g, 1000.0);
    ASSERT_GT(l.y, 0.5);

    // Lit when the ray toward the sun leaves through the hole grown by `margin` (negative: shrunk).
    auto throughHole = [&](glm::dvec3 x, double margin) {
        glm::dvec3 c = x + l * ((height - x.y) / l.y);
        return std::abs(c.x) < hole + margin && std::abs(c.z) < hole + margin;
    };

    Pinhole cam(b.s, W, H);
    const glm::dvec3 lo(-room, 0.0, -room), hi(room, height, room);
    const int fine = 4000;
    int inShaft = 0, outside = 0;
    double worstShaft[2] = {0.0, 0.0}, worstOutside[2] = {0.0, 0.0}, worstT[2] = {0.0, 0.0}, brightestShaft = 0.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const glm::dvec3 d = cam.ray(x, y);
            const double dist = exitBox(cam.position, d, lo, hi);
            const glm::dvec3 ambient = ambientQuadrature(sky, d, g) * ambientScale;
            const glm::dvec3 sun = sunE * henyeyGreenstein(glm::dot(l, d), g);
            // The reference march: fine steps, source and density constant over each, exact visibility.
            const double dt = dist / fine, stepT = std::exp(-sigma * dt);
            glm::dvec3 expected(0.0);
            double T = 1.0, litLength = 0.0;
            glm::dvec3 grown(0.0), shrunk(0.0);
            bool nearShaft = false;
            for (int i = 0; i < fine; ++i) {
                glm::dvec3 p = cam.position + d * ((i + 0.5) * dt);
                bool lit = throughHole(p, 0.0);
                nearShaft = nearShaft || throughHole(p, 0.1);
                if (lit) litLength += dt;
                const glm::dvec3 weight = T * (1.0 - stepT) * sun;
                expected += T * ambient * (1.0 - stepT) + (lit ? weight : glm::dvec3(0.0));
                if (throughHole(p, 0.02)) grown += weight;
                if (throughHole(p, -0.02)) shrunk += weight;
                T *= stepT;
            }
            const glm::dvec3 end = cam.position + d * dist;
            if (end.y > height - 1e-6 && std::abs(end.x) < hole + 0.05 && std::abs(end.z) < hole + 0.05) continue;
            const bool robust = glm::length(grown - shrunk) < 0.1 * glm::length(expected);
            const bool shaft = litLength > 0.3 && robust;
            if (shaft) {
                ++inShaft;
                brightestShaft = std::max(brightestShaft, expected.g / (ambient.g * (1.0 - T)));
            } else if (!nearShaft) {
                ++outside;
            }
            for (int k = 0; k < 2; ++k) {
                const glm::dvec3 got = rgb(*scatters[k], x, y);
                const double gotT = scatters[k]->at(x, y)[3];
                worstT[k] = std::max(worstT[k], std::abs(gotT - std::exp(-sigma * dist)));
                EXPECT_NEAR(gotT, std::exp(-sigma * dist), 2e-3)
                    << cascadeCounts[k] << " cascade(s), transmittance, pixel " << x << "," << y;
                if (shaft) {
                    double e = relErr(got, expected);
                    worstShaft[k] = std::max(worstShaft[k], e);
                    EXPECT_LT(e, 0.03) << cascadeCounts[k] << " cascade(s), through the shaft, pixel " << x << "," << y
                                       << ": " << got.g << " vs " << expected.g << " (lit " << litLength << " m)";
                } else if (!nearShaft) {
                    // The march's last sample lies within half a step of the surface, where the surface's own
                    // shadow-map texels decide whether it is lit (a texel is ~2 cm here, a step ~2 cm): the ray may
                    // gain at most that step's sun term.
                    const double lastStep = T * (1.0 - std::exp(-sigma * dist / steps)) * sun.g;
                    double e = std::abs(got.g - expected.g) / (0.01 * expected.g + lastStep);
                    worstOutside[k] = std::max(worstOutside[k], relErr(got, expected));
                    EXPECT_LT(e, 1.0) << cascadeCounts[k] << " cascade(s), outside the shaft, pixel " << x << "," << y
                                      << ": " << got.g << " vs " << expected.g << " (allowed: 1 % + " << lastStep << ")";
                    EXPECT_LT(relErr(got, expected), 0.05)
                        << cascadeCounts[k] << " cascade(s), outside the shaft, pixel " << x << "," << y;
                }
            }
        }
    for (int k = 0; k < 2; ++k)
        std::printf("fog shaft, %d cascade(s): %d pixels through the shaft (max relative error %.3g; the shaft up to "
                    "%.1fx the ambient in-scattering), %d outside it (ambient alone, max relative error %.3g), "
                    "transmittance max error %.2g\n",
                    cascadeCounts[k], inShaft, worstShaft[k], brightestShaft, outside, worstOutside[k], worstT[k]);
    EXPECT_GE(inShaft, 100);
    EXPECT_GE(outside, 500);
    EXPECT_GT(brightestShaft, 3.0); // the sun term dominates where the shaft is: it is what is measured there
}

// ---------------------------------------------------------------------------------------------
// 2 and 3. Extinction and the upsample, with the sun off

// Scenes of walls facing +Z in front of a camera at the origin looking down -Z; the colour under the fog is a
// checkerboard (pattern.checker), so it is known without any lighting.
struct FogWalls {
    std::filesystem::path glb;
    scene::Scene s;
};

FogWalls fogWalls(const std::string& name, const std::vector<std::vector<Tri>>& walls) {
    SceneBuilder b(name);
    const uint32_t m = b.material("wall", glm::vec3(0.5f), 0.0f, 0.2f);
    for (size_t i = 0; i < walls.size(); ++i)
        b.node("wall" + std::to_string(i),
               static_cast<int32_t>(b.mesh("wall" + std::to_string(i), walls[i], m)));
    b.camera({0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -1.0f}, 0.9f);
    b.sun({0.3f, 1.0f, 0.2f});
    FogWalls w;
    w.glb = b.write();
    w.s = b.s;
    return w;
}

json fogNodes(const std::filesystem::path& glb, double sigma, double resolution, double ambientScale) {
    json nodes = baseNodes(glb);
    nodes["checker"] = {{"type", "pattern.checker"},
                        {"params", {{"cell_size", 5.0}, {"color_a", {0.2, 0.4, 0.1, 1.0}}, {"color_b", {3.0, 2.0, 1.0, 1.0}}}}};
    nodes["fog"] = {{"type", "fog.volumetric"},
                    {"in", {{"depth", "gbuffer.depth"}, {"sky_sh", "sky.sh"}, {"camera", "scene.camera"}}},
                    {"params",
                     {{"density", sigma},
                      {"anisotropy", 0.0},
                      {"sun_scale", 0.0},
                      {"ambient_scale", ambientScale},
                      {"steps", 8},
                      {"resolution", resolution}}}};
    nodes["composite"] = {{"type", "fog.composite"},
                          {"in",
                           {{"color", "checker.color"},
                            {"depth", "gbuffer.depth"},
                            {"scatter", "fog.scatter"},
                            {"distance", "fog.distance"},
                            {"camera", "scene.camera"}}}};
    return nodes;
}

// A tilted floor-like wall receding from 3 m to ~25 m: every distance in between. With the sun off, isotropic
// scattering and a homogeneous medium the march is exact whatever its step count (8 here, jittered per pixel):
// T = exp(−σd) and the in-scattering is A (1 − T) with A the sky's mean radiance, SH band 0 × Y00, times
// ambient_scale. Output RGBA16F: 2e-3 of the value.
TEST_F(Fog, ExtinctionAndAmbientMatchClosedForm) {
    const int W = 48, H = 40;
    const double sigma = 0.12, ambientScale = 4e-4;
    std::vector<Tri> tilted;
    // The plane through (0, -1.5, -3) and (0, 1.5, -25), spanning x in [-20, 20].
    const glm::vec3 a(0.0f, -1.5f, -3.0f), c(0.0f, 1.5f, -25.0f);
    const glm::vec3 along = (c - a) * 0.5f, n = glm::normalize(glm::cross(glm::vec3(1, 0, 0), c - a));
    addQuad(tilted, (a + c) * 0.5f, glm::vec3(20, 0, 0), along, n.z > 0 ? n : -n);
    FogWalls w = fogWalls("fog_extinction", {tilted});
    // The same wall in a medium thinning with height, sigma(y) = sigma exp(-k (y - y0)): along a ray
    // y = dy t the optical depth to distance d is sigma exp(k y0) (1 - exp(-k dy d)) / (k dy). The march samples
    // sigma once per step (64 midpoints: the midpoint rule's error is ~(k dy dt)^2 / 24 < 1e-4 here).
    const double falloff = 0.35, reference = 1.0;
    json nodes = fogNodes(w.glb, sigma, 1.0, ambientScale);
    nodes["thinning"] = nodes["fog"];
    nodes["thinning"]["params"].update(json{{"height_falloff", falloff},
                                        {"height_reference", reference},
                                        {"steps", 64},
                                        {"jitter", "off"},
                                        {"ambient_scale", 0.0}});
    auto out = runGraph(graph(nodes,
                              {{"fogged", "composite.color"},
                               {"color", "checker.color"},
                               {"sh", "sky.sh"},
                               {"thinning", "thinning.scatter"}},
                              W, H));
    const shading::Sh9 sky = readSh(out.at("sh"));
    const glm::dvec3 mean = sky.c[0] * shading::shBasis9({0, 1, 0})[0] * ambientScale;
    ASSERT_GT(mean.b, 0.5);

    Pinhole cam(w.s, W, H);
    const glm::dvec3 pa(a), pn(glm::normalize(glm::cross(glm::vec3(1, 0, 0), c - a)));
    int checked = 0;
    double worst = 0.0, nearest = 1e30, farthest = 0.0, worstHeight = 0.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            double t = glm::dot(pa - cam.position, pn) / glm::dot(d, pn);
            glm::dvec3 hit = cam.position + t * d;
            if (t <= 0.0 || hit.z > -3.05 || hit.z < -24.95 || std::abs(hit.x) > 19.5) continue; // not on the wall
            ++checked;
            nearest = std::min(nearest, t);
            farthest = std::max(farthest, t);
            double T = std::exp(-sigma * t);
            glm::dvec3 expected = rgb(out.at("color"), x, y) * T + mean * (1.0 - T);
            double e = relErr(rgb(out.at("fogged"), x, y), expected);
            worst = std::max(worst, e);
            EXPECT_LT(e, 2e-3) << "pixel " << x << "," << y << " at " << t << " m";

            const double k = falloff * d.y;
            const double tau = sigma * std::exp(falloff * reference) *
                               (std::abs(k) < 1e-9 ? t : (1.0 - std::exp(-k * t)) / k);
            const double gotT = out.at("thinning").at(x, y)[3];
            worstHeight = std::max(worstHeight, std::abs(gotT - std::exp(-tau)));
            EXPECT_NEAR(gotT, std::exp(-tau), 2e-3) << "height falloff, pixel " << x << "," << y;
            EXPECT_EQ(out.at("thinning").at(x, y)[0], 0.0f); // no sun, no ambient: nothing in-scattered
        }
    std::printf("fog extinction: %d pixels at %.1f-%.1f m, max relative error %.2g; height falloff: transmittance "
                "max error %.2g\n",
                checked, nearest, farthest, worst, worstHeight);
    EXPECT_GE(checked, W * H / 3);
    EXPECT_GT(farthest - nearest, 10.0);
}

// The march's start offset: 4 steps through a medium whose density grows ten-fold from the top of a tilted wall to its
// foot (height falloff 1.5 /m), so one sample per step is far from the step's mean density and a fixed offset is
// biased (the step's start underestimates the optical depth by ~25 %). With jitter = pixel the offset moves by the
// golden ratio each frame; temporal.accumulate's running mean of 55 frames (a Fibonacci number: the sequence is most
// even there) must converge to the exact transmittance exp(-tau), tau the closed-form optical depth of the ray, and
// the in-scattered ambient to A (1 - exp(-tau)) (isotropic, sun off: A the sky's mean radiance x ambient_scale)
// at every pixel: the transmittance within 0.01 (measured 0.006: the mean of exp(-tau') over the offsets is not quite
// exp(-tau), and the RGBA16F history is rounded 55 times), the in-scattering within 3 % of A (measured 1.8 %). A fixed
// offset is off by 0.05-0.1 in transmittance here.
TEST_F(Fog, JitteredCoarseMarchAccumulatesToTheExactTransmittance) {
    const int W = 48, H = 40, frames = 55;
    const double sigma = 0.01, falloff = 1.5, reference = 1.5, ambientScale = 4e-4;
    std::vector<Tri> tilted;
    const glm::vec3 a(0.0f, -1.5f, -3.0f), c(0.0f, 1.5f, -25.0f);
    const glm::vec3 along = (c - a) * 0.5f, n = glm::normalize(glm::cross(glm::vec3(1, 0, 0), c - a));
    addQuad(tilted, (a + c) * 0.5f, glm::vec3(20, 0, 0), along, n.z > 0 ? n : -n);
    FogWalls w = fogWalls("fog_jitter", {tilted});
    json nodes = fogNodes(w.glb, sigma, 1.0, ambientScale);
    nodes.erase("composite");
    nodes["fog"]["params"].update(json{{"height_falloff", falloff}, {"height_reference", reference}, {"steps", 4},
                                       {"jitter", "pixel"}, {"shadows", false}});
    nodes["acc"] = {{"type", "temporal.accumulate"},
                    {"params", {{"max_samples", 64}}},
                    {"in", {{"color", "fog.scatter"}, {"history", "acc.color@prev"}, {"history_samples", "acc.samples@prev"}}}};
    json g = graph(nodes, {{"mean", "acc.color"}, {"one", "fog.scatter"}, {"sh", "sky.sh"}}, W, H);
    g["frame"]["frames"] = frames;
    auto out = runGraph(g);
    const shading::Sh9 sky = readSh(out.at("sh"));
    const glm::dvec3 A = sky.c[0] * shading::shBasis9({0, 1, 0})[0] * ambientScale;

    Pinhole cam(w.s, W, H);
    const glm::dvec3 pa(a), pn(glm::normalize(glm::cross(glm::vec3(1, 0, 0), c - a)));
    int checked = 0;
    double worst = 0.0, worstScatter = 0.0, worstOneFrame = 0.0, tauMin = 1e30, tauMax = 0.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const glm::dvec3 d = cam.ray(x, y);
            const double t = glm::dot(pa - cam.position, pn) / glm::dot(d, pn);
            const glm::dvec3 hit = cam.position + t * d;
            if (t <= 0.0 || hit.z > -3.05 || hit.z < -24.95 || std::abs(hit.x) > 19.5) continue; // not on the wall
            ++checked;
            const double k = falloff * d.y;
            const double tau = sigma * std::exp(falloff * reference) * (std::abs(k) < 1e-9 ? t : (1.0 - std::exp(-k * t)) / k);
            tauMin = std::min(tauMin, tau);
            tauMax = std::max(tauMax, tau);
            const double T = std::exp(-tau);
            const double got = out.at("mean").at(x, y)[3];
            worst = std::max(worst, std::abs(got - T));
            worstOneFrame = std::max(worstOneFrame, std::abs(double(out.at("one").at(x, y)[3]) - T));
            EXPECT_NEAR(got, T, 0.01) << "pixel " << x << "," << y << " (tau " << tau << ")";
            const double e = relErr(rgb(out.at("mean"), x, y), A * (1.0 - T)) * (1.0 - T); // relative to A
            worstScatter = std::max(worstScatter, e);
            EXPECT_LT(e, 0.03) << "in-scattering, pixel " << x << "," << y;
        }
    std::printf("jittered 4-step march, %d frames accumulated: %d pixels, optical depth %.2f-%.2f; transmittance max "
                "error %.4f (one frame alone: %.4f), in-scattering max error %.4f of A\n",
                frames, checked, tauMin, tauMax, worst, worstOneFrame, worstScatter);
    EXPECT_GE(checked, W * H / 3);
    EXPECT_GT(worstOneFrame, 0.03); // one frame's march is off: the accumulation is what converges
}

// A near wall (2 m) over the left of the view, beside an edge at x = 0.3 m, in front of a far one (20 m). The
// march runs at a quarter of the resolution; each full-resolution pixel must get its own side's fog (the
// closed form at its own distance) within 1 % of the fog's range, right up to the edge, where a plain bilinear
// upsample mixes the two (the test checks that it would: pixels with a far low-resolution neighbour exist).
TEST_F(Fog, UpsampleDoesNotBleedAcrossDepthEdge) {
    const int W = 64, H = 36;
    const double sigma = 0.1, ambientScale = 4e-4, nearZ = 2.0, farZ = 20.0, edgeX = 0.3;
    std::vector<Tri> nearWall, farWall;
    addQuad(nearWall, {static_cast<float>(edgeX - 5.0), 0, static_cast<float>(-nearZ)}, {5, 0, 0}, {0, 5, 0},
            {0, 0, 1});
    addQuad(farWall, {0, 0, static_cast<float>(-farZ)}, {40, 0, 0}, {0, 40, 0}, {0, 0, 1});
    FogWalls w = fogWalls("fog_edge", {nearWall, farWall});
    auto out = runGraph(graph(fogNodes(w.glb, sigma, 0.25, ambientScale),
                              {{"fogged", "composite.color"},
                               {"color", "checker.color"},
                               {"sh", "sky.sh"},
                               {"distance", "fog.distance"}},
                              W, H));
    const shading::Sh9 sky = readSh(out.at("sh"));
    const glm::dvec3 mean = sky.c[0] * shading::shBasis9({0, 1, 0})[0] * ambientScale;
    const Image& lowDistance = out.at("distance");
    ASSERT_EQ(lowDistance.width, W / 4);

    Pinhole cam(w.s, W, H);
    int checked = 0, besideEdge = 0;
    double worst = 0.0;
    const double range = glm::length(mean); // fog contributes 0 .. mean: errors are measured against that
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            double tNear = nearZ / -d.z;
            glm::dvec3 hitNear = cam.position + tNear * d;
            bool isNear = hitNear.x < edgeX;
            // Pixels whose footprint the edge crosses belong to neither side.
            double pixelX = 2.0 * nearZ * std::tan(0.45) * (double(W) / H) / W;
            if (std::abs(hitNear.x - edgeX) < pixelX) continue;
            double t = isNear ? tNear : farZ / -d.z;
            double T = std::exp(-sigma * t);
            glm::dvec3 colour = rgb(out.at("color"), x, y);
            glm::dvec3 expected = colour * T + mean * (1.0 - T);
            double e = glm::length(rgb(out.at("fogged"), x, y) - expected) / range;
            worst = std::max(worst, e);
            ++checked;
            // A low-resolution tap of the other side among the 2x2 a bilinear upsample reads here?
            double lx = (x + 0.5) / 4.0 - 0.5, ly = (y + 0.5) / 4.0 - 0.5;
            for (int j = 0; j < 2; ++j)
                for (int i = 0; i < 2; ++i) {
                    int tx = std::clamp(int(std::floor(lx)) + i, 0, W / 4 - 1);
                    int ty = std::clamp(int(std::floor(ly)) + j, 0, H / 4 - 1);
                    bool tapNear = lowDistance.at(tx, ty)[0] < 0.5 * (nearZ + farZ);
                    if (tapNear != isNear) {
                        ++besideEdge;
                        i = j = 2;
                    }
                }
            EXPECT_LT(e, 0.01) << (isNear ? "near" : "far") << " pixel " << x << "," << y;
        }
    std::printf("fog upsample: %d pixels, %d with a low-resolution tap across the edge, max error %.3g of the fog\n",
                checked, besideEdge, worst);
    EXPECT_GE(besideEdge, H); // the edge runs through the 2x2 footprint of at least a column of pixels
    EXPECT_GE(checked, W * H * 3 / 4);
}

// A pole narrower than a low-resolution texel, 2 m away in front of the far wall, placed between the centres of the
// low-resolution texels: none of the 2x2 taps around its pixels sees it, every bilateral weight is nil, and the
// composite takes the tap nearest in distance alone (fog/composite.comp), the far wall's fog. The pole's pixels are
// fogged as the tap nearest in distance says, within 1 % of the fog (taking none would leave them unfogged).
TEST_F(Fog, ThinFeatureTakesTheTapNearestInDistance) {
    const int W = 64, H = 36;
    const double sigma = 0.1, ambientScale = 4e-4, nearZ = 2.0, farZ = 20.0;
    const double pixelX = 2.0 * nearZ * std::tan(0.45) * (double(W) / H) / W; // a pixel's width at the pole
    std::vector<Tri> pole, farWall;
    // Full-resolution columns 27.25 .. 28.75 (the low-resolution texels' centres are at columns 26 and 30).
    addQuad(pole, {static_cast<float>(-4.0 * pixelX), 0.0f, static_cast<float>(-nearZ)},
            {static_cast<float>(0.75 * pixelX), 0, 0}, {0, 5, 0}, {0, 0, 1}); // centre, half extents
    addQuad(farWall, {0, 0, static_cast<float>(-farZ)}, {40, 0, 0}, {0, 40, 0}, {0, 0, 1});
    FogWalls w = fogWalls("fog_pole", {pole, farWall});
    auto out = runGraph(graph(fogNodes(w.glb, sigma, 0.25, ambientScale),
                              {{"fogged", "composite.color"},
                               {"color", "checker.color"},
                               {"sh", "sky.sh"},
                               {"distance", "fog.distance"},
                               {"scatter", "fog.scatter"}},
                              W, H));
    const Image& lowDistance = out.at("distance");
    const Image& scatter = out.at("scatter");
    ASSERT_EQ(lowDistance.width, W / 4);
    Pinhole cam(w.s, W, H);
    int checked = 0;
    double worst = 0.0, fogAmount = 0.0;
    for (int y = 4; y < H - 4; ++y)
        for (int x = 27; x <= 28; ++x) {
            const glm::dvec3 d = cam.ray(x, y);
            const double distance = (nearZ / -d.z) * glm::length(d);
            // The 2x2 taps: every one the far wall's; the one nearest in distance is taken.
            const double lx = (x + 0.5) / 4.0 - 0.5, ly = (y + 0.5) / 4.0 - 0.5;
            double nearest = 1e30;
            glm::dvec4 fog(0.0);
            for (int j = 0; j < 2; ++j)
                for (int i = 0; i < 2; ++i) {
                    const int tx = std::clamp(int(std::floor(lx)) + i, 0, W / 4 - 1);
                    const int ty = std::clamp(int(std::floor(ly)) + j, 0, H / 4 - 1);
                    const double tapDistance = lowDistance.at(tx, ty)[0];
                    ASSERT_GT(tapDistance, 0.5 * farZ) << "a tap sees the pole at " << x << "," << y;
                    const double rel = std::abs(tapDistance - distance) / distance;
                    if (rel < nearest) {
                        nearest = rel;
                        const float* s = scatter.at(tx, ty);
                        fog = {s[0], s[1], s[2], s[3]};
                    }
                }
            const glm::dvec3 colour = rgb(out.at("color"), x, y);
            const glm::dvec3 expected = colour * fog.a + glm::dvec3(fog);
            const double range = glm::length(glm::dvec3(fog)) + glm::length(colour) * (1.0 - fog.a);
            const double e = glm::length(rgb(out.at("fogged"), x, y) - expected) / range;
            worst = std::max(worst, std::isnan(e) ? 1e30 : e);
            fogAmount += 1.0 - fog.a;
            ++checked;
        }
    std::printf("thin pole: %d pixels fogged by the tap nearest in distance (mean transmittance %.3f), max error %.3g "
                "of the fog\n",
                checked, 1.0 - fogAmount / checked, worst);
    EXPECT_GE(checked, 50);
    EXPECT_GT(fogAmount / checked, 0.5); // the far wall's fog is thick: taking no tap would show
    EXPECT_LT(worst, 0.01);
}

} // namespace
} // namespace vitrine::test
