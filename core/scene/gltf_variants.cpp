// KHR_materials_variants: the file names variants at the top level; a primitive maps some of them to other materials.
// The caller picks one variant by name at load time (scene.gltf's material_variant); nothing else is kept.

#include "core/scene/gltf.hpp"
#include "core/scene/gltf_detail.hpp"

namespace vitrine::scene::gltf {

namespace {

// The top-level variant names ({} when the file has none).
std::vector<std::string> variantNames(const LoadContext& ctx) {
    std::vector<std::string> names;
    const Json* ext = object(ctx, ctx.doc, "extensions", "");
    const Json* variants = ext ? object(ctx, *ext, kVariants, "extensions") : nullptr;
    if (!variants) return names;
    std::string e = std::string("extensions.") + kVariants + ".variants";
    const Json* list = member(*variants, "variants");
    if (!list || !list->is_array() || list->empty()) ctx.fail(e, "expected a non-empty array of {\"name\": ...}");
    for (size_t i = 0; i < list->size(); ++i) {
        std::string ve = e + "[" + std::to_string(i) + "]";
        if (!(*list)[i].is_object()) ctx.fail(ve, "expected a JSON object {\"name\": ...}");
        if (!member((*list)[i], "name")) ctx.fail(ve + ".name", "missing; expected the variant's name");
        names.push_back(string(ctx, (*list)[i], "name", "", ve));
    }
    return names;
}

} // namespace

void readVariants(LoadContext& ctx) {
    std::vector<std::string> names = variantNames(ctx);
    ctx.variantCount = names.size();
    if (ctx.materialVariant.empty()) return;
    if (names.empty()) {
        throw UnknownMaterialVariant(ctx.message(kVariants, "material_variant '" + ctx.materialVariant +
                                                                "' asked for, but the file defines no material "
                                                                "variants (no top-level " +
                                                                std::string(kVariants) + " extension)"));
    }
    for (size_t i = 0; i < names.size(); ++i) {
        if (names[i] == ctx.materialVariant) {
            ctx.variantIndex = static_cast<int32_t>(i);
            return;
        }
    }
    std::string list;
    for (const std::string& n : names)
        list += (list.empty() ? "'" : ", '") + n + "'";
    throw UnknownMaterialVariant(
        ctx.message(std::string("extensions.") + kVariants + ".variants",
                    "no variant named '" + ctx.materialVariant + "' (material_variant); the file's variants: " + list));
}

int variantMaterial(const LoadContext& ctx, const Json& primitive, int material, const std::string& element) {
    if (ctx.variantIndex < 0) return material;
    const Json* ext = object(ctx, primitive, "extensions", element);
    const Json* ours = ext ? object(ctx, *ext, kVariants, element + ".extensions") : nullptr;
    if (!ours) return material;
    std::string e = element + ".extensions." + kVariants + ".mappings";
    const Json* mappings = member(*ours, "mappings");
    if (!mappings || !mappings->is_array())
        ctx.fail(e, "expected an array of {\"material\": ..., \"variants\": [...]}");
    // Every mapping is checked, not only up to the one that applies.
    int chosen = material;
    for (size_t i = 0; i < mappings->size(); ++i) {
        std::string me = e + "[" + std::to_string(i) + "]";
        const Json& mapping = (*mappings)[i];
        if (!mapping.is_object()) ctx.fail(me, "expected a JSON object");
        const Json* variants = member(mapping, "variants");
        if (!variants || !variants->is_array()) ctx.fail(me + ".variants", "expected an array of variant indices");
        const Json* m = member(mapping, "material");
        if (!m) ctx.fail(me + ".material", "missing; expected an index into materials");
        int mapped = static_cast<int>(checkIndex(ctx, *m, me + ".material", "materials"));
        for (const Json& v : *variants) {
            if (!v.is_number_integer() || v.get<int64_t>() < 0 || v.get<uint64_t>() >= ctx.variantCount) {
                ctx.fail(me + ".variants", v.dump() + "; expected an index into the file's " +
                                               std::to_string(ctx.variantCount) + " variants");
            }
            if (v.get<int64_t>() == ctx.variantIndex) chosen = mapped;
        }
    }
    return chosen;
}

} // namespace vitrine::scene::gltf
