// vitrine export-scene: writes a built-in scene (or re-writes a glTF file) as a .glb other tools open.
#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/scene/gltf.hpp"
#include "core/scene/museum.hpp"
#include "tools/vitrine/cli.hpp"

#include <cstdio>
#include <filesystem>

namespace vitrine::cli {

int exportSceneCommand(const Args& args) {
    if (args.positional.size() != 2)
        throw UserError("export-scene: expected `export-scene museum|FILE.gltf|FILE.glb OUT.glb`");
    const std::string& source = args.positional[0];
    std::filesystem::path out = args.positional[1];
    if (out.extension() != ".glb") throw UserError("export-scene: " + out.string() + ": expected a .glb output path");
    if (std::filesystem::exists(out) && !args.has("force"))
        throw UserError("export-scene: " + out.string() + " exists; pass --force to replace it");
    scene::Scene s;
    if (source == "museum") {
        scene::MuseumOptions options;
        options.seed = args.getUint("seed", 1);
        options.textureSize = args.getUint("texture-size", 1024);
        s = scene::buildMuseum(options);
    } else {
        s = scene::loadGltfReporting(source, args.has("strict"));
    }
    if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
    scene::exportGlb(s, out);
    std::printf("wrote %s: %zu triangles, %zu materials, %zu textures, %zu camera paths, %.1f MiB\n", out.string().c_str(),
                s.triangleCount(), s.materials.size(), s.textures.size(), s.cameraPaths.size(),
                static_cast<double>(std::filesystem::file_size(out)) / (1024.0 * 1024.0));
    return 0;
}

} // namespace vitrine::cli
