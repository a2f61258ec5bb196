#pragma once

// Textures and layered materials (MUSEUM_SPEC §1–2). A material is a stack of layers; each layer has the
// five UE4-style parameters (albedo, normal, shininess, metallic, cavity), each a constant times an
// optional texture, and every texture reference carries its own UV transform. Layers above the first
// blend over the result below them by a mask, one parameter at a time. The on-disk form is the glTF
// extension described in VITRINE_material_layers.md.

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/scene/pixel_buffer.hpp"

#include <glm/glm.hpp>

namespace vitrine::scene {

// Pixels of a texture: always 8-bit RGBA, row-major, top row first. Deliberately not vitrine::Image
// (float RGBA): a 1K texture is 4 MiB here instead of 16 MiB, sources are 8-bit anyway, and the GPU
// side uploads RGBA8 / RGBA8_SRGB as is. Mips are built on the GPU (normal maps without renormalising,
// for Toksvig), so only level 0 is stored.
struct TextureImage {
    std::string name;
    uint32_t width = 0;
    uint32_t height = 0;
    PixelBuffer pixels; // width * height * 4; a view of the bake cache for the museum's loaded textures

    uint8_t* at(uint32_t x, uint32_t y) { return &pixels[(static_cast<size_t>(y) * width + x) * 4]; }
    const uint8_t* at(uint32_t x, uint32_t y) const { return &pixels[(static_cast<size_t>(y) * width + x) * 4]; }
};

// What a texture holds decides how it is decoded: colour is sRGB-encoded (albedo, emissive), the rest
// is linear data. Normal maps are told apart from other data because their mips are built differently.
enum class TextureUsage : uint8_t { Color, Normal, Data };
enum class ColorSpace : uint8_t { Linear, Srgb };

enum class Filter : uint8_t { Nearest, Linear };
enum class MipFilter : uint8_t { None, Nearest, Linear };
enum class Wrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };

struct Sampler {
    Filter magFilter = Filter::Linear;
    Filter minFilter = Filter::Linear;
    MipFilter mipFilter = MipFilter::Linear;
    Wrap wrapU = Wrap::Repeat;
    Wrap wrapV = Wrap::Repeat;

    bool operator==(const Sampler&) const = default;
};

struct Texture {
    std::string name;
    uint32_t image = 0; // index into Scene::images; several textures may share one image
    Sampler sampler;
    TextureUsage usage = TextureUsage::Data;

    ColorSpace colorSpace() const { return usage == TextureUsage::Color ? ColorSpace::Srgb : ColorSpace::Linear; }
};

// KHR_texture_transform semantics: uv' = T(offset) · R(rotation) · S(scale) · uv, rotation in radians
// counter-clockwise in UV space (which is clockwise on the image, whose v points down).
struct UvTransform {
    glm::vec2 offset{0.0f};
    glm::vec2 scale{1.0f};
    float rotation = 0.0f;

    bool isIdentity() const { return offset == glm::vec2(0.0f) && scale == glm::vec2(1.0f) && rotation == 0.0f; }
    glm::mat3 matrix() const; // column-major, for a shader's mat3 (or its first two rows)
    glm::vec2 apply(glm::vec2 uv) const { return glm::vec2(matrix() * glm::vec3(uv, 1.0f)); }
    bool operator==(const UvTransform&) const = default;
};

// A use of a texture by one parameter.
struct TextureRef {
    int32_t texture = -1; // index into Scene::textures; -1 = none
    uint32_t uvSet = 0;   // 0 = Vertex::uv0, 1 = Vertex::uv1
    UvTransform transform;

    bool valid() const { return texture >= 0; }
    bool operator==(const TextureRef&) const = default;
};

// value = mix(atZero, factor, texel[channel]); texel = 1 without a texture, so the value is factor.
// atZero = 0 gives glTF's "factor × texel". A roughness channel read as shininess = 1 − r·roughness
// is mix(1, 1 − r, texel): atZero = 1, factor = 1 − r. glTF occlusion with strength s read as cavity is
// mix(1 − s, 1, texel).
struct ScalarParam {
    float factor = 0.0f;
    float atZero = 0.0f;
    TextureRef texture;
    uint32_t channel = 0; // 0..3 = r, g, b, a

    float evaluate(float texel) const { return atZero + (factor - atZero) * texel; }
    bool operator==(const ScalarParam&) const = default;
};

// Base colour: factor × texel (texture sRGB-decoded first). alpha is coverage for AlphaMode::Mask.
struct ColorParam {
    glm::vec4 factor{1.0f};
    TextureRef texture;
    bool operator==(const ColorParam&) const = default;
};

// Tangent-space normal map, glTF encoding: rgb = n · 0.5 + 0.5 with x along the tangent and y along the
// bitangent ("OpenGL" green). n.xy is multiplied by scale. No texture = the interpolated vertex normal.
struct NormalParam {
    float scale = 1.0f;
    TextureRef texture;
    bool operator==(const NormalParam&) const = default;
};

// Bits of MaterialLayer::overrides.
enum LayerParamBits : uint32_t {
    kLayerAlbedo = 1u << 0,
    kLayerNormal = 1u << 1,
    kLayerShininess = 1u << 2,
    kLayerMetallic = 1u << 3,
    kLayerCavity = 1u << 4,
    kLayerAll = 0x1fu,
};

// How much of a layer shows over the layers below: weight = clamp(factor × texel[channel], 0, 1), or
// clamp(factor) without a texture. The first layer has no mask (weight 1).
struct LayerMask {
    float factor = 1.0f;
    TextureRef texture;
    uint32_t channel = 0;
    bool operator==(const LayerMask&) const = default;
};

struct MaterialLayer {
    std::string name;
    ColorParam albedo;
    NormalParam normal;
    ScalarParam shininess{0.5f, 0.0f};
    ScalarParam metallic{0.0f, 0.0f};
    ScalarParam cavity{1.0f, 0.0f};
    // Parameters this layer blends over the result below (p = mix(below, this, weight)); the others pass
    // through untouched. Layer 0 defines all five whatever this says.
    uint32_t overrides = kLayerAll;
    LayerMask mask;

    bool operator==(const MaterialLayer&) const = default;
};

enum class AlphaMode : uint8_t { Opaque, Mask, Blend };

struct Material {
    std::string name;
    std::vector<MaterialLayer> layers; // at least one; layers[0] is the base
    glm::vec3 emissiveFactor{0.0f};    // linear
    float emissiveStrength = 1.0f;     // KHR_materials_emissive_strength; emitted = factor × strength × texel
    TextureRef emissiveTexture;        // sRGB
    AlphaMode alphaMode = AlphaMode::Opaque;
    float alphaCutoff = 0.5f;
    bool doubleSided = false;
    // KHR_materials_unlit: the base colour (× vertex colour) is the radiance, through the emissive path.
    bool unlit = false;
    // KHR_materials_transmission's transmissionFactor (its texture is not read): the fraction of the dielectric
    // base that lets light through, drawn by forward.transparent as thin glass (tinted by the base colour).
    float transmission = 0.0f;
    float ior = 1.5f; // KHR_materials_ior: the dielectric reflectance at normal incidence is ((ior − 1)/(ior + 1))²
    // KHR_materials_specular: the dielectric's specular strength k = specular × specularTexture.a and colour
    // c = specularColor × specularColorTexture.rgb scale its Fresnel: F0 = k · min(F0(ior) · c, 1), F90 = k
    // (common/brdf.glsl dielectricSpecular). Metals keep F0 = base colour, F90 = 1.
    float specular = 1.0f;
    TextureRef specularTexture;      // data, alpha channel
    glm::vec3 specularColor{1.0f};   // linear, ≥ 0
    TextureRef specularColorTexture; // sRGB

    // True when KHR_materials_specular changes anything (the defaults leave the dielectric as it was).
    bool hasSpecular() const {
        return specular != 1.0f || specularColor != glm::vec3(1.0f) || specularTexture.valid() ||
               specularColorTexture.valid();
    }

    // KHR_materials_clearcoat: a dielectric coat (ior 1.5, F0 0.04) over the whole material, of strength
    // c = clearcoat × clearcoatTexture.r and roughness clearcoatRoughness × clearcoatRoughnessTexture.g, with its own
    // normal map (else the base normal): f = base · (1 − c·Fc(N_c·V)) + c · coat GGX (common/brdf.glsl clearcoatLayer).
    float clearcoat = 0.0f;
    TextureRef clearcoatTexture; // data, red channel
    float clearcoatRoughness = 0.0f;
    TextureRef clearcoatRoughnessTexture; // data, green channel
    NormalParam clearcoatNormal;          // tangent space, as a layer's normal

    // True when KHR_materials_clearcoat says anything (a factor of 0, the default, leaves no coat to draw).
    bool hasClearcoat() const {
        return clearcoat != 0.0f || clearcoatRoughness != 0.0f || clearcoatTexture.valid() ||
               clearcoatRoughnessTexture.valid() || clearcoatNormal.texture.valid();
    }

    // KHR_materials_sheen: a Charlie sheen lobe over the base (under the coat) of colour sheenColor ×
    // sheenColorTexture.rgb and perceptual roughness sheenRoughness × sheenRoughnessTexture.a:
    // f = sc·D·V + (1 − max(sc)·E(N·V)) · base (common/brdf.glsl brdfCosineSheen). A black colour (the default): none.
    glm::vec3 sheenColor{0.0f};       // linear, in [0, 1]
    TextureRef sheenColorTexture;     // sRGB
    float sheenRoughness = 0.0f;      // in [0, 1]
    TextureRef sheenRoughnessTexture; // data, alpha channel

    // True when KHR_materials_sheen says anything.
    bool hasSheen() const {
        return sheenColor != glm::vec3(0.0f) || sheenRoughness != 0.0f || sheenColorTexture.valid() ||
               sheenRoughnessTexture.valid();
    }

    // KHR_materials_volume: the medium behind a transmissive surface. forward.transparent multiplies the light passing
    // through by Beer's law T = attenuationColor^(d / attenuationDistance), d = |refracted direction × thickness × the
    // node's scale| (thickness × scale for a uniform scale), thickness = thicknessFactor × thicknessTexture.g in the
    // mesh's own units, and reads what lies behind at the exit point (the Sample Viewer's approximation).
    // render.pathtrace instead refracts at the mesh's real faces and applies Beer's law over the way inside
    // (shaders/pathtrace/volume.glsl). thickness 0 (the default) is thin-walled: nothing is attenuated.
    float thickness = 0.0f;                                              // ≥ 0
    TextureRef thicknessTexture;                                         // data, green channel
    float attenuationDistance = std::numeric_limits<float>::infinity(); // > 0; +∞: no attenuation
    glm::vec3 attenuationColor{1.0f};                                    // linear, in [0, 1]

    // True when KHR_materials_volume says anything (its defaults leave a thin-walled surface).
    bool hasVolume() const {
        return thickness != 0.0f || thicknessTexture.valid() || !std::isinf(attenuationDistance) ||
               attenuationColor != glm::vec3(1.0f);
    }

    // Drawn by the transparent pass (alpha blending or transmission), not into the G-buffer.
    bool transparent() const { return alphaMode == AlphaMode::Blend || transmission > 0.0f; }

    bool operator==(const Material&) const = default;
};

// True when any texture of the material samples the given UV set (0 or 1).
bool usesUvSet(const Material& material, uint32_t uvSet);
// True when a layer of the material has a normal texture: only then do its vertices' tangents matter.
bool usesNormalMap(const Material& material);

} // namespace vitrine::scene
