#pragma once

#include "core/gpu/context.hpp"
#include "core/graph/compiler.hpp"
#include "core/graph/executor.hpp"
#include "core/graph/graph_desc.hpp"
#include "core/image/image.hpp"
#include "core/shader/compiler.hpp"
#include "tools/vitrine/cli.hpp"

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

// Rendering one output of a graph at chosen frames: shared by `compare` and `golden`.
namespace vitrine::cli {

// --device and --validate.
ContextOptions contextOptions(const Args& args);

// The --set assignments of the command line, preceded by `frame.frames=FRAMES` and `frame.write=[FRAMES - 1]` when
// frames > 0 (`--frames`): the command line's frame count is part of the document before validation, so that
// `--frames 24 --set frame.write=[0,12,23]` names frames the file alone does not have. An explicit --set of frame.*
// still wins. keepWrite: only frame.frames (`run --write-all` keeps the file's frame.write).
// With `--scene FILE` (and `graph`, the graph file the sets are for), the graph's one scene node (type scene.*) is
// first replaced by {"type": "scene.gltf", "params": {"path": FILE}} under the same id (a scene.gltf node's key_light,
// key_light_elevation and key_light_azimuth params are kept); UserError when the graph has
// no scene node or several, or FILE does not exist.
std::vector<std::string> setsWithFrames(const Args& args, uint32_t frames, bool keepWrite = false,
                                        const std::string& graph = {});

// "lavapipe" for Mesa's CPU device (lavapipe / llvmpipe), else "gpu": golden images and their tolerances are kept
// per device class, because a CPU rasteriser and a GPU round differently.
std::string deviceClass(const Context& ctx);

// The output `requested` of `desc` (empty: the first of its outputs). UserError naming the graph file and the outputs
// it has when there is no such output.
std::string pickOutput(const GraphDesc& desc, const std::string& requested);

// What renderOutput() measured: `vitrine sweep` records it per point.
struct RenderStats {
    double compileMs = 0.0;    // compileGraph(), the nodes' setup() included
    double sceneBuildMs = 0.0; // the setup() of nodes that output a scene (part of compileMs): see sceneBuildMs()
    double pipelineMs = 0.0;   // the executor's pipelines
    double runMs = 0.0;        // the frames, readback included
    MemoryStats memory;
    std::vector<std::string> passIds; // per pass, in timings[f].passGpuMs order
    std::vector<FrameTiming> timings;
};

// Scene nodes build (the museum) or load (glTF) their scene in setup(): the sum of those setup() times, which
// `bench` and `sweep` report apart from compiling the graph.
double sceneBuildMs(const CompiledGraph& graph);

// Compiles `desc` with only `output` kept (so nodes no other output needs are culled), runs `frameCount` frames and
// returns the output at each of `frames` (all < frameCount). stop: the run's RunOptions::stop (Ctrl-C); a stopped run
// may return fewer frames.
std::map<uint32_t, Image> renderOutput(Context& ctx, ShaderCompiler& shaders, GraphDesc desc, const std::string& output,
                                       uint32_t frameCount, const std::vector<uint32_t>& frames, bool progress,
                                       RenderStats* stats = nullptr, std::function<bool()> stop = {});

} // namespace vitrine::cli
