// KHR_materials_pbrSpecularGlossiness converted to the metallic-roughness model at load time, factors and textures.
//
// The two models, per the extension and glTF 2.0's Appendix B, for a colour's diffuse reflectance and its
// reflectance at normal incidence f0:
//   specular-glossiness:  c_diff = diffuse × (1 − max(specular)),   f0 = specular
//   metallic-roughness:   c_diff = base × (1 − 0.04) × (1 − m),     f0 = mix(0.04, base, m)
// Matching both on one brightness per colour (perceived brightness, √(0.299 r² + 0.587 g² + 0.114 b²)) with
// D = brightness(diffuse) × (1 − max(specular)) / 0.96 and S = brightness(specular): the diffuse match gives
// base = D / (1 − m); putting that into S = 0.04 (1 − m) + base × m and multiplying by (1 − m):
//   0.04 m² + (D + S − 0.08) m + (0.04 − S) = 0,
// whose larger root is the metallic (0 when S < 0.04: less reflective than any dielectric). The base colour is then
// read back per channel from either match — from the diffuse, diffuse × (1 − max(specular)) / (0.96 (1 − m)), exact
// as m → 0; from the specular, (specular − 0.04 (1 − m)) / m, exact as m → 1 — mixed by m². For grey colours both
// give the same value and the conversion is exact; coloured ones are approximated. Roughness = 1 − glossiness.

#include "core/scene/gltf_detail.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace vitrine::scene::gltf {

namespace {

constexpr float kDielectricF0 = 0.04f;

float brightness(glm::vec3 c) {
    return std::sqrt(0.299f * c.r * c.r + 0.587f * c.g * c.g + 0.114f * c.b * c.b);
}

float decodeSrgb(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

uint8_t encodeSrgb(float linear) {
    float c = std::clamp(linear, 0.0f, 1.0f);
    c = c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
    return static_cast<uint8_t>(std::lround(c * 255.0f));
}

uint8_t encodeLinear(float v) {
    return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
}

int wrapCoord(int i, int n, Wrap wrap) {
    if (wrap == Wrap::ClampToEdge) return std::clamp(i, 0, n - 1);
    if (wrap == Wrap::MirroredRepeat) {
        int period = 2 * n, m = ((i % period) + period) % period;
        return m < n ? m : period - 1 - m;
    }
    return ((i % n) + n) % n;
}

// Texel of `image` at normalised (u, v) (v down, as the image is stored), bilinear or nearest per the sampler's
// magnification filter, raw bytes as floats in [0, 1]. Only used to bring two textures of different sizes to one.
glm::vec4 sampleRaw(const TextureImage& image, const Sampler& sampler, float u, float v) {
    auto texel = [&](int x, int y) {
        const uint8_t* p = image.at(static_cast<uint32_t>(wrapCoord(x, int(image.width), sampler.wrapU)),
                                    static_cast<uint32_t>(wrapCoord(y, int(image.height), sampler.wrapV)));
        return glm::vec4(p[0], p[1], p[2], p[3]) / 255.0f;
    };
    float x = u * image.width - 0.5f, y = v * image.height - 0.5f;
    if (sampler.magFilter == Filter::Nearest) return texel(int(std::floor(x + 0.5f)), int(std::floor(y + 0.5f)));
    int x0 = int(std::floor(x)), y0 = int(std::floor(y));
    float fx = x - x0, fy = y - y0;
    return glm::mix(glm::mix(texel(x0, y0), texel(x0 + 1, y0), fx),
                    glm::mix(texel(x0, y0 + 1), texel(x0 + 1, y0 + 1), fx), fy);
}

std::string keyOf(const TextureRef& diffuse, const TextureRef& specGloss, glm::vec4 diffuseFactor, glm::vec3 specular,
                  float glossiness) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "%d %d %a %a %a %a %a %a %a %a", diffuse.texture, specGloss.texture, diffuseFactor.r,
                  diffuseFactor.g, diffuseFactor.b, diffuseFactor.a, specular.r, specular.g, specular.b, glossiness);
    return buf;
}

// The two converted textures (base colour, sRGB; metallic-roughness, G = roughness, B = metallic as glTF has it) at
// the larger of the two sources' sizes; either source may be absent (its factor alone then).
std::pair<int32_t, int32_t> convertTextures(LoadContext& ctx, const TextureRef& diffuse, const TextureRef& specGloss,
                                            glm::vec4 diffuseFactor, glm::vec3 specularFactor, float glossinessFactor) {
    std::string key = keyOf(diffuse, specGloss, diffuseFactor, specularFactor, glossinessFactor);
    auto found = ctx.specGlossTextures.find(key);
    if (found != ctx.specGlossTextures.end()) return found->second;

    Scene& scene = *ctx.scene;
    const Texture* dTex = diffuse.valid() ? &scene.textures[diffuse.texture] : nullptr;
    const Texture* sTex = specGloss.valid() ? &scene.textures[specGloss.texture] : nullptr;
    const TextureImage* dImg = dTex ? &scene.images[dTex->image] : nullptr;
    const TextureImage* sImg = sTex ? &scene.images[sTex->image] : nullptr;
    uint32_t width = std::max(dImg ? dImg->width : 0u, sImg ? sImg->width : 0u);
    uint32_t height = std::max(dImg ? dImg->height : 0u, sImg ? sImg->height : 0u);

    TextureImage base, metalRough;
    std::string name =
        dTex ? (dTex->name.empty() ? dImg->name : dTex->name) : (sTex->name.empty() ? sImg->name : sTex->name);
    name += name.empty() ? "" : " ";
    base.name = name + "base colour (from specular-glossiness)";
    metalRough.name = name + "metallic-roughness (from specular-glossiness)";
    for (TextureImage* img : {&base, &metalRough}) {
        img->width = width;
        img->height = height;
        img->pixels.resize(size_t(width) * height * 4);
    }
    for (uint32_t y = 0; y < height; ++y) {
        for (uint32_t x = 0; x < width; ++x) {
            float u = (x + 0.5f) / width, v = (y + 0.5f) / height;
            glm::vec4 d = diffuseFactor;
            if (dImg) {
                glm::vec4 raw =
                    dImg->width == width && dImg->height == height
                        ? glm::vec4(dImg->at(x, y)[0], dImg->at(x, y)[1], dImg->at(x, y)[2], dImg->at(x, y)[3]) / 255.0f
                        : sampleRaw(*dImg, dTex->sampler, u, v);
                d *= glm::vec4(decodeSrgb(raw.r), decodeSrgb(raw.g), decodeSrgb(raw.b), raw.a);
            }
            glm::vec3 s = specularFactor;
            float g = glossinessFactor;
            if (sImg) {
                glm::vec4 raw =
                    sImg->width == width && sImg->height == height
                        ? glm::vec4(sImg->at(x, y)[0], sImg->at(x, y)[1], sImg->at(x, y)[2], sImg->at(x, y)[3]) / 255.0f
                        : sampleRaw(*sImg, sTex->sampler, u, v);
                // specular is sRGB-encoded, glossiness (alpha) linear
                s *= glm::vec3(decodeSrgb(raw.r), decodeSrgb(raw.g), decodeSrgb(raw.b));
                g *= raw.a;
            }
            MetalRough mr = specGlossToMetalRough(d, s, g);
            uint8_t* b = base.at(x, y);
            b[0] = encodeSrgb(mr.baseColor.r);
            b[1] = encodeSrgb(mr.baseColor.g);
            b[2] = encodeSrgb(mr.baseColor.b);
            b[3] = encodeLinear(mr.baseColor.a);
            uint8_t* m = metalRough.at(x, y);
            m[0] = 255;
            m[1] = encodeLinear(mr.roughness);
            m[2] = encodeLinear(mr.metallic);
            m[3] = 255;
        }
    }
    const Texture& like = dTex ? *dTex : *sTex;
    auto add = [&](TextureImage&& image, TextureUsage usage) {
        Texture t;
        t.name = image.name;
        t.image = static_cast<uint32_t>(scene.images.size());
        t.sampler = like.sampler;
        t.usage = usage;
        scene.images.push_back(std::move(image));
        scene.textures.push_back(t);
        return static_cast<int32_t>(scene.textures.size() - 1);
    };
    std::pair<int32_t, int32_t> made;
    made.first = add(std::move(base), TextureUsage::Color);
    made.second = add(std::move(metalRough), TextureUsage::Data);
    ctx.specGlossTextures.emplace(key, made);
    return made;
}

} // namespace

MetalRough specGlossToMetalRough(glm::vec4 diffuse, glm::vec3 specular, float glossiness) {
    float maxSpecular = std::max({specular.r, specular.g, specular.b});
    float oneMinusMax = 1.0f - maxSpecular;
    float S = brightness(specular);
    float D = brightness(glm::vec3(diffuse)) * oneMinusMax / (1.0f - kDielectricF0);
    float metallic = 0.0f;
    if (S >= kDielectricF0) {
        float a = kDielectricF0, b = D + S - 2.0f * kDielectricF0, c = kDielectricF0 - S;
        float disc = std::max(b * b - 4.0f * a * c, 0.0f);
        metallic = std::clamp((-b + std::sqrt(disc)) / (2.0f * a), 0.0f, 1.0f);
    }
    glm::vec3 fromDiffuse =
        glm::vec3(diffuse) * (oneMinusMax / ((1.0f - kDielectricF0) * std::max(1.0f - metallic, 1e-6f)));
    glm::vec3 fromSpecular = (specular - glm::vec3(kDielectricF0 * (1.0f - metallic))) / std::max(metallic, 1e-6f);
    glm::vec3 base = glm::clamp(glm::mix(fromDiffuse, fromSpecular, metallic * metallic), 0.0f, 1.0f);
    return {glm::vec4(base, diffuse.a), metallic, std::clamp(1.0f - glossiness, 0.0f, 1.0f)};
}

void readSpecularGlossiness(LoadContext& ctx, const Json& ext, const std::string& element, MaterialLayer& layer) {
    std::string e = element + ".extensions." + kSpecGloss;
    glm::vec4 diffuse = numbers(ctx, ext, "diffuseFactor", 4, glm::vec4(1.0f), e);
    glm::vec3 specular = glm::vec3(numbers(ctx, ext, "specularFactor", 3, glm::vec4(1.0f), e));
    float glossiness = static_cast<float>(number(ctx, ext, "glossinessFactor", 1.0, e));
    for (int i = 0; i < 4; ++i) {
        if (!(diffuse[i] >= 0.0f && diffuse[i] <= 1.0f)) ctx.fail(e + ".diffuseFactor", "expected numbers in [0, 1]");
        if (i < 3 && !(specular[i] >= 0.0f && specular[i] <= 1.0f))
            ctx.fail(e + ".specularFactor", "expected numbers in [0, 1]");
    }
    if (!(glossiness >= 0.0f && glossiness <= 1.0f)) ctx.fail(e + ".glossinessFactor", "expected a number in [0, 1]");
    TextureRef diffuseTex, specGlossTex;
    if (const Json* t = member(ext, "diffuseTexture"))
        diffuseTex = readTextureInfo(ctx, *t, TextureUsage::Color, e + ".diffuseTexture");
    if (const Json* t = member(ext, "specularGlossinessTexture"))
        specGlossTex = readTextureInfo(ctx, *t, TextureUsage::Color, e + ".specularGlossinessTexture");

    layer.shininess.atZero = 1.0f;
    layer.metallic.atZero = 0.0f;
    if (!diffuseTex.valid() && !specGlossTex.valid()) {
        MetalRough mr = specGlossToMetalRough(diffuse, specular, glossiness);
        layer.albedo.factor = mr.baseColor;
        layer.shininess.factor = 1.0f - mr.roughness;
        layer.metallic.factor = mr.metallic;
        return;
    }
    // The converted textures carry every factor; they are sampled as the diffuse texture is (else the other).
    const TextureRef& mapping = diffuseTex.valid() ? diffuseTex : specGlossTex;
    if (diffuseTex.valid() && specGlossTex.valid() &&
        (diffuseTex.uvSet != specGlossTex.uvSet || diffuseTex.transform != specGlossTex.transform)) {
        ctx.warn(e + ".specularGlossinessTexture",
                 "its texCoord or KHR_texture_transform differs from diffuseTexture's; converted to metallic-roughness "
                 "texel by texel, both are sampled as diffuseTexture is");
    }
    for (const TextureRef* source : {&diffuseTex, &specGlossTex})
        if (source->valid()) ctx.specGlossSources.insert(source->texture);
    auto [base, metalRough] = convertTextures(ctx, diffuseTex, specGlossTex, diffuse, specular, glossiness);
    layer.albedo.factor = glm::vec4(1.0f);
    layer.albedo.texture = mapping;
    layer.albedo.texture.texture = base;
    layer.shininess.factor = 0.0f; // shininess = 1 − roughness texel
    layer.shininess.texture = mapping;
    layer.shininess.texture.texture = metalRough;
    layer.shininess.channel = 1;
    layer.metallic.factor = 1.0f;
    layer.metallic.texture = mapping;
    layer.metallic.texture.texture = metalRough;
    layer.metallic.channel = 2;
}

void dropSpecGlossSources(LoadContext& ctx) {
    if (ctx.specGlossSources.empty()) return;
    Scene& scene = *ctx.scene;
    auto forEachRef = [&](auto f) {
        for (Material& m : scene.materials) {
            for (MaterialLayer& l : m.layers) {
                for (TextureRef* r : {&l.albedo.texture, &l.normal.texture, &l.shininess.texture, &l.metallic.texture,
                                      &l.cavity.texture, &l.mask.texture})
                    f(*r);
            }
            f(m.emissiveTexture);
            f(m.specularTexture);
            f(m.specularColorTexture);
            f(m.clearcoatTexture);
            f(m.clearcoatRoughnessTexture);
            f(m.clearcoatNormal.texture);
            f(m.sheenColorTexture);
            f(m.sheenRoughnessTexture);
            f(m.thicknessTexture);
        }
    };
    std::vector<bool> used(scene.textures.size(), false);
    forEachRef([&](TextureRef& r) {
        if (r.valid()) used[r.texture] = true;
    });
    std::vector<int32_t> textureIndex(scene.textures.size(), -1);
    std::vector<Texture> textures;
    std::vector<bool> imageBefore(scene.images.size(), false), imageAfter(scene.images.size(), false);
    for (size_t i = 0; i < scene.textures.size(); ++i) {
        imageBefore[scene.textures[i].image] = true;
        if (!used[i] && ctx.specGlossSources.count(static_cast<int32_t>(i))) continue;
        imageAfter[scene.textures[i].image] = true;
        textureIndex[i] = static_cast<int32_t>(textures.size());
        textures.push_back(scene.textures[i]);
    }
    if (textures.size() == scene.textures.size()) return;
    std::vector<uint32_t> imageIndex(scene.images.size(), 0);
    std::vector<TextureImage> images;
    for (size_t i = 0; i < scene.images.size(); ++i) {
        if (imageBefore[i] && !imageAfter[i]) continue; // read only by the dropped textures
        imageIndex[i] = static_cast<uint32_t>(images.size());
        images.push_back(std::move(scene.images[i]));
    }
    for (Texture& t : textures)
        t.image = imageIndex[t.image];
    scene.textures = std::move(textures);
    scene.images = std::move(images);
    forEachRef([&](TextureRef& r) {
        if (r.valid()) r.texture = textureIndex[r.texture];
    });
    for (auto& byUsage : ctx.textureByUsage)
        for (int32_t& slot : byUsage)
            slot = slot >= 0 ? textureIndex[slot] : -1;
    ctx.specGlossSources.clear();
}

} // namespace vitrine::scene::gltf
