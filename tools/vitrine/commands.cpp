#include "core/base/atomic_file.hpp"
#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/formats.hpp"
#include "core/graph/compiler.hpp"
#include "core/graph/executor.hpp"
#include "core/graph/json_schema.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"
#include "core/image/io.hpp"
#include "core/scene/gpu_scene.hpp"
#include "core/shader/compiler.hpp"
#include "tools/vitrine/bench_bvh.hpp"
#include "tools/vitrine/cli.hpp"
#include "tools/vitrine/interrupt.hpp"
#include "tools/vitrine/output_dir.hpp"
#include "tools/vitrine/render_output.hpp"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <future>
#include <iostream>
#include <map>
#include <memory>
#include <set>

namespace vitrine::cli {

namespace fs = std::filesystem;

namespace {

std::string graphArg(const Args& args) {
    if (args.positional.size() != 1) throw UserError(args.command + ": expected one GRAPH file argument");
    return args.positional[0];
}

// `frames`: the frame count the command runs (0: --frames N, else the graph's own); see setsWithFrames().
CompiledGraph compileFromArgs(const Args& args, uint32_t frames = 0) {
    if (frames == 0 && args.has("frames")) {
        frames = args.getUint("frames", 1);
        if (frames == 0) throw UserError("--frames: expected at least 1");
    }
    return compileGraph(loadGraph(graphArg(args), setsWithFrames(args, frames, args.has("write-all"), graphArg(args))));
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string mib(uint64_t bytes) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
    return buf;
}

} // namespace

int runCommand(const Args& args) {
    const auto start = std::chrono::steady_clock::now();
    const auto msSince = [](std::chrono::steady_clock::time_point t) {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
    };
    // The Vulkan instance and device come up on another core while the graph compiles (the scene build): neither
    // needs the other, and each is a large part of the start (README "Caches"). A failure of either is reported
    // when it is needed, the graph's first.
    std::future<std::unique_ptr<Context>> pendingContext =
        std::async(std::launch::async, [options = contextOptions(args)] { return std::make_unique<Context>(options); });
    CompiledGraph graph = compileFromArgs(args);
    const double compileMs = msSince(start);
    std::string exrMode = args.get("exr", "half");
    if (exrMode != "half" && exrMode != "float" && exrMode != "none")
        throw UserError("--exr: expected half, float or none, got '" + exrMode + "'");
    // --scene FILE: out/<FILE's stem> unless --out says otherwise.
    fs::path stem = fs::path(args.has("scene") ? args.get("scene") : graphArg(args)).stem();
    fs::path outDir = args.get("out", (fs::path("out") / stem).string());
    OutputDir out(outDir, args.has("overwrite") || args.has("force"));

    const std::unique_ptr<Context> context = pendingContext.get();
    Context& ctx = *context;
    logInfo("device: " + ctx.deviceInfo().name + "; " + std::to_string(graph.passes.size()) + " passes, " +
            std::to_string(graph.desc.frame.width) + "x" + std::to_string(graph.desc.frame.height) + ", " +
            std::to_string(graph.desc.frame.frames) + " frame(s)");
    ShaderCompiler shaders;
    Executor executor(ctx, graph, shaders);
    // Start-up cost (warm starts, README "Caches"): everything before the first pass is recorded.
    char ready[200];
    std::snprintf(ready, sizeof ready,
                  "first pass after %.0f ms: graph compile %.0f ms (scene build %.0f ms), pipelines %.0f ms", msSince(start),
                  compileMs, sceneBuildMs(graph), executor.pipelineMs());
    logDebug(ready);

    const bool single = graph.desc.frame.write.size() == 1;
    std::vector<std::pair<std::string, Image>> layers; // the outputs of the frame being written
    RunOptions options;
    options.progress = !args.has("quiet");
    options.onOutput = [&](uint32_t frame, const std::string& name, const Image& image) {
        char suffix[16];
        std::snprintf(suffix, sizeof suffix, ".%04u", frame);
        fs::path png = out.claim(name + (single ? "" : suffix) + ".png");
        writePng(png, image);
        if (exrMode == "none") return;
        layers.push_back({name, image});
        if (layers.size() < graph.outputs.size()) return;
        // The frame's last output: its EXR now, so that a stopped run has every finished frame complete.
        char exrName[32];
        std::snprintf(exrName, sizeof exrName, "frame.%04u.exr", frame);
        std::vector<ExrLayer> exr;
        for (const auto& [layer, layerImage] : layers) exr.push_back({layer, &layerImage});
        writeExr(out.claim(exrName), exr, exrMode == "float" ? ExrPixelType::Float : ExrPixelType::Half);
        layers.clear();
    };
    InterruptHandlers interrupts;
    options.stop = [] { return InterruptHandlers::received() != 0; };
    const uint32_t ran = executor.run(options);
    if (int signal = InterruptHandlers::received(); signal) {
        // A signal during the last frame still stops what in that frame can stop early (a converging path tracer
        // keeps its partial result for the next run), so the run did not do all it was asked either.
        const std::string what = signal == SIGINT ? "interrupted (SIGINT)" : "terminated (SIGTERM)";
        if (ran < graph.desc.frame.frames)
            logWarning(what + ": stopped after " + std::to_string(ran) + " of " +
                       std::to_string(graph.desc.frame.frames) + " frames; the files of the finished frames are in " +
                       out.dir().string());
        else
            logWarning(what + " during the last frame, which finished with what it had; its files are in " +
                       out.dir().string());
        return kExitInterrupted;
    }
    if (ctx.validationMessageCount() > 0) {
        logWarning(std::to_string(ctx.validationMessageCount()) + " Vulkan validation message(s)");
        return 2;
    }
    logInfo("wrote " + std::to_string(graph.outputs.size()) + " output(s) of " +
            std::to_string(graph.desc.frame.write.size()) + " frame(s) to " + out.dir().string());
    return 0;
}

int validateCommand(const Args& args) {
    {
        // Every error the document has at once (each param, input and output checked on its own), as the editor
        // shows them; with one, the compile below reports it (and what only compiling finds).
        const std::string file = graphArg(args);
        nlohmann::json document = loadGraphDocument(file, setsWithFrames(args, 0, args.has("write-all"), file));
        std::vector<std::string> errors = validateGraphErrors(document, file, NodeRegistry::global());
        if (errors.size() > 1) {
            for (const std::string& e : errors) log(LogLevel::Error, e);
            log(LogLevel::Error, std::to_string(errors.size()) + " errors");
            return 1;
        }
    }
    CompiledGraph graph = compileFromArgs(args);
    std::printf("%s: ok: %zu passes, %zu textures, %zu output(s)", graphArg(args).c_str(), graph.passes.size(),
                graph.resources.size(), graph.outputs.size());
    if (!graph.culled.empty()) {
        std::printf("; culled (no output needs them):");
        for (const auto& c : graph.culled) std::printf(" %s", c.c_str());
    }
    std::printf("\n");
    return 0;
}

int nodesCommand(const Args& args) {
    const NodeRegistry& registry = NodeRegistry::global();
    if (args.has("json")) {
        const std::string path = args.get("json");
        const std::string text = registry.toJson().dump(2) + "\n";
        if (path.empty() || path == "-") std::cout << text;
        else writeFileAtomically(path, text);
        return 0;
    }
    for (const NodeSchema* s : registry.all()) {
        std::printf("%s\n    %s\n", s->type.c_str(), s->doc.c_str());
        for (const auto& in : s->inputs)
            std::printf("    in  %-14s %s%s: %s\n", in.name.c_str(), toString(in.kind), in.optional ? " (optional)" : "",
                        in.doc.c_str());
        for (const auto& o : s->outputs)
            std::printf("    out %-14s %s %s: %s\n", o.name.c_str(), toString(o.kind),
                        o.formatFrom.empty() ? formatName(o.format).c_str() : ("as " + o.formatFrom).c_str(), o.doc.c_str());
        for (const auto& p : s->params)
            std::printf("    param %-12s %s = %s: %s\n", p.name.c_str(), toString(p.type), p.defaultValue.dump().c_str(),
                        p.doc.c_str());
    }
    return 0;
}

int schemaCommand(const Args& args) {
    const std::string text = graphJsonSchema(NodeRegistry::global()).dump(2) + "\n";
    const std::string path = args.get("out");
    if (path.empty() || path == "-") std::cout << text;
    else writeFileAtomically(path, text);
    return 0;
}

int benchCommand(const Args& args) {
    const uint32_t frames = args.getUint("frames", 20);
    const uint32_t warmup = args.getUint("warmup", 2);
    if (frames == 0) throw UserError("--frames: expected at least 1");
    auto compileStart = std::chrono::steady_clock::now();
    CompiledGraph graph = compileFromArgs(args, frames + warmup);
    double graphMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - compileStart).count();
    // Scene nodes build (the museum) or load (glTF) their scene in setup(): reported apart from compiling the graph.
    const double sceneMs = sceneBuildMs(graph);
    graphMs -= sceneMs;

    Context ctx(contextOptions(args));
    ShaderCompiler shaders;
    Executor executor(ctx, graph, shaders);
    RunOptions options;
    options.frames = frames + warmup;
    options.progress = !args.has("quiet");
    takeNodeFigures();
    executor.run(options);
    // Figures nodes measured about their own work (render.pathtrace's paths/s and rays/s), median of the frames
    // after the warm-up.
    nlohmann::json figures = nlohmann::json::object();
    for (auto& [name, values] : takeNodeFigures()) {
        if (values.size() > warmup) values.erase(values.begin(), values.begin() + warmup);
        figures[name] = median(values);
    }

    const auto& timings = executor.timings();
    nlohmann::json j;
    j["graph"] = graphArg(args);
    j["device"] = ctx.deviceInfo().name;
    j["width"] = graph.desc.frame.width;
    j["height"] = graph.desc.frame.height;
    j["frames"] = frames;
    j["warmup"] = warmup;
    j["compile_ms"] = {{"graph", graphMs}, {"scene_build", sceneMs}, {"pipelines", executor.pipelineMs()}};
    j["memory_bytes"] = {{"transient_aliased", executor.memory().transientAliased},
                         {"transient_unaliased", executor.memory().transientUnaliased},
                         {"persistent", executor.memory().persistent}};
    std::vector<double> total, record, wait;
    uint64_t inFrameWaits = 0;
    j["passes"] = nlohmann::json::array();
    for (size_t p = 0; p < graph.passes.size(); ++p) {
        std::vector<double> ms, cpu;
        for (size_t f = warmup; f < timings.size(); ++f) {
            ms.push_back(timings[f].passGpuMs[p]);
            cpu.push_back(timings[f].passCpuMs[p]);
        }
        j["passes"].push_back({{"id", graph.passes[p].id}, {"type", graph.passes[p].schema->type},
                               {"setup_ms", graph.passes[p].setupMs}, {"gpu_ms_median", median(ms)},
                               {"gpu_ms_min", *std::min_element(ms.begin(), ms.end())},
                               {"gpu_ms_max", *std::max_element(ms.begin(), ms.end())},
                               {"cpu_execute_ms_median", median(cpu)}});
    }
    for (size_t f = warmup; f < timings.size(); ++f) {
        double sum = 0;
        for (double v : timings[f].passGpuMs) sum += v;
        total.push_back(sum);
        record.push_back(timings[f].cpuRecordMs);
        wait.push_back(timings[f].cpuWaitMs);
        inFrameWaits += timings[f].inFrameWaits;
    }
    j["gpu_ms_total_median"] = median(total);
    // Recording the frame's commands, less the time nodes waited for the GPU inside it (cpu_wait_ms_median; a
    // node that splits the submission to read a result back stalls the frame there).
    j["cpu_record_ms_median"] = median(record);
    j["cpu_wait_ms_median"] = median(wait);
    j["in_frame_waits"] = inFrameWaits; // fence waits inside the measured frames' recording, all together
    j["node_figures"] = figures;
    if (ctx.validationMessageCount() > 0) j["validation_messages"] = ctx.validationMessageCount();
    j["scenes"] = nlohmann::json::array();
    for (const auto& r : graph.resources) {
        auto* so = dynamic_cast<SceneObject*>(r.object.get());
        if (!so || !so->uploaded()) continue;
        const GpuSceneStats& st = so->gpu().stats();
        j["scenes"].push_back({{"resource", r.name}, {"triangles", so->scene().triangleCount()},
                               {"draws", so->gpu().draws().size()}, {"geometry_bytes", st.geometryBytes},
                               {"texture_bytes", st.textureBytes}, {"upload_ms", st.uploadMs}});
    }
    if (args.has("bvh")) {
        const CameraFrame* camera = nullptr;
        for (const auto& r : graph.resources)
            if (auto* c = dynamic_cast<CameraObject*>(r.object.get())) {
                camera = &c->current;
                break;
            }
        j["bvh"] = nlohmann::json::array();
        for (const auto& r : graph.resources)
            if (auto* so = dynamic_cast<SceneObject*>(r.object.get())) j["bvh"].push_back(benchSceneBvh(ctx, shaders, r.name, *so, camera));
        if (j["bvh"].empty()) throw UserError("bench --bvh: the graph " + graphArg(args) + " has no scene");
    }

    if (args.has("json")) {
        std::string path = args.get("json");
        if (path == "-") std::cout << j.dump(2) << "\n";
        else writeFileAtomically(path, j.dump(2) + "\n");
    }
    if (!args.has("json") || args.get("json") != "-") {
        std::printf("%s on %s, %ux%u, median of %u frames (after %u warm-up)\n", graphArg(args).c_str(),
                    ctx.deviceInfo().name.c_str(), graph.desc.frame.width, graph.desc.frame.height, frames, warmup);
        std::printf("  %-20s %-20s %10s %10s\n", "pass", "type", "GPU ms", "CPU ms");
        for (const auto& p : j["passes"])
            std::printf("  %-20s %-20s %10.3f %10.3f\n", p["id"].get<std::string>().c_str(),
                        p["type"].get<std::string>().c_str(), p["gpu_ms_median"].get<double>(),
                        p["cpu_execute_ms_median"].get<double>());
        std::printf("  %-41s %10.3f\n", "total GPU", median(total));
        std::printf("  CPU record %.3f ms, CPU wait in the frame %.3f ms (%llu waits in %u frames); compile: graph %.2f "
                    "ms, pipelines %.1f ms; scene build %.1f ms\n",
                    median(record), median(wait), static_cast<unsigned long long>(inFrameWaits), frames, graphMs,
                    executor.pipelineMs(), sceneMs);
        for (const auto& [name, value] : figures.items()) std::printf("  %s: %.0f\n", name.c_str(), value.get<double>());
        const MemoryStats& m = executor.memory();
        std::printf("  transient memory: %s aliased, %s without aliasing (%.0f%%); persistent %s\n",
                    mib(m.transientAliased).c_str(), mib(m.transientUnaliased).c_str(),
                    m.transientUnaliased ? 100.0 * m.transientAliased / m.transientUnaliased : 100.0,
                    mib(m.persistent).c_str());
        for (const auto& sc : j["scenes"])
            std::printf("  scene %s: %zu triangles in %zu draws; geometry %s, textures %s (with mips); upload %.0f ms\n",
                        sc["resource"].get<std::string>().c_str(), sc["triangles"].get<size_t>(), sc["draws"].get<size_t>(),
                        mib(sc["geometry_bytes"].get<uint64_t>()).c_str(), mib(sc["texture_bytes"].get<uint64_t>()).c_str(),
                        sc["upload_ms"].get<double>());
        if (j.contains("bvh"))
            for (const auto& b : j["bvh"]) printSceneBvhBench(b);
    }
    return ctx.validationMessageCount() > 0 ? 2 : 0;
}

int graphCommand(const Args& args) {
    CompiledGraph graph = compileFromArgs(args);
    if (!args.has("dot")) throw UserError("graph: choose an output format: --dot");
    std::printf("digraph vitrine {\n  rankdir=LR;\n  node [shape=box, fontname=\"monospace\"];\n");
    for (size_t p = 0; p < graph.passes.size(); ++p)
        std::printf("  p%zu [label=\"%zu: %s\\n%s\"];\n", p, p, graph.passes[p].id.c_str(),
                    graph.passes[p].schema->type.c_str());
    for (size_t r = 0; r < graph.resources.size(); ++r) {
        const GraphResource& res = graph.resources[r];
        if (!res.isTexture()) {
            std::printf("  r%zu [shape=note, label=\"%s\\n%s\"];\n", r, res.name.c_str(), toString(res.kind));
            continue;
        }
        std::string kind = res.history ? "history" : res.persistent ? "persistent" : res.extracted ? "output" : "transient";
        std::printf("  r%zu [shape=ellipse, label=\"%s\\n%ux%u %s\\n%s, passes %u-%u\"];\n", r, res.name.c_str(),
                    res.desc.width, res.desc.height, formatName(res.desc.format).c_str(), kind.c_str(), res.firstPass,
                    res.lastPass);
    }
    for (size_t p = 0; p < graph.passes.size(); ++p)
        for (const auto& u : graph.passes[p].uses) {
            if (u.output) std::printf("  p%zu -> r%u;\n", p, u.resource);
            else std::printf("  r%u -> p%zu [label=\"%s%s\"%s];\n", u.resource, p, u.port.c_str(),
                             u.previous ? "@prev" : "", u.previous ? ", style=dashed" : "");
        }
    for (const auto& c : graph.culled) std::printf("  \"%s\" [style=dotted, label=\"%s (culled)\"];\n", c.c_str(), c.c_str());
    std::printf("}\n");
    return 0;
}

int devicesCommand(const Args& args) {
    for (const auto& d : Context::listDevices()) {
        const char* type = d.type == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU     ? "discrete"
                           : d.type == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU ? "integrated"
                           : d.type == VK_PHYSICAL_DEVICE_TYPE_CPU            ? "cpu"
                                                                              : "other";
        std::printf("%u: %s (%s, Vulkan %u.%u)\n", d.index, d.name.c_str(), type, VK_API_VERSION_MAJOR(d.apiVersion),
                    VK_API_VERSION_MINOR(d.apiVersion));
    }
    return 0;
}

} // namespace vitrine::cli
