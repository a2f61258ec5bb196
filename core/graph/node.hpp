#pragma once

#include "core/gpu/resources.hpp"
#include "core/image/image.hpp"
#include "core/graph/graph_desc.hpp"
#include "core/shader/compiler.hpp"

#include <glm/glm.hpp>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <map>
#include <string>
#include <vector>
#include <typeinfo>

namespace vitrine {

class Context;

// Typed read access to a node's validated params (the loader filled in every default, so a
// missing name here is a bug in the node, not in the user's graph).
class Params {
public:
    Params(const nlohmann::json& values, const NodeSchema& schema) : mValues(values), mSchema(schema) {}
    bool getBool(const std::string& name) const;
    int getInt(const std::string& name) const;
    float getFloat(const std::string& name) const;
    glm::vec2 getVec2(const std::string& name) const;
    glm::vec3 getVec3(const std::string& name) const;
    glm::vec4 getVec4(const std::string& name) const;
    std::string getString(const std::string& name) const;
    // Index of an Enum param's value in its schema's choices.
    int getEnumIndex(const std::string& name) const;

private:
    const nlohmann::json& at(const std::string& name) const;
    const nlohmann::json& mValues;
    const NodeSchema& mSchema;
};

using PipelineId = uint32_t;

// What travels on a port that is not a texture: a scene (geometry, materials, their GPU copy), a
// camera for the frame, or a CPU-side data block (e.g. shadow cascades). The producer creates it
// in setup() (so consumers can read it in theirs) and may update it in execute(); consumers read
// it in the same frame, after the producer ran (the graph order guarantees it).
class PortObject {
public:
    virtual ~PortObject() = default;
    // Called when the executor that ran the graph goes away (before its Vulkan device may): drop every
    // GPU object. The CPU side stays, so another executor can run the same compiled graph.
    virtual void releaseGpu() {}
};

namespace detail {
[[noreturn]] void wrongObjectType(const std::string& port, const char* expected);
}

// Passed to Node::setup() once, when the graph is compiled (also by `vitrine validate`, with
// no GPU). A node reads its params and input descriptions here, may adjust its output
// descriptions, and declares the pipelines it will dispatch.
class SetupContext {
public:
    virtual ~SetupContext() = default;
    virtual const Params& params() const = 0;
    virtual const FrameSettings& frame() const = 0;
    virtual bool hasInput(const std::string& port) const = 0;
    virtual const ImageDesc& input(const std::string& port) const = 0;
    virtual ImageDesc& output(const std::string& port) = 0;
    // nodeSets > 0: the shader's sets 1..nodeSets are the node's own (a scene's, a BVH's: layouts that exist
    // only once the scene is on the GPU), bound through ExecuteContext::dispatchWithSets(); set 0 is still
    // bound from the ports.
    virtual PipelineId computePipeline(const std::string& shaderPath, const ShaderDefines& defines = {},
                                       uint32_t nodeSets = 0) = 0;
    // A compute pipeline from GLSL the node generated itself; `name` appears in errors. nodeSets as for
    // computePipeline (color.grade binds OCIO's LUT textures in set 1).
    virtual PipelineId computePipelineSource(const std::string& name, const std::string& source,
                                             uint32_t nodeSets = 0) = 0;
    // Object ports (scene/camera/buffer kinds). setObject() is for outputs; object() for inputs.
    virtual void setObject(const std::string& port, std::shared_ptr<PortObject> object) = 0;
    virtual std::shared_ptr<PortObject> object(const std::string& port) const = 0;
    template <typename T> std::shared_ptr<T> objectAs(const std::string& port) const {
        auto o = std::dynamic_pointer_cast<T>(object(port));
        if (!o) detail::wrongObjectType(port, typeid(T).name());
        return o;
    }
    // Resolves a path param relative to the graph file's directory.
    virtual std::filesystem::path resolvePath(const std::string& path) const = 0;
    // Throws UserError naming the graph file and /nodes/<id>/params/<param>.
    [[noreturn]] virtual void failParam(const std::string& param, const std::string& message) const = 0;
};

// Passed to Node::execute() every frame while the pass is recorded. All barriers and layout
// transitions for the ports have been issued already.
class ExecuteContext {
public:
    virtual ~ExecuteContext() = default;
    virtual Context& gpu() = 0;
    virtual VkCommandBuffer cmd() = 0;
    virtual uint32_t frameIndex() const = 0;
    virtual const Params& params() const = 0;
    // True once the run was asked to stop (Ctrl-C in `vitrine run`: RunOptions::stop). The run ends after this frame;
    // long work inside it (render.pathtrace converging) may end early and keep what it has.
    virtual bool stopRequested() const { return false; }
    virtual bool hasInput(const std::string& port) const = 0;
    // False when the input reads `x@prev` and no previous frame exists yet (it reads zeros).
    virtual bool inputValid(const std::string& port) const = 0;
    virtual const GpuImage& input(const std::string& port) = 0;
    virtual const GpuImage& output(const std::string& port) = 0;
    // Binds in_<port> / out_<port> by the shader's reflected names, pushes `push` (its size
    // must equal the shader's push-constant block) and dispatches enough groups to cover
    // width x height with the shader's local size.
    virtual void dispatch(PipelineId pipeline, const void* push, uint32_t pushSize, uint32_t width,
                          uint32_t height, uint32_t depth = 1) = 0;

    // dispatch() for a pipeline declared with nodeSets: binds `sets` (made with `layouts`) at sets 1..n after
    // the ports' set 0. The pipeline is created on its first dispatch, from these layouts, which must not
    // change afterwards. For passes that trace the scene (render.pathtrace binds the scene, its BVH and
    // geometry).
    virtual void dispatchWithSets(PipelineId pipeline, const void* push, uint32_t pushSize, uint32_t width,
                                  uint32_t height, std::span<const VkDescriptorSetLayout> layouts,
                                  std::span<const VkDescriptorSet> sets) = 0;

    // Orders this pass's earlier dispatches before its later ones (a memory dependency from compute-shader
    // writes to compute-shader reads and writes), for a pass that refines its own StorageReadWrite outputs
    // over several dispatches (render.pathtrace splits its samples so no invocation runs long).
    virtual void computeBarrier() = 0;

    // Moves one of this pass's own outputs to another usage between two of its rendering scopes (a raster pass
    // that samples in a later scope what an earlier one drew, e.g. ibl.localized's blend weights): records the
    // barrier and layout transition and tracks the new state, so the graph's later barriers start from it.
    virtual void changeUsage(const std::string& output, Usage usage) = 0;

    // Ends the frame's command buffer here, submits it and waits for the GPU, then goes on recording into a
    // fresh one (cmd() stays the same handle; bindings are gone). For long work done once (bakes), so that it
    // can show progress and read results back mid-frame; everything recorded before, this pass's inputs
    // included, has run when it returns. Never for per-frame work: it stalls the frame.
    virtual void splitSubmission() = 0;

    // Records a copy of `pixels` into mip 0 / `layer` of an output whose port usage is TransferDst.
    virtual void upload(const std::string& port, const Image& pixels, uint32_t layer = 0) = 0;

    // The object on an input or output port of a non-texture kind (see PortObject).
    virtual PortObject& object(const std::string& port) = 0;
    template <typename T> T& objectAs(const std::string& port) {
        T* o = dynamic_cast<T*>(&object(port));
        if (!o) detail::wrongObjectType(port, typeid(T).name());
        return *o;
    }
    // For nodes that build their own pipelines (raster passes).
    virtual ShaderCompiler& shaders() = 0;
    // Uniform data for the next dispatch(): bound to the shader's uniform block `Uniforms` (any
    // binding in set 0). Copied into a per-frame buffer, so `data` may be a temporary.
    virtual void setUniforms(const void* data, uint32_t size) = 0;
    template <typename T> void setUniforms(const T& data) { setUniforms(&data, static_cast<uint32_t>(sizeof(T))); }

    template <typename T> void dispatch(PipelineId pipeline, const T& push, uint32_t width, uint32_t height) {
        dispatch(pipeline, &push, static_cast<uint32_t>(sizeof(T)), width, height, 1);
    }
};

class Node {
public:
    virtual ~Node() = default;
    virtual void setup(SetupContext& ctx) {}
    virtual void execute(ExecuteContext& ctx) = 0;
    // Nodes that own Vulkan objects (raster pipelines) drop them here; see PortObject::releaseGpu().
    virtual void releaseGpu() {}
};

// Figures a node measures about its own work (render.pathtrace: paths/s, rays/s), one value per frame, collected
// by `vitrine bench` (its JSON's "node_figures" and its printout). Process-wide; thread-safe.
void recordNodeFigure(const std::string& name, double value);
std::map<std::string, std::vector<double>> takeNodeFigures(); // and forgets them

} // namespace vitrine
