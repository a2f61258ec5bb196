// render.pathtrace's CPU tracer (see pathtrace_cpu.hpp). The functions below mirror, in order and by name,
// shaders/pathtrace/sampling.glsl, shaders/scene/scene.glsl (evaluateLayers, texel pool), shaders/pathtrace/
// surface.glsl and shaders/render/pathtrace.comp; the BRDF is core/shading's, the CPU mirror of common/brdf.glsl.
#include "nodes/render/pathtrace_cpu.hpp"

#include "core/base/error.hpp"
#include "core/scene/closed_mesh.hpp"
#include "core/scene/deformation.hpp"
#include "core/scene/gpu_scene.hpp"
#include "core/shading/brdf.hpp"
#include "shaders/render/pathtrace.h"
#include "shaders/scene/scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <span>
#include <thread>

#include <time.h>

namespace vitrine {

using gpu_types::GpuLayer;
using gpu_types::GpuMaterial;
using gpu_types::GpuTexRef;
using glm::vec2;
using glm::vec3;
using glm::vec4;
using namespace shading;

void CpuAccumulation::reset(int w, int h) {
    width = w;
    height = h;
    color.assign(static_cast<size_t>(w) * h, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    stats.assign(static_cast<size_t>(w) * h, glm::vec4(0.0f));
}

bool cpuPathTracerAvailable() { return true; }

double processCpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

namespace {

constexpr float kInfinity = 3.4e38f;

float luminance(vec3 c) { return glm::dot(c, vec3(0.2126f, 0.7152f, 0.0722f)); }

// --- sampling.glsl ---
uint32_t pcgHash(uint32_t v) {
    uint32_t state = v * 747796405u + 2891336453u;
    uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}
uint32_t rngSeed(glm::uvec2 pixel, uint32_t frame, uint32_t sampleIndex) {
    return pcgHash(pixel.x ^ pcgHash(pixel.y ^ pcgHash(frame ^ pcgHash(sampleIndex))));
}
float rngNext(uint32_t& state) {
    state = state * 747796405u + 2891336453u;
    uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return static_cast<float>(((word >> 22u) ^ word) >> 8u) * (1.0f / 16777216.0f);
}
vec2 rngNext2(uint32_t& state) {
    float a = rngNext(state);
    return vec2(a, rngNext(state));
}

} // namespace

namespace cpu_sampling {

glm::mat3 basisAround(vec3 n) {
    float s = n.z >= 0.0f ? 1.0f : -1.0f;
    float a = -1.0f / (s + n.z);
    float b = n.x * n.y * a;
    vec3 t(1.0f + s * n.x * n.x * a, s * b, -s * n.x);
    vec3 bt(b, s + n.y * n.y * a, -n.y);
    return glm::mat3(t, bt, n);
}

vec3 sampleCosine(vec2 u) {
    float r = std::sqrt(u.x), phi = 2.0f * kPi * u.y;
    return vec3(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u.x)));
}

vec3 sampleGgxVndf(vec3 v, float alpha, vec2 u) {
    vec3 vh = glm::normalize(vec3(alpha * v.x, alpha * v.y, v.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = lensq > 0.0f ? vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lensq) : vec3(1.0f, 0.0f, 0.0f);
    vec3 t2 = glm::cross(vh, t1);
    float r = std::sqrt(u.x), phi = 2.0f * kPi * u.y;
    float p1 = r * std::cos(phi), p2 = r * std::sin(phi);
    float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
    return glm::normalize(vec3(alpha * nh.x, alpha * nh.y, std::max(0.0f, nh.z)));
}

float ggxVndfPdf(float NoV, float NoH, float alpha) {
    float a2 = alpha * alpha;
    return ggxD(NoH, alpha) / (2.0f * (NoV + std::sqrt(a2 + (1.0f - a2) * NoV * NoV)));
}

// --- volume.glsl ---
float ggxMaskingRatio(float NoV, float NoL, float alpha) {
    float a2 = alpha * alpha;
    float lv = std::sqrt(a2 + (1.0f - a2) * NoV * NoV), ll = std::sqrt(a2 + (1.0f - a2) * NoL * NoL);
    return NoL * (NoV + lv) / std::max(NoL * lv + NoV * ll, 1e-12f);
}

bool crossBoundary(vec3 n, vec3 ng, vec3 v, float roughness, vec4 dielectric, float eta, bool fresnel, vec3 u, vec3& l,
                   vec3& weight, bool& across) {
    float alpha = ggxAlpha(roughness);
    glm::mat3 frame = basisAround(n);
    vec3 h = frame * sampleGgxVndf(glm::transpose(frame) * v, alpha, vec2(u.y, u.z));
    float VoH = std::clamp(glm::dot(v, h), 0.0f, 1.0f);
    float sin2T = eta * eta * (1.0f - VoH * VoH);
    across = sin2T < 1.0f;
    weight = vec3(1.0f);
    if (across && fresnel) {
        vec3 F = schlickFresnelF90(vec3(dielectric), dielectric.a, eta < 1.0f ? VoH : std::sqrt(1.0f - sin2T));
        float p = std::clamp(luminance(F), 1e-3f, 1.0f - 1e-3f);
        across = u.x >= p;
        weight = across ? (vec3(1.0f) - F) / (1.0f - p) : F / p;
    }
    l = across ? glm::refract(-v, h, eta) : glm::reflect(-v, h);
    float side = glm::dot(ng, l);
    if (across ? side >= 0.0f : side <= 0.0f) return false;
    weight *= ggxMaskingRatio(std::clamp(glm::dot(n, v), 1e-4f, 1.0f), std::abs(glm::dot(n, l)), alpha);
    return true;
}

} // namespace cpu_sampling

namespace {

using namespace cpu_sampling;

vec3 sampleUniformSphere(vec2 u) {
    float z = 1.0f - 2.0f * u.x, r = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = 2.0f * kPi * u.y;
    return vec3(r * std::cos(phi), r * std::sin(phi), z);
}

// pathtrace/sampling.glsl: KHR_materials_clearcoat's lobe chosen first with coatProbability (0 without a coat).
struct BrdfLobes {
    vec3 baseColor;
    float metallic;
    float roughness;
    float specularProbability;
    float coatProbability = 0.0f;
    float coatRoughness = 0.0f;
    vec3 coatNormal{0.0f};
    float sheenProbability = 0.0f; // KHR_materials_sheen's cosine lobe, after the coat (0 without a sheen)
};

BrdfLobes brdfLobes(vec3 baseColor, float metallic, float roughness, glm::vec4 dielectric, float NoV) {
    BrdfLobes b;
    b.baseColor = baseColor;
    b.metallic = metallic;
    b.roughness = roughness;
    vec3 f0 = specularF0With(baseColor, metallic, 0.04f, dielectric);
    float s = luminance(schlickFresnelF90(f0, specularF90(metallic, dielectric), NoV));
    float d = luminance(diffuseAlbedo(baseColor, metallic));
    b.specularProbability = std::max(s / std::max(s + d, 1e-6f), 0.1f);
    return b;
}

void addClearcoatLobe(BrdfLobes& b, vec2 coat, vec3 nc, vec3 v) {
    b.coatNormal = nc;
    b.coatRoughness = coat.y;
    if (coat.x <= 0.0f) return;
    float NcoV = std::clamp(glm::dot(nc, v), 0.0f, 1.0f);
    float w = coat.x * clearcoatFresnel(NcoV);
    float base = luminance(schlickFresnel(specularF0(b.baseColor, b.metallic), NcoV)) +
                 luminance(diffuseAlbedo(b.baseColor, b.metallic));
    b.coatProbability = std::clamp(w / std::max(w + (1.0f - w) * base, 1e-6f), 0.05f, 0.95f);
}

void addSheenLobe(BrdfLobes& b, glm::vec4 sheen, float NoV) {
    if (!hasSheen(sheen)) return;
    float w = std::max(std::max(sheen.r, sheen.g), sheen.b) * sheenAlbedo(NoV, sheen.a);
    float base = luminance(schlickFresnel(specularF0(b.baseColor, b.metallic), NoV)) +
                 luminance(diffuseAlbedo(b.baseColor, b.metallic));
    b.sheenProbability = std::clamp(w / std::max(w + std::max(1.0f - w, 0.0f) * base, 1e-6f), 0.05f, 0.95f);
}

float baseBrdfPdf(const BrdfLobes& b, vec3 n, vec3 v, vec3 l) {
    float NoL = glm::dot(n, l), NoV = glm::dot(n, v);
    if (NoL <= 0.0f || NoV <= 0.0f) return 0.0f;
    vec3 h = glm::normalize(v + l);
    float spec = ggxVndfPdf(NoV, std::clamp(glm::dot(n, h), 0.0f, 1.0f), ggxAlpha(b.roughness));
    return b.specularProbability * spec + (1.0f - b.specularProbability) * NoL / kPi;
}

float sheenBrdfPdf(const BrdfLobes& b, vec3 n, vec3 v, vec3 l) {
    float base = baseBrdfPdf(b, n, v, l);
    if (b.sheenProbability <= 0.0f) return base;
    float NoL = glm::dot(n, l);
    float sheen = NoL > 0.0f && glm::dot(n, v) > 0.0f ? NoL / kPi : 0.0f;
    return b.sheenProbability * sheen + (1.0f - b.sheenProbability) * base;
}

float brdfPdf(const BrdfLobes& b, vec3 n, vec3 v, vec3 l) {
    float base = sheenBrdfPdf(b, n, v, l);
    if (b.coatProbability <= 0.0f) return base;
    const vec3 nc = b.coatNormal;
    float NcoL = glm::dot(nc, l), NcoV = glm::dot(nc, v), coat = 0.0f;
    if (NcoL > 0.0f && NcoV > 0.0f)
        coat = ggxVndfPdf(NcoV, std::clamp(glm::dot(nc, glm::normalize(v + l)), 0.0f, 1.0f), ggxAlpha(b.coatRoughness));
    return b.coatProbability * coat + (1.0f - b.coatProbability) * base;
}

bool sampleBrdf(const BrdfLobes& b, vec3 n, vec3 v, vec3 u, vec3& l) {
    if (b.coatProbability > 0.0f) {
        if (u.x < b.coatProbability) {
            glm::mat3 cf = basisAround(b.coatNormal);
            vec3 h = cf * sampleGgxVndf(glm::transpose(cf) * v, ggxAlpha(b.coatRoughness), vec2(u.y, u.z));
            l = glm::reflect(-v, h);
            return glm::dot(n, l) > 0.0f;
        }
        u.x = (u.x - b.coatProbability) / (1.0f - b.coatProbability);
    }
    glm::mat3 frame = basisAround(n);
    if (b.sheenProbability > 0.0f) {
        if (u.x < b.sheenProbability) {
            l = frame * sampleCosine(vec2(u.y, u.z));
            return glm::dot(n, l) > 0.0f;
        }
        u.x = (u.x - b.sheenProbability) / (1.0f - b.sheenProbability);
    }
    if (u.x < b.specularProbability) {
        vec3 vl = glm::transpose(frame) * v;
        vec3 h = frame * sampleGgxVndf(vl, ggxAlpha(b.roughness), vec2(u.y, u.z));
        l = glm::reflect(-v, h);
    } else {
        l = frame * sampleCosine(vec2(u.y, u.z));
    }
    return glm::dot(n, l) > 0.0f;
}

float powerHeuristic(float a, float b) {
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

// --- common/cubemap.glsl ---
vec3 cubeDirection(uint32_t face, vec2 uv) {
    switch (face) {
    case 0u: return vec3(1.0f, -uv.y, -uv.x);
    case 1u: return vec3(-1.0f, -uv.y, uv.x);
    case 2u: return vec3(uv.x, 1.0f, uv.y);
    case 3u: return vec3(uv.x, -1.0f, -uv.y);
    case 4u: return vec3(uv.x, -uv.y, 1.0f);
    default: return vec3(-uv.x, -uv.y, -1.0f);
    }
}

uint32_t cubeFace(vec3 d, vec2& uv) {
    vec3 a = glm::abs(d);
    if (a.x >= a.y && a.x >= a.z) {
        uv = d.x > 0.0f ? vec2(-d.z, -d.y) / a.x : vec2(d.z, -d.y) / a.x;
        return d.x > 0.0f ? 0u : 1u;
    }
    if (a.y >= a.z) {
        uv = d.y > 0.0f ? vec2(d.x, d.z) / a.y : vec2(d.x, -d.z) / a.y;
        return d.y > 0.0f ? 2u : 3u;
    }
    uv = d.z > 0.0f ? vec2(d.x, -d.y) / a.z : vec2(-d.x, -d.y) / a.z;
    return d.z > 0.0f ? 4u : 5u;
}

// --- the environment: sky cube map (bilinear at LOD 0 within a face, edges clamped) and sky.env_cdf ---
constexpr float kEnvUniform = 0.1f;

struct Env {
    const CpuSky* sky = nullptr;
    float scale = 1.0f;

    vec3 radiance(vec3 d) const {
        vec2 uv;
        uint32_t face = cubeFace(d, uv);
        const Image& img = sky->faces[face];
        float x = (uv.x * 0.5f + 0.5f) * static_cast<float>(img.width) - 0.5f;
        float y = (uv.y * 0.5f + 0.5f) * static_cast<float>(img.height) - 0.5f;
        int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
        float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
        auto at = [&](int tx, int ty) {
            const float* p = img.at(std::clamp(tx, 0, img.width - 1), std::clamp(ty, 0, img.height - 1));
            return vec3(p[0], p[1], p[2]);
        };
        vec3 top = glm::mix(at(x0, y0), at(x0 + 1, y0), fx), bottom = glm::mix(at(x0, y0 + 1), at(x0 + 1, y0 + 1), fx);
        return glm::mix(top, bottom, fy) * scale;
    }

    // sky.env_cdf's table, its red channel only (a quarter of the memory the binary searches walk).
    std::vector<float> cdfTable;
    int cdfWidth = 0;

    Env(const CpuSky& s, float skyScale) : sky(&s), scale(skyScale) {
        const Image& t = s.envCdf;
        if (t.empty()) return;
        cdfWidth = t.width;
        cdfTable.resize(static_cast<size_t>(t.width) * t.height);
        for (int y = 0; y < t.height; ++y)
            for (int x = 0; x < t.width; ++x) cdfTable[static_cast<size_t>(y) * t.width + x] = t.at(x, y)[0];
    }

    float cdf(int x, int row) const {
        return x < 0 || row < 0 ? 0.0f : cdfTable[static_cast<size_t>(row) * cdfWidth + x];
    }
    float total() const { return cdfTable.empty() ? 0.0f : cdf(0, 6 * sky->size); }

    float texelPdf(int x, int row, vec2 uv) const {
        int size = sky->size;
        float pRow = cdf(size, row) - cdf(size, row - 1);
        float pX = cdf(x, row) - cdf(x - 1, row);
        float texelArea = 4.0f / static_cast<float>(size * size);
        float r2 = 1.0f + glm::dot(uv, uv);
        return pRow * pX / texelArea * r2 * std::sqrt(r2);
    }

    float pdf(vec3 d) const {
        int size = sky->size;
        vec2 uv;
        uint32_t face = cubeFace(d, uv);
        glm::ivec2 t = glm::clamp(glm::ivec2((uv * 0.5f + 0.5f) * static_cast<float>(size)), glm::ivec2(0),
                                  glm::ivec2(size - 1));
        float p = texelPdf(t.x, static_cast<int>(face) * size + t.y, uv);
        return (1.0f - kEnvUniform) * p + kEnvUniform / (4.0f * kPi);
    }

    vec3 sample(vec3 u) const {
        if (u.x < kEnvUniform) return sampleUniformSphere(vec2(u.y, u.z));
        int size = sky->size;
        float ur = (u.x - kEnvUniform) / (1.0f - kEnvUniform);
        int lo = 0, hi = 6 * size - 1;
        while (lo < hi) {
            int mid = (lo + hi) / 2;
            if (cdf(size, mid) > ur) hi = mid;
            else lo = mid + 1;
        }
        int row = lo;
        float ux = u.y;
        lo = 0;
        hi = size - 1;
        while (lo < hi) {
            int mid = (lo + hi) / 2;
            if (cdf(mid, row) > ux) hi = mid;
            else lo = mid + 1;
        }
        float c0 = cdf(lo - 1, row), c1 = cdf(lo, row);
        float fx = c1 > c0 ? std::clamp((ux - c0) / (c1 - c0), 0.0f, 0.999999f) : 0.5f;
        vec2 uv = (vec2(static_cast<float>(lo) + fx, static_cast<float>(row % size) + u.z) * 2.0f) /
                      static_cast<float>(size) -
                  1.0f;
        return glm::normalize(cubeDirection(static_cast<uint32_t>(row / size), uv));
    }
};

// --- scene.glsl: texel pool and evaluateLayers ---
struct Materials {
    std::vector<GpuMaterial> materials;
    std::vector<GpuLayer> layers;
    TexelPool pool;

    int modulo(int i, int m) const {
        int t = i - m * static_cast<int>(std::floor(static_cast<float>(i) / static_cast<float>(m)));
        return t < 0 ? t + m : (t >= m ? t - m : t);
    }
    int wrap(int i, int size, uint32_t mode) const {
        if (mode == VITRINE_TEXEL_CLAMP) return std::clamp(i, 0, size - 1);
        if (mode == VITRINE_TEXEL_MIRROR) {
            int t = modulo(i, 2 * size);
            return t >= size ? 2 * size - 1 - t : t;
        }
        return modulo(i, size);
    }
    // 8-bit channel to float: linear (v / 255) and sRGB-decoded (the GLSL's formula, tabulated).
    struct Decode {
        std::array<float, 256> linear{}, srgb{};
        Decode() {
            for (int i = 0; i < 256; ++i) {
                float c = static_cast<float>(i) / 255.0f;
                linear[i] = c;
                srgb[i] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
            }
        }
    };
    vec4 fetch(const std::array<uint32_t, 4>& tex, int x, int y) const {
        static const Decode decode;
        uint32_t packed = pool.texels[tex[0] + static_cast<uint32_t>(y) * tex[1] + static_cast<uint32_t>(x)];
        const std::array<float, 256>& rgb = (tex[3] & VITRINE_TEXEL_SRGB) != 0u ? decode.srgb : decode.linear;
        return vec4(rgb[packed & 0xffu], rgb[(packed >> 8) & 0xffu], rgb[(packed >> 16) & 0xffu],
                    decode.linear[packed >> 24]);
    }
    vec4 sample(int index, vec2 uv) const {
        const auto& tex = pool.table[static_cast<size_t>(index)];
        glm::ivec2 size(static_cast<int>(tex[1]), static_cast<int>(tex[2]));
        uint32_t wrapU = (tex[3] >> VITRINE_TEXEL_WRAP_U_SHIFT) & 3u, wrapV = (tex[3] >> VITRINE_TEXEL_WRAP_V_SHIFT) & 3u;
        vec2 st = uv * vec2(size);
        if ((tex[3] & VITRINE_TEXEL_NEAREST) != 0u) {
            glm::ivec2 i(glm::floor(st));
            return fetch(tex, wrap(i.x, size.x, wrapU), wrap(i.y, size.y, wrapV));
        }
        st -= 0.5f;
        vec2 f = glm::fract(st);
        glm::ivec2 i0(glm::floor(st));
        int x0 = wrap(i0.x, size.x, wrapU), x1 = wrap(i0.x + 1, size.x, wrapU);
        int y0 = wrap(i0.y, size.y, wrapV), y1 = wrap(i0.y + 1, size.y, wrapV);
        vec4 top = glm::mix(fetch(tex, x0, y0), fetch(tex, x1, y0), f.x);
        vec4 bottom = glm::mix(fetch(tex, x0, y1), fetch(tex, x1, y1), f.x);
        return glm::mix(top, bottom, f.y);
    }
    static vec2 refUv(const GpuTexRef& r, vec2 uv0, vec2 uv1) {
        vec3 uv(r.info.y == 0 ? uv0 : uv1, 1.0f);
        return vec2(glm::dot(vec3(r.row0), uv), glm::dot(vec3(r.row1), uv));
    }
    vec4 sampleRef(const GpuTexRef& r, vec2 uv0, vec2 uv1) const {
        if (r.info.x < 0) return vec4(1.0f);
        return sample(r.info.x, refUv(r, uv0, uv1));
    }
    static float channelOf(vec4 t, int c) { return c == 0 ? t.r : c == 1 ? t.g : c == 2 ? t.b : t.a; }

    // Asks the memory system for the texels sample(index, uv) will read (the two rows of its bilinear footprint),
    // without waiting for them: the batched tracer calls this for every hit of a batch before shading any of them,
    // so their cache misses overlap instead of stalling one path at a time. Reads nothing; changes no result.
    void prefetch(int index, vec2 uv) const {
        const auto& tex = pool.table[static_cast<size_t>(index)];
        glm::ivec2 size(static_cast<int>(tex[1]), static_cast<int>(tex[2]));
        uint32_t wrapU = (tex[3] >> VITRINE_TEXEL_WRAP_U_SHIFT) & 3u, wrapV = (tex[3] >> VITRINE_TEXEL_WRAP_V_SHIFT) & 3u;
        vec2 st = uv * vec2(size);
        if ((tex[3] & VITRINE_TEXEL_NEAREST) == 0u) st -= 0.5f;
        if (!(std::abs(st.x) < 1e8f && std::abs(st.y) < 1e8f)) return;
        glm::ivec2 i0(glm::floor(st));
        int x0 = wrap(i0.x, size.x, wrapU), y0 = wrap(i0.y, size.y, wrapV), y1 = wrap(i0.y + 1, size.y, wrapV);
        const uint32_t* base = pool.texels.data() + tex[0] + static_cast<uint32_t>(x0);
        __builtin_prefetch(base + static_cast<uint32_t>(y0) * tex[1]);
        __builtin_prefetch(base + static_cast<uint32_t>(y1) * tex[1]);
    }
    void prefetchRef(const GpuTexRef& r, vec2 uv0, vec2 uv1) const {
        if (r.info.x >= 0) prefetch(r.info.x, refUv(r, uv0, uv1));
    }
    // Every texture evaluateLayers and pathSurface may read for material m. (Prefetching only those the layer bits
    // select measured slower, 2026-12-05: about 285 k against 340 k paths/s.)
    void prefetchMaterial(const GpuMaterial& m, vec2 uv0, vec2 uv1) const {
        for (uint32_t i = 0; i < m.info.y; ++i)
            for (const GpuTexRef& r : layers[m.info.x + i].refs) prefetchRef(r, uv0, uv1);
        for (const GpuTexRef* r : {&m.emissiveRef, &m.specularRef, &m.specularColorRef, &m.clearcoatRef,
                                   &m.clearcoatRoughnessRef, &m.clearcoatNormalRef, &m.sheenColorRef,
                                   &m.sheenRoughnessRef})
            prefetchRef(*r, uv0, uv1);
    }

    // scene.glsl materialClearcoat / materialClearcoatNormal: KHR_materials_clearcoat's strength and roughness, and
    // the coat's tangent-space normal.
    vec2 materialClearcoat(const GpuMaterial& m, vec2 uv0, vec2 uv1) const {
        vec2 c(m.clearcoat.x, m.clearcoat.y);
        if (m.clearcoatRef.info.x >= 0) c.x *= sampleRef(m.clearcoatRef, uv0, uv1).r;
        if (m.clearcoatRoughnessRef.info.x >= 0) c.y *= sampleRef(m.clearcoatRoughnessRef, uv0, uv1).g;
        return glm::clamp(c, 0.0f, 1.0f);
    }
    vec3 materialClearcoatNormal(const GpuMaterial& m, vec2 uv0, vec2 uv1) const {
        if (m.clearcoatNormalRef.info.x < 0) return vec3(0.0f, 0.0f, 1.0f);
        vec3 n = vec3(sampleRef(m.clearcoatNormalRef, uv0, uv1)) * 2.0f - 1.0f;
        n.x *= m.clearcoat.z;
        n.y *= m.clearcoat.z;
        return n;
    }

    // scene.glsl materialSheen: KHR_materials_sheen's colour (rgb) and roughness (a).
    glm::vec4 materialSheen(const GpuMaterial& m, vec2 uv0, vec2 uv1) const {
        glm::vec4 s = m.sheen;
        if (m.sheenColorRef.info.x >= 0) {
            glm::vec4 t = sampleRef(m.sheenColorRef, uv0, uv1);
            s.r *= t.r;
            s.g *= t.g;
            s.b *= t.b;
        }
        if (m.sheenRoughnessRef.info.x >= 0) s.a *= sampleRef(m.sheenRoughnessRef, uv0, uv1).a;
        return glm::clamp(s, 0.0f, 1.0f);
    }

    // scene.glsl materialThickness: KHR_materials_volume's thickness in the mesh's units (0: thin-walled).
    float materialThickness(const GpuMaterial& m, vec2 uv0, vec2 uv1) const {
        float t = m.optics.w;
        if (m.thicknessRef.info.x >= 0) t *= sampleRef(m.thicknessRef, uv0, uv1).g;
        return std::max(t, 0.0f);
    }

    // scene.glsl materialSpecular: KHR_materials_specular's colour (rgb) and strength (a).
    vec4 materialSpecular(const GpuMaterial& m, vec2 uv0, vec2 uv1) const {
        vec4 s = m.specular;
        if (m.specularRef.info.x >= 0) s.a *= sampleRef(m.specularRef, uv0, uv1).a;
        if (m.specularColorRef.info.x >= 0) {
            vec3 c = vec3(s) * vec3(sampleRef(m.specularColorRef, uv0, uv1));
            s = vec4(c, s.a);
        }
        return s;
    }

    struct LayeredSurface {
        vec4 albedo{1.0f};
        vec3 normal{0.0f, 0.0f, 1.0f};
        float shininess = 0.5f, metallic = 0.0f, cavity = 1.0f;
    };
    LayeredSurface evaluateLayers(const GpuMaterial& m, vec2 uv0, vec2 uv1) const {
        LayeredSurface s;
        uint32_t first = m.info.x, count = m.info.y;
        for (uint32_t i = 0; i < count; ++i) {
            const GpuLayer& l = layers[first + i];
            float w = 1.0f;
            if (i > 0) {
                const GpuTexRef& mr = l.refs[VITRINE_REF_MASK];
                float t = mr.info.x < 0 ? 1.0f : channelOf(sampleRef(mr, uv0, uv1), mr.info.z);
                w = std::clamp(l.scalars1.w * t, 0.0f, 1.0f);
            }
            uint32_t bits = l.bits.x;
            if ((bits & VITRINE_LAYER_ALBEDO) != 0u)
                s.albedo = glm::mix(s.albedo, l.albedo * sampleRef(l.refs[VITRINE_REF_ALBEDO], uv0, uv1), w);
            if ((bits & VITRINE_LAYER_NORMAL) != 0u) {
                vec3 n(0.0f, 0.0f, 1.0f);
                const GpuTexRef& nr = l.refs[VITRINE_REF_NORMAL];
                if (nr.info.x >= 0) {
                    n = vec3(sampleRef(nr, uv0, uv1)) * 2.0f - 1.0f;
                    n.x *= l.scalars0.x;
                    n.y *= l.scalars0.x;
                }
                s.normal = glm::mix(s.normal, n, w);
            }
            if ((bits & VITRINE_LAYER_SHININESS) != 0u) {
                const GpuTexRef& r = l.refs[VITRINE_REF_SHININESS];
                float t = r.info.x < 0 ? 1.0f : channelOf(sampleRef(r, uv0, uv1), r.info.z);
                s.shininess = glm::mix(s.shininess, glm::mix(l.scalars0.z, l.scalars0.y, t), w);
            }
            if ((bits & VITRINE_LAYER_METALLIC) != 0u) {
                const GpuTexRef& r = l.refs[VITRINE_REF_METALLIC];
                float t = r.info.x < 0 ? 1.0f : channelOf(sampleRef(r, uv0, uv1), r.info.z);
                s.metallic = glm::mix(s.metallic, glm::mix(l.scalars1.x, l.scalars0.w, t), w);
            }
            if ((bits & VITRINE_LAYER_CAVITY) != 0u) {
                const GpuTexRef& r = l.refs[VITRINE_REF_CAVITY];
                float t = r.info.x < 0 ? 1.0f : channelOf(sampleRef(r, uv0, uv1), r.info.z);
                s.cavity = glm::mix(s.cavity, glm::mix(l.scalars1.z, l.scalars1.y, t), w);
            }
        }
        return s;
    }
};

// Where an Embree triangle came from (the BVH's GpuBvhTriangleRef).
struct TriangleRef {
    uint32_t instance, primitive, triangle, material;
};

using PathSurface = CpuSurface;

// surface.glsl iorFromF0: the IOR of a dielectric whose F0 is ((ior - 1) / (ior + 1))^2 (GpuMaterial optics.y).
float iorFromF0(float f0) {
    const float r = std::sqrt(std::clamp(f0, 0.0f, 0.98f));
    return (1.0f + r) / (1.0f - r);
}

// shaders/pathtrace/media.glsl PathMedia: the KHR_materials_volume media a path is in, innermost (the last entered)
// last, at most kMaxMedia (PATHTRACE_MAX_MEDIA).
struct PathMedia {
    static constexpr uint32_t kMaxMedia = 4;
    uint32_t count = 0;
    std::array<uint32_t, kMaxMedia> material{};

    // media.glsl findMedium: where the media hold `m`, innermost first; -1 where the path is not in it.
    int find(uint32_t m) const {
        for (int i = static_cast<int>(count) - 1; i >= 0; --i)
            if (material[static_cast<size_t>(i)] == m) return i;
        return -1;
    }
    // media.glsl currentMedium: the innermost volume's attenuationColor and attenuationDistance (0: none, as air).
    vec4 current(std::span<const GpuMaterial> materials) const {
        return count > 0 ? materials[material[count - 1]].volume : vec4(1.0f, 1.0f, 1.0f, 0.0f);
    }
    // media.glsl meetBoundary: s.eta and s.dielectric from the IORs on s's two sides.
    void meet(PathSurface& s, std::span<const GpuMaterial> materials) const {
        const auto ior = [&](uint32_t i) { return iorFromF0(materials[material[i]].optics.y); };
        const float outer = count > 0 ? ior(count - 1) : 1.0f;
        float here = outer, there = s.ior;
        bool air = count == 0; // what lies beyond s's volume is no volume
        if (s.inside) {
            const int at = find(s.material);
            if (at < 0) { // the path started inside this volume
                here = s.ior;
                there = outer;
            } else if (at == static_cast<int>(count) - 1) { // out of the innermost volume into the one around it
                there = at > 0 ? ior(static_cast<uint32_t>(at - 1)) : 1.0f;
                air = at == 0;
            } else { // out of a volume overlapped by one entered later: the path stays in that one
                there = outer;
            }
        }
        s.eta = here / there;
        if (!air) { // F0 of the two media (against air, the material's own)
            const float r = (here - there) / (here + there);
            s.dielectric = dielectricSpecular(r * r, s.specular);
        }
    }
    // media.glsl crossMedia: the path met boundary s and crossed it (into its volume or out of it) or was reflected.
    void cross(const PathSurface& s, bool across) {
        const int at = find(s.material);
        if (across == s.inside) { // out of the volume, or reflected outside it
            if (!across || at < 0) return;
            for (uint32_t i = static_cast<uint32_t>(at); i + 1 < count; ++i)
                material[i] = material[i + 1];
            --count;
        } else if ((across || at < 0) && count < kMaxMedia) {
            material[count++] = s.material;
        }
    }
};

// Paths traced in lock step by CpuPathTracer::Impl::tracePaths: enough for their texture fetches' cache misses to
// overlap, few enough that a batch's state stays in the L1 cache.
constexpr size_t kPathBatch = 16;

vec3 offsetRay(vec3 p, vec3 ng, vec3 dir) {
    float scale = 1e-4f * (1.0f + std::max(std::max(std::abs(p.x), std::abs(p.y)), std::abs(p.z)));
    return p + ng * (glm::dot(ng, dir) >= 0.0f ? scale : -scale);
}

} // namespace

struct CpuPathTracer::Impl {
    const scene::Scene& scene;
    scene::ScenePose pose;            // as given
    bool deforms = false;             // scene::Deformation::any()
    std::vector<scene::Vertex> posed; // Scene::vertices with the deforming meshes posed (empty when none deforms)
    std::span<const scene::Vertex> vertices; // what the triangles and their shading read: posed or Scene::vertices
    std::vector<glm::mat4> world;
    std::vector<glm::mat3> normalMatrix;
    Materials materials;
    std::vector<TriangleRef> refs;
    std::vector<uint8_t> openVolume;       // per scene primitive: scene::openVolumePrimitives
    std::vector<glm::vec3> worldPositions; // 3 per triangle (the shading's geometric normal uses world positions)
    RTCDevice device = nullptr;
    RTCScene rtc = nullptr;
    RTCScene rtcOpaque = nullptr; // with `transparent`: the triangles no light passes

    Impl(const scene::Scene& s, const scene::ScenePose& p, bool transparent)
        : scene(s), pose(p), world(p.instanceWorld) {
        const scene::Deformation deformation(s);
        deforms = deformation.any();
        if (deforms) posed = deformation.posedVertices(p);
        vertices = deforms ? std::span<const scene::Vertex>(posed) : std::span<const scene::Vertex>(s.vertices);
        packMaterials(s, materials.materials, materials.layers);
        materials.pool = packTexelPool(s);
        openVolume = scene::openVolumePrimitives(s);
        device = rtcNewDevice("threads=1"); // our own threads call into it; its builder uses one
        if (!device) throw InternalError("render.pathtrace: Embree could not create a device");
        for (size_t i = 0; i < s.instances.size(); ++i) {
            const glm::mat4& w = i < world.size() ? world[i] : s.instances[i].world;
            if (i >= world.size()) world.push_back(w);
            normalMatrix.push_back(glm::transpose(glm::inverse(glm::mat3(w))));
            const scene::Mesh& mesh = s.meshes[s.instances[i].mesh];
            for (uint32_t p = mesh.firstPrimitive; p < mesh.firstPrimitive + mesh.primitiveCount; ++p) {
                const scene::Primitive& prim = s.primitives[p];
                // As the GPU BVH (core/accel/scene_bvh.cpp): transparent primitives are left out unless asked for.
                if (!transparent && s.materials[prim.material].transparent()) continue;
                for (uint32_t t = 0; t < prim.indexCount / 3; ++t) {
                    for (uint32_t k = 0; k < 3; ++k) {
                        const scene::Vertex& v = vertices[s.indices[prim.firstIndex + 3 * t + k] + prim.vertexOffset];
                        worldPositions.push_back(glm::vec3(w * glm::vec4(v.position, 1.0f)));
                    }
                    refs.push_back({static_cast<uint32_t>(i), p, t, prim.material});
                }
            }
        }
        rtc = newScene(worldPositions);
        if (transparent) {
            // The triangles that stop every shadow ray (neither masked nor transparent): a shadow ray that one of them
            // blocks needs no walk over the surfaces it would otherwise pass (shadowTransmittance).
            std::vector<glm::vec3> opaque;
            for (size_t t = 0; t < refs.size(); ++t) {
                const scene::Material& m = s.materials[refs[t].material];
                if (m.transparent() || m.alphaMode == scene::AlphaMode::Mask) continue;
                opaque.insert(opaque.end(), worldPositions.begin() + 3 * t, worldPositions.begin() + 3 * t + 3);
            }
            rtcOpaque = newScene(opaque);
        }
    }

    // An Embree scene of the triangles whose corners are positions[3 t + 0..2].
    RTCScene newScene(const std::vector<glm::vec3>& positions) const {
        RTCScene scene = rtcNewScene(device);
        rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
        rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
        RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        const size_t triangles = positions.size() / 3;
        float* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), std::max<size_t>(1, 3 * triangles)));
        uint32_t* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                     3 * sizeof(uint32_t), triangles));
        for (size_t i = 0; i < positions.size(); ++i) {
            vb[3 * i] = positions[i].x;
            vb[3 * i + 1] = positions[i].y;
            vb[3 * i + 2] = positions[i].z;
        }
        for (size_t i = 0; i < 3 * triangles; ++i) ib[i] = static_cast<uint32_t>(i);
        rtcCommitGeometry(geom);
        rtcAttachGeometry(scene, geom);
        rtcReleaseGeometry(geom);
        rtcCommitScene(scene);
        return scene;
    }

    ~Impl() {
        if (rtc) rtcReleaseScene(rtc);
        if (rtcOpaque) rtcReleaseScene(rtcOpaque);
        if (device) rtcReleaseDevice(device);
    }

    struct Hit {
        float t;
        vec2 barycentrics;
        uint32_t triangle;
    };

    bool closest(vec3 o, vec3 d, float tmin, Hit& hit, uint64_t& rays) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRayHit rh{};
        rh.ray.org_x = o.x;
        rh.ray.org_y = o.y;
        rh.ray.org_z = o.z;
        rh.ray.dir_x = d.x;
        rh.ray.dir_y = d.y;
        rh.ray.dir_z = d.z;
        rh.ray.tnear = tmin;
        rh.ray.tfar = kInfinity;
        rh.ray.mask = ~0u;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(rtc, &context, &rh);
        ++rays;
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
        hit.t = rh.ray.tfar;
        hit.barycentrics = vec2(rh.hit.u, rh.hit.v);
        hit.triangle = rh.hit.primID;
        return true;
    }

    bool occluded(vec3 o, vec3 d, uint64_t& rays, float tmax = kInfinity) const {
        return occludedIn(rtc, o, d, rays, tmax);
    }
    bool occludedIn(RTCScene scene, vec3 o, vec3 d, uint64_t& rays, float tmax = kInfinity) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRay r{};
        r.org_x = o.x;
        r.org_y = o.y;
        r.org_z = o.z;
        r.dir_x = d.x;
        r.dir_y = d.y;
        r.dir_z = d.z;
        r.tnear = 0.0f;
        r.tfar = tmax;
        r.mask = ~0u;
        rtcOccluded1(scene, &context, &r);
        ++rays;
        return r.tfar < 0.0f;
    }

    // pathtrace.comp's dielectricLayers: light t a thin-walled transmissive dielectric lets through, under its sheen
    // and coat.
    static vec3 dielectricLayers(const PathSurface& s, vec3 v, vec3 t) {
        float NoV = std::clamp(glm::dot(s.normal, v), 0.0f, 1.0f);
        if (hasSheen(s.sheen)) t *= sheenScaling(vec3(s.sheen), NoV, s.sheen.a);
        return clearcoatLayer(t, s.coat.x, glm::dot(s.coatNormal, v), vec3(0.0f));
    }

    // pathtrace.comp's dielectricThrough: what a transmissive dielectric lets pass (a thin wall straight on, a
    // volume's boundary refracted).
    static vec3 dielectricThrough(const PathSurface& s, vec3 v) {
        float NoV = std::clamp(glm::dot(s.normal, v), 0.0f, 1.0f);
        vec3 t =
            (vec3(1.0f) - schlickFresnelF90(vec3(s.dielectric), s.dielectric.a, NoV)) * s.baseColor * s.attenuation;
        return dielectricLayers(s, v, t);
    }

    // pathtrace.comp's pathPassing: what passes s on a shadow ray (0 for an opaque surface, and for a volume's boundary
    // unless throughVolumes; from inside a volume, 1 - F(n.v)).
    static vec3 pathPassing(const PathSurface& s, vec3 v, bool throughVolumes) {
        if (s.boundary && !throughVolumes) return vec3(0.0f);
        if (s.inside)
            return vec3(1.0f) -
                   schlickFresnelF90(vec3(s.dielectric), s.dielectric.a, std::clamp(glm::dot(s.normal, v), 0.0f, 1.0f));
        vec3 through =
            s.transmission > 0.0f ? s.transmission * (1.0f - s.metallic) * dielectricThrough(s, v) : vec3(0.0f);
        return vec3(1.0f - s.coverage) + s.coverage * through;
    }

    // pathtrace.comp's shadowTransmittance: 0 behind anything opaque, 1 with nothing in the way; with seeThrough the
    // product of pathPassing over every surface crossed (at most PATHTRACE_MAX_PASSES), a volume's boundary stopping
    // the ray unless throughVolumes (the sun's rays); Beer's law over each segment in the media it is in (from the
    // path's `media`).
    vec3 shadowTransmittance(vec3 o, vec3 d, bool seeThrough, bool throughVolumes, PathMedia media,
                             uint64_t& rays) const {
        if (!seeThrough) return occluded(o, d, rays) ? vec3(0.0f) : vec3(1.0f);
        // First against what no light passes (the GPU tracer walks the surfaces only: one BVH there); then every hit
        // left is one to pass.
        if (rtcOpaque && occludedIn(rtcOpaque, o, d, rays)) return vec3(0.0f);
        vec3 T(1.0f);
        float tmin = 0.0f, last = 0.0f; // last: where the ray met the last surface
        for (uint32_t i = 0; i < PATHTRACE_MAX_PASSES; ++i) {
            Hit hit;
            if (!closest(o, d, tmin, hit, rays)) return T;
            const vec4 medium = media.current(materials.materials);
            if (medium.a > 0.0f) T *= glm::pow(vec3(medium), vec3((hit.t - last) / medium.a));
            PathSurface s = pathSurface(hit, o, d);
            if (s.boundary && throughVolumes) {
                media.meet(s, materials.materials);
                media.cross(s, true);
            }
            T *= pathPassing(s, -d, throughVolumes);
            if (std::max(std::max(T.r, T.g), T.b) <= 0.0f) return vec3(0.0f);
            last = hit.t;
            tmin = std::nextafter(hit.t, kInfinity); // Embree's tnear is inclusive, the GLSL test strict
        }
        return vec3(0.0f);
    }

    // pathtrace.comp's sunThroughTransmission: the sun behind a thin-walled transmissive dielectric, scattered towards
    // v through its transmission lobe (core/shading thinTransmissionCosine), tinted, shadowed from the far side.
    vec3 sunThroughTransmission(const PathSurface& s, vec3 v, vec3 sunDir, vec3 sunE, bool seeThrough,
                                const PathMedia& media, uint64_t& rays) const {
        if (s.boundary || glm::dot(s.geometricNormal, sunDir) >= 0.0f) return vec3(0.0f);
        vec3 f = thinTransmissionCosine(s.normal, v, sunDir, vec3(s.dielectric), s.dielectric.a, s.roughness);
        if (f.x <= 0.0f && f.y <= 0.0f && f.z <= 0.0f) return vec3(0.0f);
        vec3 t = dielectricLayers(s, v, s.baseColor * s.attenuation * f);
        return t * sunE *
               shadowTransmittance(offsetRay(s.position, s.geometricNormal, sunDir), sunDir, seeThrough, true, media,
                                   rays);
    }

    // pathtrace.comp's drawTransmission: one component of KHR_materials_transmission's mixture; true when the path
    // passes (throughput scaled), else s is the drawn component's reflecting surface.
    static bool drawTransmission(PathSurface& s, vec3 v, vec3& throughput, uint32_t& rng) {
        float u = rngNext(rng), metallic = s.metallic;
        s.metallic = u < metallic ? 1.0f : 0.0f;
        if (u < metallic + (1.0f - metallic) * (1.0f - s.transmission)) return false;
        vec3 through = dielectricThrough(s, v);
        float reflected = luminance(
            schlickFresnelF90(vec3(s.dielectric), s.dielectric.a, std::clamp(glm::dot(s.normal, v), 0.0f, 1.0f)));
        float pass = std::clamp(luminance(through) / std::max(luminance(through) + reflected, 1e-6f), 0.05f, 0.95f);
        if (rngNext(rng) < pass) {
            throughput *= through / pass;
            return true;
        }
        throughput /= 1.0f - pass;
        s.baseColor = vec3(0.0f);
        return false;
    }

    // surface.glsl's materialBoundsVolume.
    static bool materialBoundsVolume(const GpuMaterial& m) { return m.optics.x > 0.0f && m.optics.w > 0.0f; }
    // surface.glsl's boundsVolume: the material bounds a volume and the primitive's faces of it are closed.
    bool boundsVolume(const GpuMaterial& m, uint32_t primitive) const {
        return materialBoundsVolume(m) && !openVolume[primitive];
    }

    // pathCulled: the back of a single-sided material's triangle, which the rasteriser culls (never a volume's).
    bool culled(const Hit& hit, vec3 direction) const {
        const TriangleRef& ref = refs[hit.triangle];
        const GpuMaterial& m = materials.materials[ref.material];
        if (m.info.w != 0u || boundsVolume(m, ref.primitive)) return false;
        const vec3* p = &worldPositions[3 * static_cast<size_t>(hit.triangle)];
        return glm::dot(glm::cross(p[1] - p[0], p[2] - p[0]), direction) > 0.0f;
    }

    bool traceVisible(vec3 origin, vec3 dir, Hit& hit, uint64_t& rays) const {
        float tmin = 0.0f;
        for (int skip = 0; skip < 4; ++skip) {
            if (!closest(origin, dir, tmin, hit, rays)) return false;
            if (!culled(hit, dir)) return true;
            // Past the culled triangle (Embree's tnear is inclusive, the GLSL test is strict).
            tmin = std::nextafter(hit.t, kInfinity);
        }
        return false;
    }

    // The hit triangle's three indices, and its three vertices (object space).
    const uint32_t* triangleIndices(const Hit& hit) const {
        const TriangleRef& ref = refs[hit.triangle];
        return &scene.indices[scene.primitives[ref.primitive].firstIndex + 3 * ref.triangle];
    }
    std::array<const scene::Vertex*, 3> triangleVertices(const Hit& hit) const {
        const uint32_t* idx = triangleIndices(hit);
        const uint32_t offset = scene.primitives[refs[hit.triangle].primitive].vertexOffset;
        return {&vertices[idx[0] + offset], &vertices[idx[1] + offset], &vertices[idx[2] + offset]};
    }
    void prefetchIndices(const Hit& hit) const { __builtin_prefetch(triangleIndices(hit)); }
    void prefetchVertices(const Hit& hit) const {
        for (const scene::Vertex* vertex : triangleVertices(hit)) {
            const char* v = reinterpret_cast<const char*>(vertex);
            __builtin_prefetch(v); // a vertex may straddle two cache lines
            __builtin_prefetch(v + sizeof(scene::Vertex) - 1);
        }
    }

    // The texels pathSurface(hit, ...) will read, requested ahead (Materials::prefetch).
    void prefetchSurface(const Hit& hit) const {
        const TriangleRef& ref = refs[hit.triangle];
        const auto [v0, v1, v2] = triangleVertices(hit);
        vec3 bary(1.0f - hit.barycentrics.x - hit.barycentrics.y, hit.barycentrics.x, hit.barycentrics.y);
        vec2 uv0 = bary.x * v0->uv0 + bary.y * v1->uv0 + bary.z * v2->uv0;
        vec2 uv1 = bary.x * v0->uv1 + bary.y * v1->uv1 + bary.z * v2->uv1;
        materials.prefetchMaterial(materials.materials[ref.material], uv0, uv1);
    }

    PathSurface pathSurface(const Hit& hit, vec3 origin, vec3 direction) const {
        const TriangleRef& ref = refs[hit.triangle];
        const auto [pv0, pv1, pv2] = triangleVertices(hit);
        const scene::Vertex &v0 = *pv0, &v1 = *pv1, &v2 = *pv2;
        vec3 bary(1.0f - hit.barycentrics.x - hit.barycentrics.y, hit.barycentrics.x, hit.barycentrics.y);
        const glm::mat3 w(world[ref.instance]);
        const glm::mat3& normalM = normalMatrix[ref.instance];

        PathSurface s;
        s.t = hit.t;
        s.position = origin + hit.t * direction;
        vec3 ng = glm::normalize(normalM * glm::cross(v1.position - v0.position, v2.position - v0.position));
        bool backFace = glm::dot(ng, direction) > 0.0f;
        if (backFace) ng = -ng;
        s.geometricNormal = ng;

        vec3 n = normalM * (bary.x * v0.normal + bary.y * v1.normal + bary.z * v2.normal);
        vec4 tangent = bary.x * v0.tangent + bary.y * v1.tangent + bary.z * v2.tangent;
        vec2 uv0 = bary.x * v0.uv0 + bary.y * v1.uv0 + bary.z * v2.uv0;
        vec2 uv1 = bary.x * v0.uv1 + bary.y * v1.uv1 + bary.z * v2.uv1;
        vec4 color = bary.x * v0.color + bary.y * v1.color + bary.z * v2.color;

        const GpuMaterial& m = materials.materials[ref.material];
        Materials::LayeredSurface l = materials.evaluateLayers(m, uv0, uv1);

        n = glm::dot(n, n) > 1e-20f ? glm::normalize(n) : ng;
        vec3 t = w * vec3(tangent);
        t = t - n * glm::dot(n, t);
        t = glm::dot(t, t) > 1e-12f ? glm::normalize(t) : vec3(1.0f, 0.0f, 0.0f);
        vec3 b = glm::cross(n, t) * (tangent.w < 0.0f ? -1.0f : 1.0f);
        float len = glm::length(l.normal);
        vec3 nts = len > 1e-6f ? l.normal / len : vec3(0.0f, 0.0f, 1.0f);
        vec3 N = glm::normalize(t * nts.x + b * nts.y + n * nts.z);
        if (backFace) N = -N;
        float NoV = glm::dot(N, -direction);
        if (NoV < 0.01f) N = glm::normalize(N - direction * (0.01f - NoV));
        s.normal = N;
        s.coat = m.optics.z > 0.5f ? vec2(0.0f) : materials.materialClearcoat(m, uv0, uv1);
        s.coatNormal = N;
        s.sheen = m.optics.z > 0.5f ? glm::vec4(0.0f) : materials.materialSheen(m, uv0, uv1);
        if (s.coat.x > 0.0f) { // the same frame about the coat's own tangent-space normal
            vec3 c = materials.materialClearcoatNormal(m, uv0, uv1);
            vec3 cts = glm::length(c) > 1e-6f ? glm::normalize(c) : vec3(0.0f, 0.0f, 1.0f);
            vec3 C = glm::normalize(t * cts.x + b * cts.y + n * cts.z);
            if (backFace) C = -C;
            float CoV = glm::dot(C, -direction);
            if (CoV < 0.01f) C = glm::normalize(C - direction * (0.01f - CoV));
            s.coatNormal = C;
        }

        s.baseColor = vec3(l.albedo) * vec3(color);
        s.metallic = std::clamp(l.metallic, 0.0f, 1.0f);
        s.roughness = roughnessFromShininess(std::clamp(l.shininess, 0.0f, 1.0f));
        s.cavity = std::clamp(l.cavity, 0.0f, 1.0f);
        s.specular = materials.materialSpecular(m, uv0, uv1);
        s.dielectric = dielectricSpecular(0.04f, s.specular);
        // surface.glsl's PATHTRACE_SEE_THROUGH_SURFACE part: coverage, transmission and the volume's boundary.
        s.coverage = m.info.z == 1u   ? (l.albedo.a < m.emissive.a ? 0.0f : 1.0f)
                     : m.info.z == 2u ? std::clamp(l.albedo.a, 0.0f, 1.0f)
                                      : 1.0f;
        s.transmission = m.optics.x;
        s.boundary = boundsVolume(m, ref.primitive);
        s.inside = s.boundary && backFace;
        s.ior = iorFromF0(m.optics.y);
        s.material = ref.material;
        s.eta = s.inside ? s.ior : 1.0f / s.ior;
        if (materialBoundsVolume(m) && !s.boundary && m.volume.a > 0.0f) { // faces that bound nothing: thin-walled
            const vec3 modelScale(glm::length(w[0]), glm::length(w[1]), glm::length(w[2]));
            const vec3 crossing = glm::normalize(glm::refract(direction, N, 1.0f / s.ior)) *
                                  materials.materialThickness(m, uv0, uv1) * modelScale;
            s.attenuation = glm::pow(vec3(m.volume), vec3(glm::length(crossing) / m.volume.a));
        }
        if (s.transmission > 0.0f) s.dielectric = dielectricSpecular(m.optics.y, s.specular);
        s.emissive = vec3(m.emissive);
        if (m.emissiveRef.info.x >= 0) s.emissive *= vec3(materials.sampleRef(m.emissiveRef, uv0, uv1));
        if (m.optics.z > 0.5f) {
            s.emissive = s.baseColor;
            s.baseColor = vec3(0.0f);
            s.metallic = 0.0f;
            s.cavity = 0.0f;
        }
        return s;
    }

    // A path in flight: where it goes next and what it has gathered (pathtrace.comp's tracePath locals).
    struct PathState {
        vec3 origin{0.0f}, dir{0.0f};
        vec3 radiance{0.0f}, throughput{1.0f};
        float brdfPdfPrev = 0.0f; // 0: a camera ray, or after a volume's boundary (what is found counts in full)
        uint32_t rng = 0, bounce = 0;
        uint32_t passes = 0;   // surfaces passed through (seeThrough; not bounces)
        PathMedia media;       // the volumes the path is in
        bool ended = false;  // passed through more than PATHTRACE_MAX_PASSES
        Hit hit{};
    };
    struct PathLights {
        bool envSampling = false, sun = false;
        vec3 sunE{0.0f}, sunDir{0.0f, 0.0f, 1.0f};
    };
    static PathLights pathLights(const CpuTraceSettings& st, const Env& env) {
        PathLights l;
        l.envSampling = st.envSampling && st.skyScale > 0.0f && env.total() > 0.0f;
        l.sunE = env.sky->sunIlluminance * st.sunScale;
        l.sunDir = glm::normalize(env.sky->sunDirection);
        l.sun = l.sunE.x > 0.0f || l.sunE.y > 0.0f || l.sunE.z > 0.0f;
        return l;
    }

    // pathtrace.comp's fromDenserSide: a path meets boundary s from inside its volume, or enters it from a denser
    // medium; the crossing's Fresnel is drawn at the microfacet there.
    static bool fromDenserSide(const PathSurface& s) { return s.inside || s.eta > 1.0f; }

    // pathtrace.comp's throughBoundary: the path through a volume's boundary s (met by PathMedia::meet; across it or
    // back by Fresnel from its denser side, else into it); false where the microfacet drawn sends it nowhere.
    static bool throughBoundary(PathState& p, const PathSurface& s) {
        vec3 l, w;
        bool across;
        const float a = rngNext(p.rng);
        const vec2 bc = rngNext2(p.rng);
        if (!crossBoundary(s.normal, s.geometricNormal, -p.dir, s.roughness, s.dielectric, s.eta, fromDenserSide(s),
                           vec3(a, bc), l, w, across))
            return false;
        p.throughput *= w;
        p.media.cross(s, across);
        p.dir = l;
        return true;
    }

    // pathtrace.comp's tracePath at a surface found along p.dir: alpha coverage, then (where covered) the emission and
    // the transmission's component. True when the path passes through it (p moved past it, not a bounce); false when
    // s reflects (p.radiance has its emission) or the path ends (p.passes over the limit).
    bool passSurface(PathState& p, PathSurface& s, const CpuTraceSettings& st, const PathLights& lights,
                     uint64_t& rays) const {
        // Beer's law over the way inside a volume.
        const vec4 medium = p.media.current(materials.materials);
        if (medium.a > 0.0f) p.throughput *= glm::pow(vec3(medium), vec3(s.t / medium.a));
        if (st.seeThrough && s.boundary) p.media.meet(s, materials.materials); // the IORs on its two sides
        // A boundary from its denser side: across it by Fresnel, or back.
        if (st.seeThrough && s.boundary && fromDenserSide(s)) {
            if (++p.passes > PATHTRACE_MAX_PASSES || !throughBoundary(p, s)) {
                p.ended = true;
                return false;
            }
            p.brdfPdfPrev = 0.0f;
            p.origin = offsetRay(s.position, s.geometricNormal, p.dir);
            return true;
        }
        bool pass = st.seeThrough && s.coverage < 1.0f && rngNext(p.rng) >= s.coverage;
        bool refracts = false; // passes into a volume
        if (!pass) {
            p.radiance += p.throughput * s.emissive * st.emissiveScale;
            if (st.seeThrough && s.transmission > 0.0f) {
                // The transmissive component's share, whichever component drawTransmission then draws.
                if (lights.sun)
                    p.radiance +=
                        p.throughput * (s.transmission * (1.0f - s.metallic)) *
                        sunThroughTransmission(s, -p.dir, lights.sunDir, lights.sunE, st.seeThrough, p.media, rays);
                pass = drawTransmission(s, -p.dir, p.throughput, p.rng);
                refracts = pass && s.boundary;
            }
        }
        if (!pass) return false;
        if (++p.passes > PATHTRACE_MAX_PASSES) {
            p.ended = true;
            return false;
        }
        if (refracts) { // into the volume, through one of the boundary's microfacets
            if (!throughBoundary(p, s)) {
                p.ended = true;
                return false;
            }
            p.brdfPdfPrev = 0.0f;
        }
        p.origin = offsetRay(s.position, s.geometricNormal, p.dir);
        return true;
    }

    // The path left the scene: the sky it sees, MIS-weighted against the sky's own sampling after a bounce (nothing
    // from inside an absorbing volume: an open mesh).
    void addMiss(PathState& p, const Env& env, const PathLights& lights) const {
        if (p.media.current(materials.materials).a > 0.0f) return;
        float w = p.brdfPdfPrev <= 0.0f || !lights.envSampling ? 1.0f : powerHeuristic(p.brdfPdfPrev, env.pdf(p.dir));
        p.radiance += p.throughput * env.radiance(p.dir) * w;
    }

    // tracePath's work at surface s (its emission already added): next-event estimation to the sun and the sky,
    // then the next direction from the BRDF and Russian roulette. False when the path ends here.
    bool shadeVertex(PathState& p, const PathSurface& s, const CpuTraceSettings& st, const Env& env,
                     const PathLights& lights, uint64_t& rays) const {
        if (p.bounce >= st.maxBounces) return false;

        vec3 v = -p.dir, n = s.normal, ng = s.geometricNormal;
        BrdfLobes lobes =
            brdfLobes(s.baseColor, s.metallic, s.roughness, s.dielectric, std::clamp(glm::dot(n, v), 0.0f, 1.0f));
        addClearcoatLobe(lobes, s.coat, s.coatNormal, v);
        addSheenLobe(lobes, s.sheen, std::clamp(glm::dot(n, v), 0.0f, 1.0f));
        vec3 weight = p.throughput * s.cavity;

        if (lights.sun && glm::dot(ng, lights.sunDir) > 0.0f) {
            // The bake widens the lobes the sun is reflected by (regularizedRoughness); s.t: from the last vertex.
            const float roughness = regularizedRoughness(s.roughness, st.causticFootprint, s.t);
            const vec2 coat(s.coat.x, regularizedRoughness(s.coat.y, st.causticFootprint, s.t));
            vec3 f = brdfCosineSheen(n, s.coatNormal, v, lights.sunDir, s.baseColor, s.metallic, roughness,
                                     s.dielectric, coat, s.sheen, st.multiscatter);
            if (f.x > 0.0f || f.y > 0.0f || f.z > 0.0f)
                p.radiance += weight * f * lights.sunE *
                              shadowTransmittance(offsetRay(s.position, ng, lights.sunDir), lights.sunDir,
                                                  st.seeThrough, true, p.media, rays);
        }
        if (lights.envSampling) {
            float a = rngNext(p.rng);
            vec2 bc = rngNext2(p.rng);
            vec3 l = env.sample(vec3(a, bc));
            float pdf = env.pdf(l);
            if (glm::dot(ng, l) > 0.0f && pdf > 0.0f) {
                vec3 f = brdfCosineSheen(n, s.coatNormal, v, l, s.baseColor, s.metallic, s.roughness, s.dielectric,
                                         s.coat, s.sheen, st.multiscatter);
                if (f.x > 0.0f || f.y > 0.0f || f.z > 0.0f)
                    p.radiance +=
                        weight * f * env.radiance(l) *
                        shadowTransmittance(offsetRay(s.position, ng, l), l, st.seeThrough, false, p.media, rays) *
                        powerHeuristic(pdf, brdfPdf(lobes, n, v, l)) / pdf;
            }
        }

        vec3 l;
        float a = rngNext(p.rng);
        vec2 bc = rngNext2(p.rng);
        if (!sampleBrdf(lobes, n, v, vec3(a, bc), l) || glm::dot(ng, l) <= 0.0f) return false;
        float pdf = brdfPdf(lobes, n, v, l);
        if (pdf <= 0.0f) return false;
        p.throughput = weight *
                       brdfCosineSheen(n, s.coatNormal, v, l, s.baseColor, s.metallic, s.roughness, s.dielectric,
                                       s.coat, s.sheen, st.multiscatter) /
                       pdf;
        p.brdfPdfPrev = pdf;
        if (p.bounce >= 2u) {
            float q = std::min(std::max(std::max(p.throughput.r, p.throughput.g), p.throughput.b), 0.95f);
            if (rngNext(p.rng) >= q) return false;
            p.throughput /= q;
        }
        p.origin = offsetRay(s.position, ng, l);
        p.dir = l;
        return true;
    }

    // pathtrace.comp's tracePath, line for line.
    vec3 tracePath(vec3 origin, vec3 dir, uint32_t& rng, const CpuTraceSettings& st, const Env& env,
                   uint64_t& rays) const {
        return continuePath(origin, dir, rng, st, env, rays, nullptr, true);
    }

    // tracePath, optionally from a first surface already found along dir (the ray-traced twins' queries); without
    // firstEmission that surface's emission is left out.
    vec3 continuePath(vec3 origin, vec3 dir, uint32_t& rng, const CpuTraceSettings& st, const Env& env,
                      uint64_t& rays, const PathSurface* first, bool firstEmission) const {
        const PathLights lights = pathLights(st, env);
        PathState p;
        p.origin = origin;
        p.dir = dir;
        p.rng = rng;
        for (;; ++p.bounce) {
            PathSurface s;
            if (p.bounce == 0u && first) {
                s = *first;
                if (firstEmission) p.radiance += p.throughput * s.emissive * st.emissiveScale;
            } else {
                if (!traceVisible(p.origin, p.dir, p.hit, rays)) {
                    addMiss(p, env, lights);
                    break;
                }
                s = pathSurface(p.hit, p.origin, p.dir);
                if (passSurface(p, s, st, lights, rays)) {
                    --p.bounce; // passing is not a bounce (the loop's ++ gives it back)
                    continue;
                }
                if (p.ended) break;
            }
            if (!shadeVertex(p, s, st, env, lights, rays)) break;
        }
        rng = p.rng;
        return p.radiance;
    }

    // tracePath for a batch of paths in lock step, bounce by bounce: every live path's ray is traced, then every hit's
    // texels are requested (prefetchSurface), then every hit is shaded. Each path computes exactly what tracePath
    // computes (its own random numbers, the same operations in the same order); only the order among paths changes,
    // so the texture fetches' cache misses of a batch overlap instead of stalling each path in turn.
    void tracePaths(std::span<PathState> paths, const CpuTraceSettings& st, const Env& env, uint64_t& rays) const {
        const PathLights lights = pathLights(st, env);
        std::array<uint32_t, kPathBatch> live{};
        size_t alive = std::min(paths.size(), live.size());
        for (size_t k = 0; k < alive; ++k) live[k] = static_cast<uint32_t>(k);
        while (alive > 0) {
            size_t kept = 0;
            for (size_t a = 0; a < alive; ++a) {
                PathState& p = paths[live[a]];
                if (traceVisible(p.origin, p.dir, p.hit, rays)) live[kept++] = live[a];
                else addMiss(p, env, lights);
            }
            alive = kept;
            // Each hit's data is a chain of dependent loads (triangle record, indices, vertices, texels): one
            // link per pass over the batch, so each pass's misses overlap.
            for (size_t a = 0; a < alive; ++a) __builtin_prefetch(&refs[paths[live[a]].hit.triangle]);
            for (size_t a = 0; a < alive; ++a) prefetchIndices(paths[live[a]].hit);
            for (size_t a = 0; a < alive; ++a) prefetchVertices(paths[live[a]].hit);
            for (size_t a = 0; a < alive; ++a) prefetchSurface(paths[live[a]].hit);
            kept = 0;
            for (size_t a = 0; a < alive; ++a) {
                PathState& p = paths[live[a]];
                PathSurface s = pathSurface(p.hit, p.origin, p.dir);
                if (passSurface(p, s, st, lights, rays)) { // on through it, the same bounce
                    live[kept++] = live[a];
                    continue;
                }
                if (p.ended || !shadeVertex(p, s, st, env, lights, rays)) continue;
                ++p.bounce;
                live[kept++] = live[a];
            }
            alive = kept;
        }
    }

    // The primary ray through (x, y) + jitter: from the camera (perspective) or the near plane (orthographic).
    static void cameraRay(const CpuTraceSettings& st, int x, int y, vec2 jitter, vec3& origin, vec3& dir) {
        vec2 ndc = (vec2(static_cast<float>(x), static_cast<float>(y)) + jitter) /
                       vec2(static_cast<float>(st.width), static_cast<float>(st.height)) * 2.0f -
                   1.0f;
        vec4 nearH = st.invViewProj * vec4(ndc, 1.0f, 1.0f);
        vec4 farH = st.invViewProj * vec4(ndc, 0.5f, 1.0f);
        dir = glm::normalize(vec3(farH) / farH.w - vec3(nearH) / nearH.w);
        origin = st.orthographic ? vec3(nearH) / nearH.w : st.cameraPos;
    }

    // pathtrace.comp's main for one row: this batch's samples, merged into the accumulation (Chan et al.). The row's
    // paths (pixel by pixel, sample by sample) are traced kPathBatch at a time by tracePaths.
    void traceRow(int y, const CpuTraceSettings& st, const Env& env, CpuAccumulation& acc, uint64_t& rays) const {
        const size_t spp = st.spp, n = static_cast<size_t>(st.width) * spp;
        thread_local std::vector<vec3> radiance;
        radiance.resize(n);
        std::array<PathState, kPathBatch> batch;
        for (size_t begin = 0; begin < n; begin += kPathBatch) {
            const size_t count = std::min(kPathBatch, n - begin);
            for (size_t k = 0; k < count; ++k) {
                const int x = static_cast<int>((begin + k) / spp);
                const uint32_t i = static_cast<uint32_t>((begin + k) % spp);
                PathState& p = batch[k];
                p = PathState{};
                p.rng = rngSeed(glm::uvec2(x, y), st.seed, i);
                vec2 jitter = st.antialias ? rngNext2(p.rng) : vec2(0.5f);
                cameraRay(st, x, y, jitter, p.origin, p.dir);
            }
            tracePaths(std::span<PathState>(batch.data(), count), st, env, rays);
            for (size_t k = 0; k < count; ++k) radiance[begin + k] = batch[k].radiance;
        }
        accumulateRow(y, st, acc, [&](int x, uint32_t i) { return radiance[static_cast<size_t>(x) * spp + i]; });
    }

    // One row of any per-pixel estimator `sample(x, rng)`, merged into the accumulation (Chan et al.).
    template <class Sample>
    void estimateRow(int y, const CpuTraceSettings& st, CpuAccumulation& acc, const Sample& sample) const {
        accumulateRow(y, st, acc, [&](int x, uint32_t i) {
            uint32_t rng = rngSeed(glm::uvec2(x, y), st.seed, i);
            return sample(x, rng);
        });
    }

    // Merges one row's samples `sampleAt(x, i)` (i < spp, taken in that order) into the accumulation.
    template <class SampleAt>
    void accumulateRow(int y, const CpuTraceSettings& st, CpuAccumulation& acc, const SampleAt& sampleAt) const {
        for (int x = 0; x < st.width; ++x) {
            vec3 sum(0.0f);
            float mean = 0.0f, m2 = 0.0f;
            for (uint32_t i = 0; i < st.spp; ++i) {
                vec3 L = sampleAt(x, i);
                if (!std::isfinite(L.x) || !std::isfinite(L.y) || !std::isfinite(L.z)) L = vec3(0.0f);
                sum += L;
                float yl = luminance(L), delta = yl - mean;
                mean += delta / static_cast<float>(i + 1u);
                m2 += delta * (yl - mean);
            }
            const size_t p = static_cast<size_t>(y) * st.width + x;
            float nB = static_cast<float>(st.spp);
            vec3 colorB = sum / std::max(nB, 1.0f);
            glm::vec4& statsA = acc.stats[p];
            float nA = statsA.x;
            float n = nA + nB;
            vec3 color = (vec3(acc.color[p]) * nA + colorB * nB) / std::max(n, 1.0f);
            float delta = mean - statsA.y;
            float meanY = statsA.y + delta * nB / std::max(n, 1.0f);
            float M2 = statsA.z + m2 + delta * delta * nA * nB / std::max(n, 1.0f);
            float standardError = n > 1.0f ? std::sqrt(std::max(M2, 0.0f) / ((n - 1.0f) * n)) : 0.0f;
            acc.color[p] = vec4(color, 1.0f);
            statsA = vec4(n, meanY, M2, standardError);
        }
    }
};

CpuPathTracer::CpuPathTracer(const scene::Scene& scene, const scene::ScenePose& pose, bool transparent)
    : mImpl(std::make_unique<Impl>(scene, pose, transparent)) {}

bool CpuPathTracer::outdated(const scene::ScenePose& pose) const {
    const Impl& m = *mImpl;
    if (pose.instanceWorld != m.pose.instanceWorld) return true;
    // Joints are nodes: a deforming scene is outdated when any node moved or a morph weight changed.
    return m.deforms && (pose.nodeWorld != m.pose.nodeWorld || pose.meshWeights != m.pose.meshWeights);
}

CpuPathTracer::~CpuPathTracer() = default;

namespace {

// Runs row(y, rays) for every row of the frame on every core; the calling thread reports progress.
template <class Row>
CpuTraceCounters forEachRow(const CpuTraceSettings& s, const Row& row, const std::function<void(double)>& progress) {
    const double cpuStart = processCpuSeconds();
    const auto wallStart = std::chrono::steady_clock::now();
    const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
    std::atomic<int> nextRow{0}, rowsDone{0};
    std::atomic<uint64_t> rays{0};
    auto work = [&](bool report) {
        uint64_t local = 0;
        auto last = std::chrono::steady_clock::now();
        for (int y; (y = nextRow.fetch_add(1)) < s.height;) {
            row(y, local);
            rowsDone.fetch_add(1);
            if (!report) continue;
            auto now = std::chrono::steady_clock::now();
            if (now - last > std::chrono::milliseconds(200)) {
                progress(static_cast<double>(rowsDone.load()) / s.height);
                last = now;
            }
        }
        rays.fetch_add(local);
    };
    std::vector<std::thread> pool;
    for (unsigned i = 1; i < threads; ++i) pool.emplace_back(work, false);
    work(static_cast<bool>(progress));
    for (auto& t : pool) t.join();
    if (progress) progress(1.0);
    CpuTraceCounters c;
    c.paths = static_cast<uint64_t>(s.width) * s.height * s.spp;
    c.rays = rays.load();
    c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
    c.cpuSeconds = processCpuSeconds() - cpuStart;
    return c;
}

} // namespace

CpuTraceCounters CpuPathTracer::trace(const CpuTraceSettings& s, const CpuSky& sky, CpuAccumulation& acc,
                                      const std::function<void(double)>& progress) {
    if (acc.width != s.width || acc.height != s.height) acc.reset(s.width, s.height);
    const Env env(sky, s.skyScale);
    return forEachRow(
        s, [&](int y, uint64_t& rays) { mImpl->traceRow(y, s, env, acc, rays); }, progress);
}

CpuTraceCounters CpuPathTracer::estimate(const CpuTraceSettings& s, const CpuSky& sky, CpuAccumulation& acc,
                                         const CpuSampleFn& sample, const std::function<void(double)>& progress) {
    if (acc.width != s.width || acc.height != s.height) acc.reset(s.width, s.height);
    const Env env(sky, s.skyScale);
    return forEachRow(
        s,
        [&](int y, uint64_t& rays) {
            CpuRays q;
            q.mImpl = mImpl.get();
            q.mSettings = &s;
            q.mEnv = &env;
            mImpl->estimateRow(y, s, acc, [&](int x, uint32_t& rng) { return sample(q, x, y, rng); });
            rays += q.mRays;
        },
        progress);
}

// --- CpuRays ---

namespace {
const CpuPathTracer::Impl& implOf(const void* p) { return *static_cast<const CpuPathTracer::Impl*>(p); }
const Env& envOf(const void* p) { return *static_cast<const Env*>(p); }
} // namespace

bool CpuRays::intersect(vec3 o, vec3 d, float tmax, CpuSurface& hit) const {
    CpuPathTracer::Impl::Hit h;
    if (!implOf(mImpl).traceVisible(o, d, h, mRays) || h.t >= tmax) return false;
    hit = implOf(mImpl).pathSurface(h, o, d);
    return true;
}

bool CpuRays::firstHit(vec3 o, vec3 d, CpuSurface& hit, bool& inside) const {
    const CpuPathTracer::Impl& impl = implOf(mImpl);
    CpuPathTracer::Impl::Hit h;
    inside = false;
    if (!impl.closest(o, d, 0.0f, h, mRays)) return false;
    if (impl.culled(h, d)) {
        inside = true;
        return false;
    }
    hit = impl.pathSurface(h, o, d);
    return true;
}

bool CpuRays::occluded(vec3 o, vec3 d, float tmax) const { return implOf(mImpl).occluded(o, d, mRays, tmax); }

vec3 CpuRays::radiance(vec3 o, vec3 d, uint32_t& rng) const {
    return implOf(mImpl).tracePath(o, d, rng, *mSettings, envOf(mEnv), mRays);
}

vec3 CpuRays::radianceFrom(const CpuSurface& s, vec3 d, uint32_t& rng, bool emission) const {
    return implOf(mImpl).continuePath(s.position - s.t * d, d, rng, *mSettings, envOf(mEnv), mRays, &s, emission);
}

vec3 CpuRays::sky(vec3 d) const { return envOf(mEnv).radiance(glm::normalize(d)); }
vec3 CpuRays::sunIlluminance() const { return envOf(mEnv).sky->sunIlluminance * mSettings->sunScale; }
vec3 CpuRays::sunDirection() const { return glm::normalize(envOf(mEnv).sky->sunDirection); }

void CpuRays::cameraRay(int x, int y, vec2 jitter, vec3& origin, vec3& direction) const {
    CpuPathTracer::Impl::cameraRay(*mSettings, x, y, jitter, origin, direction);
}

vec3 CpuRays::offset(vec3 p, vec3 geometricNormal, vec3 dir) { return offsetRay(p, geometricNormal, dir); }
float CpuRays::next(uint32_t& rng) { return rngNext(rng); }
vec2 CpuRays::next2(uint32_t& rng) { return rngNext2(rng); }

// --- CpuAccumulation ---

std::vector<uint8_t> CpuAccumulation::serialize() const {
    const uint32_t header[4] = {0x52545056u /* "VPTR" */, static_cast<uint32_t>(width), static_cast<uint32_t>(height),
                                1u};
    const size_t n = color.size() * sizeof(glm::vec4);
    std::vector<uint8_t> bytes(sizeof header + 2 * n);
    std::memcpy(bytes.data(), header, sizeof header);
    std::memcpy(bytes.data() + sizeof header, color.data(), n);
    std::memcpy(bytes.data() + sizeof header + n, stats.data(), n);
    return bytes;
}

bool CpuAccumulation::deserialize(const std::vector<uint8_t>& bytes, int w, int h) {
    uint32_t header[4];
    const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h) * sizeof(glm::vec4);
    if (w <= 0 || h <= 0 || bytes.size() != sizeof header + 2 * n) return false;
    std::memcpy(header, bytes.data(), sizeof header);
    if (header[0] != 0x52545056u || header[1] != static_cast<uint32_t>(w) || header[2] != static_cast<uint32_t>(h) ||
        header[3] != 1u)
        return false;
    reset(w, h);
    std::memcpy(color.data(), bytes.data() + sizeof header, n);
    std::memcpy(stats.data(), bytes.data() + sizeof header + n, n);
    return true;
}

double CpuAccumulation::relativeNoise(double* p90) const {
    std::vector<float> relative;
    relative.reserve(stats.size());
    for (const glm::vec4& st : stats)
        if (st.y > 0.0f) relative.push_back(st.w / st.y);
    if (relative.empty()) {
        if (p90) *p90 = 0.0;
        return 0.0;
    }
    auto at = [&](double q) {
        auto it = relative.begin() + static_cast<std::ptrdiff_t>(q * double(relative.size() - 1));
        std::nth_element(relative.begin(), it, relative.end());
        return static_cast<double>(*it);
    };
    if (p90) *p90 = at(0.9);
    return at(0.5);
}

} // namespace vitrine
