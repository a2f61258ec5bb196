// scene.gltf: a glTF 2.0 scene (.gltf or .glb) through core/scene's loader.
#include "core/base/error.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gltf.hpp"
#include "nodes/scene/scene_node.hpp"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "scene.gltf";
    s.doc = "A glTF 2.0 file: meshes, metallic-roughness or VITRINE_material_layers materials, cameras, animations, "
            "KHR_texture_transform, KHR_materials_emissive_strength, _unlit, _transmission, _ior, _specular, "
            "_clearcoat, _sheen, _volume, _variants, "
            "_pbrSpecularGlossiness (converted to metallic-roughness), KHR_lights_punctual, node and morph-weight "
            "animations, morph targets, skins.";
    s.pass = PassKind::Transfer;
    s.params = {{"path", ParamType::Path, "", {}, {}, {}, "The .gltf or .glb file (relative to the graph file)"},
                {"strict", ParamType::Bool, false, {}, {}, {},
                 "Refuse the file when loading it gives warnings (what vitrine ignores: unsupported extensions in "
                 "extensionsUsed, point and line primitives, unused attributes, ...) instead of printing them; "
                 "`--strict` on the command line"},
                {"material_variant", ParamType::String, "", {}, {}, {},
                 "KHR_materials_variants: the variant (by name) whose materials the primitives get; empty: their "
                 "default materials. A name the file does not define is an error listing its variants"},
                {"key_light", ParamType::Bool, false, {}, {}, {},
                 "When the file has no directional light, give the scene a sun (the one shadowed light, whose "
                 "direction the sky nodes given the scene and shadow.directional follow) from the camera side: key_light_elevation "
                 "above the horizon, key_light_azimuth to the right of the direction back to the first frame's camera. "
                 "Off: such a file's sun comes from the sky node's params"},
                {"key_light_elevation", ParamType::Float, 35.0, 0.0, 90.0, {},
                 "key_light: degrees above the horizon"},
                {"key_light_azimuth", ParamType::Float, 30.0, -180.0, 180.0, {},
                 "key_light: degrees to the right (seen from the camera) of the direction back to the camera"}};
    addSceneNodeSchema(s);
    return s;
}

class Gltf final : public SceneNode {
public:
    void setup(SetupContext& ctx) override {
        std::string path = ctx.params().getString("path");
        if (path.empty()) ctx.failParam("path", "expected the path of a .gltf or .glb file");
        std::filesystem::path file = ctx.resolvePath(path);
        if (!std::filesystem::exists(file)) ctx.failParam("path", "file not found: " + file.string());
        std::shared_ptr<const scene::Scene> scene;
        try {
            scene = std::make_shared<const scene::Scene>(scene::loadGltfReporting(
                file, ctx.params().getBool("strict"), ctx.params().getString("material_variant")));
        } catch (const scene::UnknownMaterialVariant& e) {
            ctx.failParam("material_variant", e.what());
        } catch (const UserError& e) {
            // The glTF error names its file and element; the graph's file and param say where the path came from.
            ctx.failParam("path", e.what());
        }
        mKeyLight.on = ctx.params().getBool("key_light");
        mKeyLight.elevation = ctx.params().getFloat("key_light_elevation");
        mKeyLight.azimuth = ctx.params().getFloat("key_light_azimuth");
        publish(ctx, std::move(scene));
    }
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Gltf>(); });

} // namespace
} // namespace vitrine
