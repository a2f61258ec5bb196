// glTF images, samplers, textures and materials → scene textures and layered materials.

#include "core/scene/gltf.hpp"
#include "core/scene/gltf_detail.hpp"

#include <cmath>
#include <limits>
#include <set>

#include <tiny_gltf.h>

namespace vitrine::scene::gltf {

const char* usageName(TextureUsage usage) {
    switch (usage) {
    case TextureUsage::Color:
        return "color";
    case TextureUsage::Normal:
        return "normal";
    default:
        return "data";
    }
}

namespace {

Filter toFilter(int f) {
    return f == TINYGLTF_TEXTURE_FILTER_NEAREST ? Filter::Nearest : Filter::Linear;
}

Wrap toWrap(int w) {
    if (w == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE) return Wrap::ClampToEdge;
    if (w == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT) return Wrap::MirroredRepeat;
    return Wrap::Repeat;
}

Sampler toSampler(const tinygltf::Sampler& s) {
    Sampler out;
    out.magFilter = toFilter(s.magFilter);
    out.wrapU = toWrap(s.wrapS);
    out.wrapV = toWrap(s.wrapT);
    switch (s.minFilter) {
    case TINYGLTF_TEXTURE_FILTER_NEAREST:
        out.minFilter = Filter::Nearest;
        out.mipFilter = MipFilter::None;
        break;
    case TINYGLTF_TEXTURE_FILTER_LINEAR:
        out.mipFilter = MipFilter::None;
        break;
    case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST:
        out.minFilter = Filter::Nearest;
        out.mipFilter = MipFilter::Nearest;
        break;
    case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_NEAREST:
        out.mipFilter = MipFilter::Nearest;
        break;
    case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR:
        out.minFilter = Filter::Nearest;
        break;
    default:
        break; // LINEAR_MIPMAP_LINEAR or unspecified: trilinear
    }
    return out;
}

TextureImage toImage(const LoadContext& ctx, const tinygltf::Image& src, size_t index) {
    std::string e = "images[" + std::to_string(index) + "]";
    if (src.image.empty() || src.width <= 0 || src.height <= 0) {
        ctx.fail(e, "could not be loaded or decoded" + (src.uri.empty() ? std::string() : " ('" + src.uri + "')") +
                        "; expected a PNG or JPEG image");
    }
    int comps = src.component, bytesPer = src.bits == 16 ? 2 : 1;
    if (comps < 1 || comps > 4 || (src.bits != 8 && src.bits != 16) ||
        src.image.size() < size_t(src.width) * src.height * comps * bytesPer) {
        ctx.fail(e, "decoded to an unexpected pixel format");
    }
    TextureImage out;
    out.name = src.name;
    out.width = static_cast<uint32_t>(src.width);
    out.height = static_cast<uint32_t>(src.height);
    out.pixels.resize(size_t(out.width) * out.height * 4);
    for (size_t p = 0; p < size_t(out.width) * out.height; ++p) {
        uint8_t c[4] = {0, 0, 0, 255};
        for (int k = 0; k < comps; ++k) {
            size_t at = (p * comps + k) * bytesPer;
            // 16-bit PNG is big-endian in the file but stb returns native shorts: take the high byte.
            c[k] = bytesPer == 2 ? static_cast<uint8_t>((src.image[at] | src.image[at + 1] << 8) >> 8) : src.image[at];
        }
        if (comps <= 2) { // grey or grey + alpha
            c[3] = comps == 2 ? c[1] : 255;
            c[1] = c[2] = c[0];
        }
        std::copy(c, c + 4, &out.pixels[p * 4]);
    }
    return out;
}

int32_t resolveTexture(LoadContext& ctx, uint32_t gltfIndex, TextureUsage usage) {
    const int32_t loaded = ctx.sceneTexture[gltfIndex];
    if (loaded < 0) return -1; // no image vitrine could read (loadImagesAndTextures warned): drawn without it
    std::array<int32_t, 3>& byUsage = ctx.textureByUsage[gltfIndex];
    int32_t& slot = byUsage[static_cast<int>(usage)];
    if (slot >= 0) return slot;
    bool unassigned = byUsage[0] < 0 && byUsage[1] < 0 && byUsage[2] < 0;
    if (unassigned) {
        ctx.scene->textures[loaded].usage = usage;
        slot = loaded;
    } else {
        Texture copy = ctx.scene->textures[loaded];
        copy.usage = usage;
        slot = static_cast<int32_t>(ctx.scene->textures.size());
        ctx.scene->textures.push_back(copy);
    }
    return slot;
}

void checkKeys(const LoadContext& ctx, const Json& obj, std::initializer_list<const char*> keys,
               const std::string& element) {
    for (auto it = obj.begin(); it != obj.end(); ++it) {
        bool known = it.key() == "extensions" || it.key() == "extras";
        for (const char* k : keys)
            known = known || it.key() == k;
        if (!known) {
            std::string list;
            for (const char* k : keys)
                list += (list.empty() ? "" : ", ") + std::string(k);
            ctx.fail(element + "." + it.key(), "unknown key; expected one of: " + list);
        }
    }
}

uint32_t readChannel(const LoadContext& ctx, const Json& obj, const std::string& element) {
    int64_t c = integer(ctx, obj, "channel", 0, element);
    if (c < 0 || c > 3) ctx.fail(element + ".channel", std::to_string(c) + "; expected 0..3 (r, g, b, a)");
    return static_cast<uint32_t>(c);
}

ScalarParam readScalar(LoadContext& ctx, const Json& layer, const char* key, ScalarParam def, const std::string& e) {
    const Json* p = object(ctx, layer, key, e);
    if (!p) return def;
    std::string pe = e + "." + key;
    checkKeys(ctx, *p, {"factor", "atZero", "channel", "texture"}, pe);
    def.factor = static_cast<float>(number(ctx, *p, "factor", def.factor, pe));
    def.atZero = static_cast<float>(number(ctx, *p, "atZero", def.atZero, pe));
    def.channel = readChannel(ctx, *p, pe);
    if (const Json* t = member(*p, "texture"))
        def.texture = readTextureInfo(ctx, *t, TextureUsage::Data, pe + ".texture");
    return def;
}

uint32_t readOverrides(const LoadContext& ctx, const Json& layer, const std::string& e) {
    const Json* list = member(layer, "overrides");
    if (!list) return kLayerAll;
    if (!list->is_array()) ctx.fail(e + ".overrides", "expected an array of parameter names");
    static const std::pair<const char*, uint32_t> kNames[] = {{"albedo", kLayerAlbedo},
                                                              {"normal", kLayerNormal},
                                                              {"shininess", kLayerShininess},
                                                              {"metallic", kLayerMetallic},
                                                              {"cavity", kLayerCavity}};
    uint32_t bits = 0;
    for (const Json& name : *list) {
        uint32_t bit = 0;
        for (const auto& [n, b] : kNames) {
            if (name.is_string() && name.get<std::string>() == n) bit = b;
        }
        if (!bit) ctx.fail(e + ".overrides", name.dump() + "; expected albedo, normal, shininess, metallic or cavity");
        bits |= bit;
    }
    return bits;
}

MaterialLayer readLayer(LoadContext& ctx, const Json& layer, const std::string& e) {
    if (!layer.is_object()) ctx.fail(e, "expected a JSON object");
    checkKeys(ctx, layer, {"name", "albedo", "normal", "shininess", "metallic", "cavity", "overrides", "mask"}, e);
    MaterialLayer out;
    out.name = string(ctx, layer, "name", "", e);
    if (const Json* a = object(ctx, layer, "albedo", e)) {
        checkKeys(ctx, *a, {"factor", "texture"}, e + ".albedo");
        out.albedo.factor = numbers(ctx, *a, "factor", 4, glm::vec4(1.0f), e + ".albedo");
        if (const Json* t = member(*a, "texture")) {
            out.albedo.texture = readTextureInfo(ctx, *t, TextureUsage::Color, e + ".albedo.texture");
        }
    }
    if (const Json* n = object(ctx, layer, "normal", e)) {
        checkKeys(ctx, *n, {"scale", "texture"}, e + ".normal");
        out.normal.scale = static_cast<float>(number(ctx, *n, "scale", 1.0, e + ".normal"));
        if (const Json* t = member(*n, "texture")) {
            out.normal.texture = readTextureInfo(ctx, *t, TextureUsage::Normal, e + ".normal.texture");
        }
    }
    out.shininess = readScalar(ctx, layer, "shininess", ScalarParam{0.5f, 0.0f}, e);
    out.metallic = readScalar(ctx, layer, "metallic", ScalarParam{0.0f, 0.0f}, e);
    out.cavity = readScalar(ctx, layer, "cavity", ScalarParam{1.0f, 0.0f}, e);
    out.overrides = readOverrides(ctx, layer, e);
    if (const Json* m = object(ctx, layer, "mask", e)) {
        checkKeys(ctx, *m, {"factor", "channel", "texture"}, e + ".mask");
        out.mask.factor = static_cast<float>(number(ctx, *m, "factor", 1.0, e + ".mask"));
        out.mask.channel = readChannel(ctx, *m, e + ".mask");
        if (const Json* t = member(*m, "texture")) {
            out.mask.texture = readTextureInfo(ctx, *t, TextureUsage::Data, e + ".mask.texture");
        }
    }
    return out;
}

// The core metallic-roughness material as a one-layer stack (see gltf.hpp for the mapping). specGloss: the material's
// KHR_materials_pbrSpecularGlossiness, which replaces pbrMetallicRoughness (then only a fallback for other viewers).
MaterialLayer readMetallicRoughness(LoadContext& ctx, const Json& m, const std::string& e, const Json* specGloss) {
    MaterialLayer layer;
    layer.name = "base";
    float roughness = 1.0f, metallic = 1.0f;
    const Json* pbr = object(ctx, m, "pbrMetallicRoughness", e);
    if (pbr && specGloss) {
        // The fallback for viewers without the extension: its textures count as used (no "no material uses it"
        // warning) and go with the conversion's sources unless another material samples them.
        std::string pe = e + ".pbrMetallicRoughness";
        if (const Json* t = member(*pbr, "baseColorTexture"))
            ctx.specGlossSources.insert(
                readTextureInfo(ctx, *t, TextureUsage::Color, pe + ".baseColorTexture").texture);
        if (const Json* t = member(*pbr, "metallicRoughnessTexture")) {
            ctx.specGlossSources.insert(
                readTextureInfo(ctx, *t, TextureUsage::Data, pe + ".metallicRoughnessTexture").texture);
        }
    }
    if (pbr && !specGloss) {
        std::string pe = e + ".pbrMetallicRoughness";
        layer.albedo.factor = numbers(ctx, *pbr, "baseColorFactor", 4, glm::vec4(1.0f), pe);
        if (const Json* t = member(*pbr, "baseColorTexture")) {
            layer.albedo.texture = readTextureInfo(ctx, *t, TextureUsage::Color, pe + ".baseColorTexture");
        }
        metallic = static_cast<float>(number(ctx, *pbr, "metallicFactor", 1.0, pe));
        roughness = static_cast<float>(number(ctx, *pbr, "roughnessFactor", 1.0, pe));
        if (const Json* t = member(*pbr, "metallicRoughnessTexture")) {
            TextureRef ref = readTextureInfo(ctx, *t, TextureUsage::Data, pe + ".metallicRoughnessTexture");
            layer.shininess.texture = ref;
            layer.shininess.channel = 1;
            layer.metallic.texture = ref;
            layer.metallic.channel = 2;
        }
    }
    layer.shininess.factor = 1.0f - roughness;
    layer.shininess.atZero = 1.0f;
    layer.metallic.factor = metallic;
    if (specGloss) readSpecularGlossiness(ctx, *specGloss, e, layer);
    if (const Json* n = object(ctx, m, "normalTexture", e)) {
        layer.normal.texture = readTextureInfo(ctx, *n, TextureUsage::Normal, e + ".normalTexture");
        layer.normal.scale = static_cast<float>(number(ctx, *n, "scale", 1.0, e + ".normalTexture"));
    }
    if (const Json* o = object(ctx, m, "occlusionTexture", e)) {
        float strength = static_cast<float>(number(ctx, *o, "strength", 1.0, e + ".occlusionTexture"));
        layer.cavity = ScalarParam{1.0f, 1.0f - strength, {}, 0};
        layer.cavity.texture = readTextureInfo(ctx, *o, TextureUsage::Data, e + ".occlusionTexture");
    }
    return layer;
}

Material readMaterial(LoadContext& ctx, const Json& m, const std::string& e) {
    Material out;
    out.name = string(ctx, m, "name", "", e);
    const Json* extensions = object(ctx, m, "extensions", e);
    const Json* layers = extensions ? object(ctx, *extensions, kLayersExtension, e + ".extensions") : nullptr;
    if (layers) {
        std::string le = e + ".extensions." + kLayersExtension + ".layers";
        const Json* list = member(*layers, "layers");
        if (!list || !list->is_array() || list->empty()) ctx.fail(le, "expected a non-empty array of layers");
        for (size_t i = 0; i < list->size(); ++i)
            out.layers.push_back(readLayer(ctx, (*list)[i], le + "[" + std::to_string(i) + "]"));
    } else {
        const Json* specGloss = extensions ? object(ctx, *extensions, kSpecGloss, e + ".extensions") : nullptr;
        out.layers.push_back(readMetallicRoughness(ctx, m, e, specGloss));
    }
    out.emissiveFactor = glm::vec3(numbers(ctx, m, "emissiveFactor", 3, glm::vec4(0.0f), e));
    if (const Json* t = member(m, "emissiveTexture")) {
        out.emissiveTexture = readTextureInfo(ctx, *t, TextureUsage::Color, e + ".emissiveTexture");
    }
    if (extensions) {
        if (const Json* s = object(ctx, *extensions, kEmissiveStrength, e + ".extensions")) {
            out.emissiveStrength =
                static_cast<float>(number(ctx, *s, "emissiveStrength", 1.0, e + ".extensions." + kEmissiveStrength));
        }
    }
    if (extensions) {
        if (object(ctx, *extensions, kUnlit, e + ".extensions")) out.unlit = true;
        if (const Json* t = object(ctx, *extensions, kTransmission, e + ".extensions")) {
            std::string te = e + ".extensions." + kTransmission;
            out.transmission = static_cast<float>(number(ctx, *t, "transmissionFactor", 0.0, te));
            if (!(out.transmission >= 0.0f && out.transmission <= 1.0f))
                ctx.fail(te + ".transmissionFactor", "expected a number in [0, 1]");
            if (member(*t, "transmissionTexture")) ctx.warn(te + ".transmissionTexture", "not read; the factor is used");
        }
        if (const Json* i = object(ctx, *extensions, kIor, e + ".extensions")) {
            std::string ie = e + ".extensions." + kIor;
            out.ior = static_cast<float>(number(ctx, *i, "ior", 1.5, ie));
            if (!(out.ior == 0.0f || (out.ior >= 1.0f && out.ior <= 10.0f)))
                ctx.fail(ie + ".ior", "expected 0 or a number in [1, 10]");
        }
        if (const Json* sp = object(ctx, *extensions, kSpecular, e + ".extensions")) {
            std::string se = e + ".extensions." + kSpecular;
            out.specular = static_cast<float>(number(ctx, *sp, "specularFactor", 1.0, se));
            if (!(out.specular >= 0.0f && out.specular <= 1.0f))
                ctx.fail(se + ".specularFactor", "expected a number in [0, 1]");
            out.specularColor = glm::vec3(numbers(ctx, *sp, "specularColorFactor", 3, glm::vec4(1.0f), se));
            for (int c = 0; c < 3; ++c) {
                if (!(out.specularColor[c] >= 0.0f))
                    ctx.fail(se + ".specularColorFactor[" + std::to_string(c) + "]", "expected a number >= 0");
            }
            if (const Json* t = member(*sp, "specularTexture"))
                out.specularTexture = readTextureInfo(ctx, *t, TextureUsage::Data, se + ".specularTexture");
            if (const Json* t = member(*sp, "specularColorTexture"))
                out.specularColorTexture = readTextureInfo(ctx, *t, TextureUsage::Color, se + ".specularColorTexture");
        }
        if (const Json* cc = object(ctx, *extensions, kClearcoat, e + ".extensions")) {
            std::string ce = e + ".extensions." + kClearcoat;
            out.clearcoat = static_cast<float>(number(ctx, *cc, "clearcoatFactor", 0.0, ce));
            if (!(out.clearcoat >= 0.0f && out.clearcoat <= 1.0f))
                ctx.fail(ce + ".clearcoatFactor", "expected a number in [0, 1]");
            out.clearcoatRoughness = static_cast<float>(number(ctx, *cc, "clearcoatRoughnessFactor", 0.0, ce));
            if (!(out.clearcoatRoughness >= 0.0f && out.clearcoatRoughness <= 1.0f))
                ctx.fail(ce + ".clearcoatRoughnessFactor", "expected a number in [0, 1]");
            if (const Json* t = member(*cc, "clearcoatTexture"))
                out.clearcoatTexture = readTextureInfo(ctx, *t, TextureUsage::Data, ce + ".clearcoatTexture");
            if (const Json* t = member(*cc, "clearcoatRoughnessTexture"))
                out.clearcoatRoughnessTexture =
                    readTextureInfo(ctx, *t, TextureUsage::Data, ce + ".clearcoatRoughnessTexture");
            if (const Json* n = object(ctx, *cc, "clearcoatNormalTexture", ce)) {
                out.clearcoatNormal.texture =
                    readTextureInfo(ctx, *n, TextureUsage::Normal, ce + ".clearcoatNormalTexture");
                out.clearcoatNormal.scale =
                    static_cast<float>(number(ctx, *n, "scale", 1.0, ce + ".clearcoatNormalTexture"));
            }
        }
        if (const Json* sh = object(ctx, *extensions, kSheen, e + ".extensions")) {
            std::string she = e + ".extensions." + kSheen;
            out.sheenColor = glm::vec3(numbers(ctx, *sh, "sheenColorFactor", 3, glm::vec4(0.0f), she));
            for (int c = 0; c < 3; ++c) {
                if (!(out.sheenColor[c] >= 0.0f && out.sheenColor[c] <= 1.0f))
                    ctx.fail(she + ".sheenColorFactor[" + std::to_string(c) + "]", "expected a number in [0, 1]");
            }
            out.sheenRoughness = static_cast<float>(number(ctx, *sh, "sheenRoughnessFactor", 0.0, she));
            if (!(out.sheenRoughness >= 0.0f && out.sheenRoughness <= 1.0f))
                ctx.fail(she + ".sheenRoughnessFactor", "expected a number in [0, 1]");
            if (const Json* t = member(*sh, "sheenColorTexture"))
                out.sheenColorTexture = readTextureInfo(ctx, *t, TextureUsage::Color, she + ".sheenColorTexture");
            if (const Json* t = member(*sh, "sheenRoughnessTexture"))
                out.sheenRoughnessTexture =
                    readTextureInfo(ctx, *t, TextureUsage::Data, she + ".sheenRoughnessTexture");
        }
        if (const Json* v = object(ctx, *extensions, kVolume, e + ".extensions")) {
            std::string ve = e + ".extensions." + kVolume;
            out.thickness = static_cast<float>(number(ctx, *v, "thicknessFactor", 0.0, ve));
            if (!(out.thickness >= 0.0f && std::isfinite(out.thickness)))
                ctx.fail(ve + ".thicknessFactor", "expected a number >= 0");
            if (const Json* t = member(*v, "thicknessTexture"))
                out.thicknessTexture = readTextureInfo(ctx, *t, TextureUsage::Data, ve + ".thicknessTexture");
            // JSON has no infinity: the default (+inf, no attenuation) is the property's absence.
            out.attenuationDistance = static_cast<float>(
                number(ctx, *v, "attenuationDistance", std::numeric_limits<double>::infinity(), ve));
            if (!(out.attenuationDistance > 0.0f))
                ctx.fail(ve + ".attenuationDistance", "expected a number > 0");
            out.attenuationColor = glm::vec3(numbers(ctx, *v, "attenuationColor", 3, glm::vec4(1.0f), ve));
            for (int c = 0; c < 3; ++c) {
                if (!(out.attenuationColor[c] >= 0.0f && out.attenuationColor[c] <= 1.0f))
                    ctx.fail(ve + ".attenuationColor[" + std::to_string(c) + "]", "expected a number in [0, 1]");
            }
        }
    }
    std::string mode = string(ctx, m, "alphaMode", "OPAQUE", e);
    if (mode == "OPAQUE")
        out.alphaMode = AlphaMode::Opaque;
    else if (mode == "MASK")
        out.alphaMode = AlphaMode::Mask;
    else if (mode == "BLEND")
        out.alphaMode = AlphaMode::Blend;
    else
        ctx.fail(e + ".alphaMode", "'" + mode + "'; expected OPAQUE, MASK or BLEND");
    out.alphaCutoff = static_cast<float>(number(ctx, m, "alphaCutoff", 0.5, e));
    out.doubleSided = boolean(ctx, m, "doubleSided", false, e);
    return out;
}

// One warning per material extension of kIgnoredMaterialExtensions the file uses, at its extensionsUsed entry (or at
// the first material using it when extensionsUsed lacks it), naming what is not drawn and the materials concerned.
void warnIgnoredMaterialExtensions(const LoadContext& ctx, const Json* materials) {
    const Json* used = member(ctx.doc, "extensionsUsed");
    for (const IgnoredMaterialExtension& ext : kIgnoredMaterialExtensions) {
        std::string users, first;
        size_t count = 0;
        for (size_t i = 0; materials && i < materials->size(); ++i) {
            const Json* extensions = member((*materials)[i], "extensions");
            if (!extensions || !extensions->is_object() || !member(*extensions, ext.name)) continue;
            std::string e = "materials[" + std::to_string(i) + "]";
            if (first.empty()) first = e + ".extensions." + ext.name;
            if (++count <= 8) users += (users.empty() ? "" : ", ") + e;
        }
        if (count > 8) users += " and " + std::to_string(count - 8) + " more";
        std::string element = first;
        for (size_t i = 0; used && used->is_array() && i < used->size(); ++i) {
            if ((*used)[i] == ext.name) element = "extensionsUsed[" + std::to_string(i) + "]";
        }
        if (element.empty()) continue; // neither listed nor used
        if (count == 0) {
            ctx.warn(element, std::string("extension '") + ext.name +
                                  "' is not supported by vitrine; no material uses it (vitrine would ignore " +
                                  ext.ignored + ")");
        } else {
            ctx.warn(element, std::string("extension '") + ext.name + "' is not supported by vitrine: " + ext.ignored +
                                  " of " + users + " is ignored; drawn with the rest of the material");
        }
    }
}

} // namespace

TextureRef readTextureInfo(LoadContext& ctx, const Json& info, TextureUsage usage, const std::string& e) {
    if (!info.is_object()) ctx.fail(e, "expected a textureInfo object {\"index\": ...}");
    const Json* index = member(info, "index");
    if (!index) ctx.fail(e + ".index", "missing; expected an index into textures");
    uint32_t gltfIndex = checkIndex(ctx, *index, e + ".index", "textures");
    TextureRef ref;
    int64_t uvSet = integer(ctx, info, "texCoord", 0, e);
    if (const Json* ext = object(ctx, info, "extensions", e)) {
        if (const Json* tt = object(ctx, *ext, kTextureTransform, e + ".extensions")) {
            std::string te = e + ".extensions." + kTextureTransform;
            ref.transform.offset = glm::vec2(numbers(ctx, *tt, "offset", 2, glm::vec4(0.0f), te));
            ref.transform.scale = glm::vec2(numbers(ctx, *tt, "scale", 2, glm::vec4(1.0f), te));
            ref.transform.rotation = static_cast<float>(number(ctx, *tt, "rotation", 0.0, te));
            uvSet = integer(ctx, *tt, "texCoord", uvSet, te); // the extension overrides textureInfo.texCoord
        }
    }
    if (uvSet < 0) ctx.fail(e + ".texCoord", std::to_string(uvSet) + "; expected a TEXCOORD_n set, n >= 0");
    if (uvSet > 1) { // legal; a third UV set is rare enough that vitrine's vertices keep two
        ctx.warn(e + ".texCoord",
                 std::to_string(uvSet) + ": vitrine keeps TEXCOORD_0 and TEXCOORD_1; drawn without this texture");
        return ref;
    }
    ref.uvSet = static_cast<uint32_t>(uvSet);
    ref.texture = resolveTexture(ctx, gltfIndex, usage);
    return ref;
}

Json writeTextureInfo(const TextureRef& ref, int textureIndex) {
    Json info = {{"index", textureIndex}};
    if (ref.uvSet != 0) info["texCoord"] = ref.uvSet;
    if (!ref.transform.isIdentity()) {
        info["extensions"][kTextureTransform] = {{"offset", {ref.transform.offset.x, ref.transform.offset.y}},
                                                 {"scale", {ref.transform.scale.x, ref.transform.scale.y}},
                                                 {"rotation", ref.transform.rotation}};
    }
    return info;
}

void loadImagesAndTextures(LoadContext& ctx) {
    const tinygltf::Model& model = *ctx.model;
    Scene& scene = *ctx.scene;
    // Images tinygltf could not decode (decodeOrLeaveEmpty: WebP, KTX2, damaged data) are left out, with a warning;
    // textures of theirs, and textures without a source, are drawn as if absent.
    std::vector<int32_t> sceneImage(model.images.size(), -1);
    for (size_t i = 0; i < model.images.size(); ++i) {
        const tinygltf::Image& image = model.images[i];
        if (image.image.empty() && image.width <= 0) {
            ctx.warn("images[" + std::to_string(i) + "]",
                     "could not be decoded" + (image.uri.empty() ? std::string() : " ('" + image.uri + "')") +
                         (image.mimeType.empty() ? std::string() : " (" + image.mimeType + ")") +
                         ": vitrine reads PNG and JPEG (not WebP, KTX2 or damaged data); textures using it are drawn "
                         "without it");
            continue;
        }
        sceneImage[i] = static_cast<int32_t>(scene.images.size());
        scene.images.push_back(toImage(ctx, image, i));
    }

    std::vector<Sampler> samplers;
    for (const tinygltf::Sampler& s : model.samplers)
        samplers.push_back(toSampler(s));

    const Json* docTextures = member(ctx.doc, "textures");
    ctx.textureByUsage.assign(model.textures.size(), {-1, -1, -1});
    ctx.sceneTexture.assign(model.textures.size(), -1);
    for (size_t i = 0; i < model.textures.size(); ++i) {
        const tinygltf::Texture& t = model.textures[i];
        std::string e = "textures[" + std::to_string(i) + "]";
        if (t.source < 0) { // legal: a texture-source extension may supply the image
            ctx.warn(e + ".source",
                     "missing (texture-source extensions such as KHR_texture_basisu and EXT_texture_webp "
                     "are not read); materials using this texture are drawn without it");
            continue;
        }
        if (sceneImage[t.source] < 0) continue; // its image was left out, with a warning
        Texture texture;
        texture.name = t.name;
        texture.image = static_cast<uint32_t>(sceneImage[t.source]);
        if (t.sampler >= 0) texture.sampler = samplers[t.sampler];
        // exportGlb() records the usage so that a texture no material uses still comes back the same.
        if (const Json* extras = object(ctx, (*docTextures)[i], "extras", e)) {
            if (const Json* ours = object(ctx, *extras, kExtrasKey, e + ".extras")) {
                std::string usage = string(ctx, *ours, "usage", "", e + ".extras.vitrine");
                for (TextureUsage u : {TextureUsage::Color, TextureUsage::Normal, TextureUsage::Data}) {
                    if (usage == usageName(u)) {
                        texture.usage = u;
                        ctx.textureByUsage[i][static_cast<int>(u)] = static_cast<int32_t>(scene.textures.size());
                    }
                }
            }
        }
        ctx.sceneTexture[i] = static_cast<int32_t>(scene.textures.size());
        scene.textures.push_back(texture);
    }
}

void loadMaterials(LoadContext& ctx) {
    readVariants(ctx);
    const Json* materials = member(ctx.doc, "materials");
    if (materials && !materials->is_array()) ctx.fail("materials", "expected an array");
    for (size_t i = 0; materials && i < materials->size(); ++i) {
        std::string e = "materials[" + std::to_string(i) + "]";
        if (!(*materials)[i].is_object()) ctx.fail(e, "expected a JSON object");
        ctx.scene->materials.push_back(readMaterial(ctx, (*materials)[i], e));
    }
    warnIgnoredMaterialExtensions(ctx, materials);
    for (size_t i = 0; i < ctx.textureByUsage.size(); ++i) {
        const auto& u = ctx.textureByUsage[i];
        if (u[0] < 0 && u[1] < 0 && u[2] < 0 && ctx.sceneTexture[i] >= 0) {
            ctx.warn("textures[" + std::to_string(i) + "]", "no material uses it; kept as linear data");
        }
    }
    dropSpecGlossSources(ctx);
}

} // namespace vitrine::scene::gltf
