// The CPU path tracer traces a row's paths in batches, bounce by bounce (CpuPathTracer::Impl::tracePaths), so that
// their texture fetches overlap. Batching reorders work between paths only: each path must come out exactly as the
// path-by-path estimator (CpuRays::radiance, used by the ray-traced twins) computes it. This test renders the
// museum both ways and requires bit-identical accumulations.
#include "core/scene/museum.hpp"
#include "nodes/render/pathtrace_cpu.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>

namespace vitrine {
namespace {

// A small sky: every face one radiance, a valid (uniform) sampling table so that sky sampling and its MIS run, and
// a low sun that enters the museum's windows.
CpuSky testSky() {
    CpuSky sky;
    sky.size = 4;
    for (int f = 0; f < 6; ++f) {
        Image face(sky.size, sky.size);
        for (int y = 0; y < sky.size; ++y)
            for (int x = 0; x < sky.size; ++x) {
                float* p = face.at(x, y);
                p[0] = 900.0f + 100.0f * f;
                p[1] = 1100.0f;
                p[2] = 1600.0f - 50.0f * y;
                p[3] = 1.0f;
            }
        sky.faces.push_back(face);
    }
    // sky.env_cdf's layout: per row its conditional CDF in x < size, the rows' marginal CDF in column size, the
    // unnormalised total at (0, 6 size).
    sky.envCdf = Image(sky.size + 1, 6 * sky.size + 1);
    for (int row = 0; row < 6 * sky.size; ++row) {
        for (int x = 0; x < sky.size; ++x) sky.envCdf.at(x, row)[0] = static_cast<float>(x + 1) / sky.size;
        sky.envCdf.at(sky.size, row)[0] = static_cast<float>(row + 1) / (6.0f * sky.size);
    }
    sky.envCdf.at(0, 6 * sky.size)[0] = 1.0f;
    sky.sunIlluminance = glm::vec3(90000.0f, 85000.0f, 80000.0f);
    sky.sunDirection = glm::normalize(glm::vec3(0.4f, 0.5f, 0.3f));
    return sky;
}

TEST(PathTraceCpuBatch, BatchedRowsEqualThePathByPathTracerBitForBit) {
    scene::MuseumOptions o;
    o.textureSize = 64; // textured, so the batch's texel prefetching runs on every hit
    const scene::Scene museum = scene::buildMuseum(o);
    ASSERT_FALSE(museum.cameraPaths.empty());
    const scene::CameraKey& key = museum.cameraPaths.front().keys.front();

    CpuTraceSettings s;
    s.width = 40;
    s.height = 24;
    s.spp = 5; // not a divisor of the batch: batches straddle pixels
    s.seed = 7;
    const glm::mat4 view = glm::inverse(glm::translate(glm::mat4(1.0f), key.position) * glm::mat4_cast(key.orientation));
    // Reversed depth, as the renderer's cameras: ndc z 1 at the near plane.
    const glm::mat4 proj = glm::perspectiveRH_ZO(key.yfov, float(s.width) / float(s.height), 100.0f, 0.1f);
    s.invViewProj = glm::inverse(proj * view);
    s.cameraPos = key.position;

    const CpuSky sky = testSky();
    CpuPathTracer tracer(museum, {});

    CpuAccumulation batched, pathByPath;
    const CpuTraceCounters cb = tracer.trace(s, sky, batched);
    const CpuTraceCounters cp = tracer.estimate(s, sky, pathByPath, [&](const CpuRays& q, int x, int y, uint32_t& rng) {
        glm::vec2 jitter = s.antialias ? CpuRays::next2(rng) : glm::vec2(0.5f);
        glm::vec3 origin, direction;
        q.cameraRay(x, y, jitter, origin, direction);
        return q.radiance(origin, direction, rng);
    });

    // The scene was seen: paths bounced and gathered light.
    EXPECT_GT(cb.rays, 3 * cb.paths);
    double sum = 0.0;
    for (const glm::vec4& c : batched.color) sum += c.g;
    EXPECT_GT(sum / batched.color.size(), 1.0);
    std::printf("%llu paths, %llu rays; mean green %.1f cd/m^2\n", static_cast<unsigned long long>(cb.paths),
                static_cast<unsigned long long>(cb.rays), sum / batched.color.size());

    EXPECT_EQ(cb.rays, cp.rays);
    ASSERT_EQ(batched.color.size(), pathByPath.color.size());
    size_t differing = 0;
    for (size_t i = 0; i < batched.color.size(); ++i)
        if (std::memcmp(&batched.color[i], &pathByPath.color[i], sizeof(glm::vec4)) != 0 ||
            std::memcmp(&batched.stats[i], &pathByPath.stats[i], sizeof(glm::vec4)) != 0)
            ++differing;
    EXPECT_EQ(differing, 0u) << "of " << batched.color.size() << " pixels";
}

} // namespace
} // namespace vitrine
