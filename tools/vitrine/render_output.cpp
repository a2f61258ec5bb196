#include "tools/vitrine/render_output.hpp"

#include "core/base/error.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/compiler.hpp"
#include "core/graph/executor.hpp"

#include <algorithm>
#include <chrono>
#include <cctype>
#include <filesystem>

namespace vitrine::cli {

ContextOptions contextOptions(const Args& args) {
    ContextOptions o;
    o.device = args.get("device");
    o.validation = args.has("validate");
    return o;
}

std::vector<std::string> setsWithFrames(const Args& args, uint32_t frames, bool keepWrite, const std::string& graph) {
    std::vector<std::string> sets;
    if (args.has("scene") && !graph.empty()) {
        const std::string file = args.get("scene");
        std::error_code ec;
        if (file.empty() || !std::filesystem::is_regular_file(file, ec))
            throw UserError("--scene " + file + ": file not found; expected a .gltf or .glb file");
        const nlohmann::json doc = loadGraphDocument(graph);
        std::vector<std::string> ids;
        if (doc.contains("nodes") && doc["nodes"].is_object())
            for (const auto& [id, node] : doc["nodes"].items())
                if (node.is_object() && node.contains("type") && node["type"].is_string() &&
                    node["type"].get<std::string>().rfind("scene.", 0) == 0)
                    ids.push_back(id);
        if (ids.size() != 1) {
            std::string list;
            for (const std::string& id : ids)
                list += (list.empty() ? "" : ", ") + id;
            throw UserError(graph + ": --scene: expected exactly one scene node (type scene.*) to replace, found " +
                            std::to_string(ids.size()) + (list.empty() ? "" : " (" + list + ")"));
        }
        nlohmann::json node = {{"type", "scene.gltf"},
                               {"params", {{"path", std::filesystem::absolute(file).lexically_normal().string()}}}};
        if (args.has("strict")) node["params"]["strict"] = true;
        // The graph's look stays: a scene.gltf node's key light (a choice of lighting, not of the file) is kept.
        const nlohmann::json& old = doc["nodes"][ids[0]];
        if (old["type"] == "scene.gltf" && old.contains("params") && old["params"].is_object())
            for (const char* key : {"key_light", "key_light_elevation", "key_light_azimuth"})
                if (old["params"].contains(key)) node["params"][key] = old["params"][key];
        sets.push_back(ids[0] + "=" + node.dump());
    } else if (args.has("strict") && !graph.empty()) {
        // --strict without --scene: every scene.gltf node of the graph loads strictly.
        const nlohmann::json doc = loadGraphDocument(graph);
        size_t count = 0;
        if (doc.contains("nodes") && doc["nodes"].is_object())
            for (const auto& [id, node] : doc["nodes"].items())
                if (node.is_object() && node.contains("type") && node["type"] == "scene.gltf")
                    sets.push_back(id + ".params.strict=true"), ++count;
        if (count == 0) throw UserError(graph + ": --strict: the graph has no scene.gltf node (and no --scene FILE)");
    }
    if (frames > 0) {
        sets.push_back("frame.frames=" + std::to_string(frames));
        if (!keepWrite) sets.push_back("frame.write=[" + std::to_string(frames - 1) + "]");
    }
    const std::vector<std::string>& given = args.all("set");
    sets.insert(sets.end(), given.begin(), given.end());
    return sets;
}

std::string deviceClass(const Context& ctx) {
    std::string name = ctx.deviceInfo().name;
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
    return name.find("llvmpipe") != std::string::npos || name.find("lavapipe") != std::string::npos ? "lavapipe"
                                                                                                    : "gpu";
}

std::string pickOutput(const GraphDesc& desc, const std::string& requested) {
    if (desc.outputs.empty()) throw UserError(desc.where("/outputs") + ": expected at least one output");
    if (requested.empty()) {
        // Outputs are kept sorted by name (JSON objects), so "first" would favour "debug/..." over the
        // image the graph is about: an output called "final" wins, then the first one without a '/'.
        for (const OutputDecl& o : desc.outputs)
            if (o.name == "final") return o.name;
        for (const OutputDecl& o : desc.outputs)
            if (o.name.find('/') == std::string::npos) return o.name;
        return desc.outputs.front().name;
    }
    std::string names;
    for (const OutputDecl& o : desc.outputs) {
        if (o.name == requested) return requested;
        names += (names.empty() ? "" : ", ") + o.name;
    }
    throw UserError(desc.where("/outputs") + ": --output " + requested + ": no such output; the graph has " + names);
}

double sceneBuildMs(const CompiledGraph& graph) {
    double ms = 0.0;
    auto outputsScene = [&](const PassUse& u) {
        return u.output && graph.resources[u.resource].kind == PortKind::Scene;
    };
    for (const CompiledPass& p : graph.passes)
        if (std::any_of(p.uses.begin(), p.uses.end(), outputsScene)) ms += p.setupMs;
    return ms;
}

std::map<uint32_t, Image> renderOutput(Context& ctx, ShaderCompiler& shaders, GraphDesc desc, const std::string& output,
                                       uint32_t frameCount, const std::vector<uint32_t>& frames, bool progress,
                                       RenderStats* stats, std::function<bool()> stop) {
    using Clock = std::chrono::steady_clock;
    auto ms = [](Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); };
    std::erase_if(desc.outputs, [&](const OutputDecl& o) { return o.name != output; });
    desc.frame.frames = frameCount;
    desc.frame.write = frames;
    auto t = Clock::now();
    CompiledGraph graph = compileGraph(std::move(desc));
    if (stats) {
        stats->compileMs = ms(t);
        stats->sceneBuildMs = sceneBuildMs(graph);
    }
    Executor executor(ctx, graph, shaders);
    std::map<uint32_t, Image> images;
    RunOptions options;
    options.frames = frameCount;
    options.write = frames;
    options.progress = progress;
    options.onOutput = [&](uint32_t frame, const std::string&, const Image& image) { images[frame] = image; };
    options.stop = std::move(stop);
    t = Clock::now();
    executor.run(options);
    if (stats) {
        stats->runMs = ms(t);
        stats->pipelineMs = executor.pipelineMs();
        stats->memory = executor.memory();
        stats->timings = executor.timings();
        stats->passIds.clear();
        for (const CompiledPass& p : graph.passes) stats->passIds.push_back(p.id);
    }
    return images;
}

} // namespace vitrine::cli
