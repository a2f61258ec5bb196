#include "core/bake/lightmap_bake.hpp"

#include "core/scene/hash.hpp"
#include "core/scene/scene.hpp"
#include "core/shading/sh.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

namespace vitrine::bake {

namespace {

constexpr uint32_t kVersion = 3; // 2: the filter keeps energy, texels average the paths that start outside geometry;
                                 // 3: bounces reflect with the full material (GGX + Lambert), 8 of them by default
constexpr char kMagic[4] = {'V', 'T', 'L', 'M'};

struct Header {
    char magic[4];
    uint32_t version;
    uint32_t width, height;
    uint32_t counts[3];
    float origin[3];
    float spacing;
    uint32_t pad;
};
static_assert(sizeof(Header) == 48);

} // namespace

IrradianceVolume planIrradianceVolume(const scene::Scene& scene, float spacing, uint32_t maxProbes) {
    IrradianceVolume v;
    scene::Aabb bounds;
    bool any = false;
    for (const scene::MeshInstance& inst : scene.instances)
        if (!inst.dynamic) {
            bounds.expand(inst.worldBounds);
            any = true;
        }
    if (!any || !(spacing > 0.0f) || maxProbes == 0) return v;
    const glm::vec3 extent = glm::max(bounds.max - bounds.min, glm::vec3(0.0f));
    auto countsFor = [&](float s) { return glm::uvec3(glm::ceil(extent / s)) + 1u; };
    glm::uvec3 counts = countsFor(spacing);
    while (size_t(counts.x) * counts.y * counts.z > maxProbes) {
        spacing *= 1.1f;
        counts = countsFor(spacing);
    }
    // Centred on the bounds, so the grid's overhang is the same on both sides.
    v.spacing = spacing;
    v.counts = counts;
    v.origin = (bounds.min + bounds.max) * 0.5f - spacing * glm::vec3(counts - 1u) * 0.5f;
    v.sh.assign(v.probeCount(), {});
    v.validity.assign(v.probeCount(), 0.0f);
    return v;
}

glm::vec3 probeDirection(uint32_t i, uint32_t count) {
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    const double z = 1.0 - (2.0 * i + 1.0) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden * i;
    return glm::vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z));
}

void projectProbe(IrradianceVolume& volume, size_t probe, std::span<const glm::vec3> radiance, float backFaces) {
    shading::Sh9 sh;
    const uint32_t n = static_cast<uint32_t>(radiance.size());
    const double weight = 4.0 * std::numbers::pi / std::max(n, 1u);
    for (uint32_t i = 0; i < n; ++i)
        shading::shAccumulate(sh, glm::dvec3(probeDirection(i, n)), glm::dvec3(radiance[i]), weight);
    for (int k = 0; k < 9; ++k) volume.sh.at(probe)[k] = glm::vec3(sh.c[k]);
    volume.validity.at(probe) = backFaces > 0.25f ? 0.0f : 1.0f;
}

std::vector<glm::vec4> bakeJobs(const LightmapTexels& texels, const IrradianceVolume& volume, uint32_t probeRays,
                                size_t* texelJobs) {
    std::vector<glm::vec4> jobs;
    for (size_t i = 0; i < texels.region.size(); ++i)
        if (texels.region[i] >= 0) {
            jobs.emplace_back(texels.position[i], kJobTexel);
            jobs.emplace_back(texels.normal[i], float(i));
        }
    if (texelJobs) *texelJobs = jobs.size() / 2;
    for (uint32_t z = 0; z < volume.counts.z; ++z)
        for (uint32_t y = 0; y < volume.counts.y; ++y)
            for (uint32_t x = 0; x < volume.counts.x; ++x) {
                const size_t probe = x + size_t(volume.counts.x) * (y + size_t(volume.counts.y) * z);
                for (uint32_t r = 0; r < probeRays; ++r) {
                    jobs.emplace_back(volume.position(x, y, z), kJobProbeRay);
                    jobs.emplace_back(probeDirection(r, probeRays), float(probe * probeRays + r));
                }
            }
    return jobs;
}

std::vector<uint8_t> serializeBakedLighting(const BakedLighting& b) {
    Header h{};
    std::memcpy(h.magic, kMagic, sizeof kMagic);
    h.version = kVersion;
    h.width = b.width;
    h.height = b.height;
    for (int i = 0; i < 3; ++i) {
        h.counts[i] = b.volume.counts[i];
        h.origin[i] = b.volume.origin[i];
    }
    h.spacing = b.volume.spacing;
    const size_t probes = b.volume.probeCount();
    std::vector<uint8_t> out(sizeof h + b.lightmap.size() * 4 + probes * (27 + 1) * 4);
    uint8_t* p = out.data();
    std::memcpy(p, &h, sizeof h);
    p += sizeof h;
    std::memcpy(p, b.lightmap.data(), b.lightmap.size() * 4);
    p += b.lightmap.size() * 4;
    if (probes) {
        std::memcpy(p, b.volume.sh.data(), probes * 27 * 4);
        p += probes * 27 * 4;
        std::memcpy(p, b.volume.validity.data(), probes * 4);
    }
    return out;
}

std::optional<BakedLighting> deserializeBakedLighting(std::span<const uint8_t> bytes) {
    Header h;
    if (bytes.size() < sizeof h) return std::nullopt;
    std::memcpy(&h, bytes.data(), sizeof h);
    if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0 || h.version != kVersion) return std::nullopt;
    BakedLighting b;
    b.width = h.width;
    b.height = h.height;
    b.volume.counts = {h.counts[0], h.counts[1], h.counts[2]};
    b.volume.origin = {h.origin[0], h.origin[1], h.origin[2]};
    b.volume.spacing = h.spacing;
    const uint64_t texels = uint64_t(h.width) * h.height;
    const uint64_t probes = uint64_t(h.counts[0]) * h.counts[1] * h.counts[2];
    if (texels > (1ull << 28) || probes > (1ull << 24) || bytes.size() != sizeof h + texels * 4 + probes * 28 * 4)
        return std::nullopt;
    const uint8_t* p = bytes.data() + sizeof h;
    b.lightmap.resize(texels);
    std::memcpy(b.lightmap.data(), p, texels * 4);
    p += texels * 4;
    b.volume.sh.resize(probes);
    b.volume.validity.resize(probes);
    if (probes) {
        std::memcpy(b.volume.sh.data(), p, probes * 27 * 4);
        p += probes * 27 * 4;
        std::memcpy(b.volume.validity.data(), p, probes * 4);
    }
    return b;
}

BakeKey lightmapCacheKey(const scene::Scene& scene, const LightmapBakeSettings& s, uint64_t lightingHash) {
    scene::Hasher h;
    h.string("lightmap");
    h.value(kVersion);
    h.value(scene.lightmapHash()); // probes do not change the lightmaps
    h.value(lightingHash);
    h.value(s.atlas.texelsPerMeter);
    h.value(s.atlas.minSize);
    h.value(s.atlas.maxSize);
    h.value(s.atlas.gutter);
    h.value(s.atlas.atlasWidth);
    h.value(s.atlas.minChartGap);
    h.value(s.samples);
    h.value(s.maxBounces);
    h.value(s.probeSpacing);
    h.value(s.probeRays);
    h.value(s.maxProbes);
    h.value(s.filter.iterations);
    h.value(s.filter.positionSigma);
    h.value(s.filter.normalPower);
    h.value(s.filter.texelSize);
    h.value(s.sunScale);
    h.value(s.skyScale);
    h.value(s.emissiveScale);
    if (s.seed != 0) h.value(s.seed); // seed 0 keeps the key it had before the seed existed
    h.value(s.causticFootprint);
    if (s.multiscatter) h.string("multiscatter"); // off keeps the keys of before the setting
    return {"lightmap", h.result()};
}

} // namespace vitrine::bake
