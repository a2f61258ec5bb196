#include "core/scene/museum/textures.hpp"
#include "core/scene/hash.hpp"

#include <array>
#include <optional>

#include "core/scene/museum/texture_util.hpp"

#include <cmath>

#include <glm/gtc/constants.hpp>

namespace vitrine::scene::museum {

TextureImage normalMapFromHeight(const std::string& name, const std::vector<float>& height, uint32_t size, bool wrap) {
    TextureImage out = blankImage(name, size);
    int n = static_cast<int>(size);
    auto at = [&](int x, int y) {
        if (wrap) {
            x = (x + n) % n;
            y = (y + n) % n;
        } else {
            x = glm::clamp(x, 0, n - 1);
            y = glm::clamp(y, 0, n - 1);
        }
        return height[size_t(y) * n + x];
    };
    float scale = 0.5f * n; // central difference over two texels of 1/n tile units
    for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
            float du = (at(x + 1, y) - at(x - 1, y)) * scale;
            float dv = (at(x, y + 1) - at(x, y - 1)) * scale;
            // Tangent = +u (image right), bitangent = image up = -v: n ∝ (-dh/du, +dh/dv, 1).
            glm::vec3 nrm = glm::normalize(glm::vec3(-du, dv, 1.0f));
            putData(out, size_t(y) * n + x, nrm.x * 0.5f + 0.5f, nrm.y * 0.5f + 0.5f, nrm.z * 0.5f + 0.5f);
        }
    }
    return out;
}

namespace {

constexpr float kTau = 6.28318530718f;

float fract(float x) {
    return x - std::floor(x);
}

// Distance (tile units) from u to the nearest multiple of period.
float toGrid(float u, float period) {
    float f = fract(u / period) * period;
    return std::min(f, period - f);
}

template <typename F> void forEachTexel(uint32_t size, F f) {
    float inv = 1.0f / size;
    for (uint32_t y = 0; y < size; ++y) {
        for (uint32_t x = 0; x < size; ++x)
            f(size_t(y) * size + x, (x + 0.5f) * inv, (y + 0.5f) * inv);
    }
}

struct Family {
    TextureImage albedo, data, normal;
};

Family marble(uint32_t n, Rng rng) {
    Family f{blankImage("marble_albedo", n), blankImage("marble_data", n), {}};
    std::vector<float> height(size_t(n) * n);
    Fbm turbulence(4, 6, 0.5f, rng), clouds(16, 4, 0.5f, rng);
    const glm::vec3 white(0.83f, 0.82f, 0.79f), warm(0.70f, 0.67f, 0.62f), veinColor(0.24f, 0.25f, 0.27f);
    forEachTexel(n, [&](size_t i, float u, float v) {
        float t = turbulence.sample(u, v), c = clouds.sample(u, v);
        // Integer frequencies across the tile keep the veins seamless.
        float vein1 = 1.0f - smoothstep(0.0f, 0.10f, std::abs(std::sin(kTau * (2 * u + v) + 9.0f * t)));
        float vein2 = 1.0f - smoothstep(0.0f, 0.05f, std::abs(std::sin(kTau * (u - 3 * v) + 12.0f * c)));
        float vein = std::max(0.85f * vein1, 0.45f * vein2) * (0.5f + 0.5f * t);
        float grout = 1.0f - smoothstep(0.0018f, 0.0032f, std::min(toGrid(u, 0.5f), toGrid(v, 0.5f)));
        glm::vec3 color = glm::mix(glm::mix(white, warm, c * 0.7f), veinColor, vein);
        color = glm::mix(color, glm::vec3(0.42f, 0.40f, 0.37f), grout);
        putColor(f.albedo, i, color);
        float chequer = float((int(std::floor(2 * u)) + int(std::floor(2 * v))) & 1);
        putData(f.data, i, 0.94f - 0.12f * vein - 0.5f * grout, chequer, 1.0f - 0.6f * grout);
        height[i] = -0.0012f * grout + 0.00015f * c;
    });
    f.normal = normalMapFromHeight("marble_normal", height, n, true);
    return f;
}

Family stone(uint32_t n, Rng rng) {
    Family f{blankImage("stone_albedo", n), blankImage("stone_data", n), {}};
    std::vector<float> height(size_t(n) * n);
    Fbm body(8, 6, 0.55f, rng);
    Worley pits(24, rng);
    ValueNoise grain(256, rng);
    const glm::vec3 sand(0.50f, 0.43f, 0.33f);
    forEachTexel(n, [&](size_t i, float u, float v) {
        float b = body.sample(u, v), g = grain.sample(u, v), f1, f2, id;
        pits.sample(u, v, f1, f2, id);
        float pit = (1.0f - smoothstep(0.0f, 0.22f, f1)) * (id > 0.55f ? 1.0f : 0.25f);
        glm::vec3 color = sand * (0.70f + 0.55f * b) * (0.90f + 0.2f * id) * (0.93f + 0.14f * g) * (1.0f - 0.45f * pit);
        putColor(f.albedo, i, color);
        // Ashlar joints for walls (blocks of 1 × 0.5 tile, alternate rows shifted by half a block).
        float row = std::floor(2 * v);
        float joint = std::max(1.0f - smoothstep(0.006f, 0.011f, toGrid(v, 0.5f)),
                               1.0f - smoothstep(0.003f, 0.006f, toGrid(u + 0.5f * row, 1.0f)));
        putData(f.data, i, 0.16f + 0.14f * b, joint, 1.0f - 0.7f * pit);
        height[i] = 0.004f * b - 0.0025f * pit + 0.0003f * g;
    });
    f.normal = normalMapFromHeight("stone_normal", height, n, true);
    return f;
}

Family wood(uint32_t n, Rng rng) {
    Family f{blankImage("wood_albedo", n), blankImage("wood_data", n), {}};
    std::vector<float> height(size_t(n) * n);
    Fbm warp(4, 5, 0.5f, rng), wear(8, 4, 0.5f, rng);
    ValueNoise pores(64, rng);
    const glm::vec3 light(0.36f, 0.19f, 0.085f), dark(0.13f, 0.06f, 0.028f);
    forEachTexel(n, [&](size_t i, float u, float v) {
        float w = warp.sample(u, v);
        float ring = fract(10.0f * v + 1.6f * w + 0.25f * std::sin(kTau * (u + 0.3f * w)));
        float late = smoothstep(0.55f, 0.9f, ring) * (1.0f - smoothstep(0.93f, 1.0f, ring));
        float pore = smoothstep(0.78f, 0.92f, pores.sample(u, 8.0f * v)); // stretched along the grain
        glm::vec3 color = glm::mix(light, dark, 0.75f * late) * (0.8f + 0.4f * w) * (1.0f - 0.35f * pore);
        putColor(f.albedo, i, color);
        float intact = smoothstep(0.33f, 0.45f, wear.sample(u, v));
        putData(f.data, i, intact, late, 1.0f - 0.5f * pore);
        height[i] = -0.0006f * pore + 0.0003f * late;
    });
    f.normal = normalMapFromHeight("wood_normal", height, n, true);
    return f;
}

TextureImage dirt(uint32_t n, Rng rng) {
    TextureImage out = blankImage("dirt_data", n);
    Fbm body(4, 6, 0.55f, rng);
    Worley cells(12, rng);
    ValueNoise speckle(256, rng);
    forEachTexel(n, [&](size_t i, float u, float v) {
        float f1, f2, id;
        cells.sample(u, v, f1, f2, id);
        float crevice = 1.0f - smoothstep(0.0f, 0.15f, f2 - f1);
        float d = smoothstep(0.46f, 0.66f, body.sample(u, v) + 0.3f * crevice);
        putData(out, i, d, smoothstep(0.75f, 0.85f, speckle.sample(u, v)), 1.0f - 0.5f * crevice);
    });
    return out;
}

TextureImage brushed(uint32_t n, Rng rng) {
    std::vector<float> height(size_t(n) * n);
    ValueNoise fine(16, rng), coarse(64, rng);
    // Much higher frequency across v than along u: streaks along u, like a brushed sheet.
    forEachTexel(n, [&](size_t i, float u, float v) {
        height[i] = 0.00012f * (0.6f * fine.sample(u, 32.0f * v) + 0.4f * coarse.sample(u, 8.0f * v));
    });
    return normalMapFromHeight("brushed_normal", height, n, true);
}

TextureImage engraving(uint32_t n) {
    std::vector<float> height(size_t(n) * n);
    // Rings about 5 texels apart: crisp at 1:1, a shimmering mess when minified — on purpose.
    float rings = n / 10.0f, amplitude = 0.25f / (kTau * rings);
    forEachTexel(n, [&](size_t i, float u, float v) {
        glm::vec2 p(2 * u - 1, 2 * v - 1);
        float r = glm::length(p), theta = std::atan2(p.y, p.x);
        float rr = r + 0.012f * std::sin(36.0f * theta) * r;
        float h =
            std::sin(kTau * rings * rr) + 0.5f * std::sin(kTau * rings * 0.5f * (r - 0.01f * std::sin(24 * theta)));
        height[i] = amplitude * h * (r < 0.97f ? 1.0f : 0.0f);
    });
    return normalMapFromHeight("engraving_normal", height, n, false);
}

Family cloth(uint32_t n, Rng rng) {
    Family f{blankImage("cloth_albedo", n), {}, {}};
    std::vector<float> height(size_t(n) * n);
    Fbm mottle(8, 4, 0.5f, rng);
    constexpr float kThreads = 128.0f;
    const glm::vec3 crimson(0.30f, 0.022f, 0.035f);
    forEachTexel(n, [&](size_t i, float u, float v) {
        float gu = u * kThreads, gv = v * kThreads;
        int over = (int(gu) + int(gv)) & 1;
        float fu = fract(gu), fv = fract(gv);
        // The thread on top bulges across its width; the crossing thread dips at its ends.
        float h = over ? std::sin(glm::pi<float>() * fu) * (0.75f + 0.25f * std::sin(glm::pi<float>() * fv))
                       : std::sin(glm::pi<float>() * fv) * (0.75f + 0.25f * std::sin(glm::pi<float>() * fu));
        float m = mottle.sample(u, v);
        putColor(f.albedo, i, crimson * (0.55f + 0.45f * h) * (0.8f + 0.4f * m) * (over ? 1.0f : 0.85f));
        height[i] = 0.35f / kThreads * h;
    });
    f.normal = normalMapFromHeight("cloth_normal", height, n, true);
    return f;
}

TextureImage plaster(uint32_t n, Rng rng) {
    std::vector<float> height(size_t(n) * n);
    Fbm bumps(16, 5, 0.5f, rng);
    forEachTexel(n, [&](size_t i, float u, float v) { height[i] = 0.0009f * bumps.sample(u, v); });
    return normalMapFromHeight("plaster_normal", height, n, true);
}

int32_t add(Scene& scene, TextureImage&& image, TextureUsage usage, Sampler sampler = {}) {
    Texture t;
    t.name = image.name;
    t.image = static_cast<uint32_t>(scene.images.size());
    t.usage = usage;
    t.sampler = sampler;
    scene.images.push_back(std::move(image));
    scene.textures.push_back(t);
    return static_cast<int32_t>(scene.textures.size()) - 1;
}

} // namespace

MuseumTextures makeTextures(Scene& scene, uint32_t size, Rng& rng, const MuseumOptions& options) {
    // Every family draws from its own fork, taken in this order whether the images are generated or loaded.
    std::array<Rng, 8> forks{Rng(0), Rng(0), Rng(0), Rng(0), Rng(0), Rng(0), Rng(0), Rng(0)};
    Rng probe = rng;
    const uint64_t stream = probe.next();
    for (uint64_t k = 0; k < forks.size(); ++k) forks[k] = rng.fork(k + 1);

    Sampler clamp;
    clamp.wrapU = clamp.wrapV = Wrap::ClampToEdge;
    // The textures in Scene::textures order, with how each is sampled.
    struct Slot {
        int32_t MuseumTextures::*index;
        TextureUsage usage;
        Sampler sampler;
    };
    const std::array<Slot, 16> slots = {{
        {&MuseumTextures::marbleAlbedo, TextureUsage::Color, {}},  {&MuseumTextures::marbleData, TextureUsage::Data, {}},
        {&MuseumTextures::marbleNormal, TextureUsage::Normal, {}}, {&MuseumTextures::stoneAlbedo, TextureUsage::Color, {}},
        {&MuseumTextures::stoneData, TextureUsage::Data, {}},      {&MuseumTextures::stoneNormal, TextureUsage::Normal, {}},
        {&MuseumTextures::woodAlbedo, TextureUsage::Color, {}},    {&MuseumTextures::woodData, TextureUsage::Data, {}},
        {&MuseumTextures::woodNormal, TextureUsage::Normal, {}},   {&MuseumTextures::dirt, TextureUsage::Data, {}},
        {&MuseumTextures::brushedNormal, TextureUsage::Normal, {}}, {&MuseumTextures::fineNormal, TextureUsage::Normal, clamp},
        {&MuseumTextures::clothAlbedo, TextureUsage::Color, {}},   {&MuseumTextures::clothNormal, TextureUsage::Normal, {}},
        {&MuseumTextures::plasterNormal, TextureUsage::Normal, {}}, {&MuseumTextures::paintings, TextureUsage::Color, clamp},
    }};

    Hasher h;
    h.string("museum textures v1");
    h.value(stream);
    h.value(size);
    h.value(museumTextureSourceHash());
    const uint64_t key = h.result();

    std::vector<TextureImage> images;
    if (options.loadTextures) {
        if (std::optional<std::vector<TextureImage>> loaded = options.loadTextures(key)) {
            // (A conditional `ok ? *loaded : std::vector<TextureImage>{}` here copied all 64 MiB of them.)
            bool ok = loaded->size() == slots.size();
            for (const TextureImage& image : *loaded)
                ok = ok && image.width > 0 && image.height > 0 &&
                     image.pixels.size() == static_cast<size_t>(image.width) * image.height * 4;
            if (ok) images = std::move(*loaded);
        }
    }
    if (images.empty()) {
        Family m = marble(size, forks[0]);
        Family s = stone(size, forks[1]);
        Family w = wood(size, forks[2]);
        images.push_back(std::move(m.albedo));
        images.push_back(std::move(m.data));
        images.push_back(std::move(m.normal));
        images.push_back(std::move(s.albedo));
        images.push_back(std::move(s.data));
        images.push_back(std::move(s.normal));
        images.push_back(std::move(w.albedo));
        images.push_back(std::move(w.data));
        images.push_back(std::move(w.normal));
        images.push_back(dirt(size, forks[3]));
        images.push_back(brushed(size, forks[4]));
        images.push_back(engraving(size));
        Family c = cloth(size, forks[5]);
        images.push_back(std::move(c.albedo));
        images.push_back(std::move(c.normal));
        images.push_back(plaster(size, forks[6]));
        images.push_back(paintingAtlas(size, forks[7]));
        if (options.storeTextures) options.storeTextures(key, images);
    }
    MuseumTextures t;
    for (size_t i = 0; i < slots.size(); ++i)
        t.*(slots[i].index) = add(scene, std::move(images[i]), slots[i].usage, slots[i].sampler);
    return t;
}

} // namespace vitrine::scene::museum
