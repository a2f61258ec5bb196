#include "core/graph/compiler.hpp"
#include "core/graph/executor.hpp"

#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/gpu/formats.hpp"
#include "core/graph/json_util.hpp"
#include "core/graph/order.hpp"
#include "core/graph/registry.hpp"

#include <chrono>
#include <cmath>

namespace vitrine {

int CompiledGraph::findResource(const std::string& name) const {
    for (size_t i = 0; i < resources.size(); ++i)
        if (resources[i].name == name) return static_cast<int>(i);
    return -1;
}

const CompiledPass* CompiledGraph::findPass(const std::string& id) const {
    for (const auto& p : passes)
        if (p.id == id) return &p;
    return nullptr;
}

namespace {

VkImageUsageFlags usageFlags(Usage u) {
    switch (u) {
    case Usage::Sampled: return VK_IMAGE_USAGE_SAMPLED_BIT;
    case Usage::StorageRead:
    case Usage::StorageWrite:
    case Usage::StorageReadWrite: return VK_IMAGE_USAGE_STORAGE_BIT;
    case Usage::ColorAttachment: return VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    case Usage::DepthAttachment:
    case Usage::DepthRead: return VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
    case Usage::TransferSrc: return VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    case Usage::TransferDst: return VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    }
    return 0;
}

class Setup final : public SetupContext {
public:
    Setup(CompiledGraph& graph, CompiledPass& pass, const NodeDecl& decl) : mGraph(graph), mPass(pass), mDecl(decl) {}

    const Params& params() const override { return *mPass.params; }
    const FrameSettings& frame() const override { return mGraph.desc.frame; }
    bool hasInput(const std::string& port) const override { return mDecl.inputs.count(port) != 0; }
    const ImageDesc& input(const std::string& port) const override {
        for (const auto& u : mPass.uses) {
            if (u.output || u.port != port) continue;
            if (u.previous)
                throw InternalError("node " + mDecl.id + " asks in setup() for input '" + port +
                                    "', which reads an @prev history whose producer is set up later");
            return mGraph.resources[u.resource].desc;
        }
        throw InternalError("node " + mDecl.id + " asks for unconnected input '" + port + "'");
    }
    ImageDesc& output(const std::string& port) override {
        for (const auto& u : mPass.uses)
            if (u.output && u.port == port) return mGraph.resources[u.resource].desc;
        throw InternalError("node " + mDecl.id + " asks for undeclared output '" + port + "'");
    }
    PipelineId computePipeline(const std::string& shader, const ShaderDefines& defines, uint32_t nodeSets) override {
        mPass.pipelines.push_back({shader, defines, {}, nodeSets});
        return static_cast<PipelineId>(mPass.pipelines.size() - 1);
    }
    PipelineId computePipelineSource(const std::string& name, const std::string& source, uint32_t nodeSets) override {
        mPass.pipelines.push_back({name, {}, source, nodeSets});
        return static_cast<PipelineId>(mPass.pipelines.size() - 1);
    }
    void setObject(const std::string& port, std::shared_ptr<PortObject> object) override {
        for (const auto& u : mPass.uses)
            if (u.output && u.port == port && !mGraph.resources[u.resource].isTexture()) {
                mGraph.resources[u.resource].object = std::move(object);
                return;
            }
        throw InternalError("node " + mDecl.id + " sets an object on '" + port + "', which is not an object output");
    }
    std::shared_ptr<PortObject> object(const std::string& port) const override {
        for (const auto& u : mPass.uses)
            if (!u.output && u.port == port && !mGraph.resources[u.resource].isTexture()) {
                const GraphResource& r = mGraph.resources[u.resource];
                if (!r.object) throw InternalError("node " + mDecl.id + ": the producer of '" + r.name + "' set no object");
                return r.object;
            }
        throw InternalError("node " + mDecl.id + " asks for object input '" + port + "', which is not connected");
    }
    std::filesystem::path resolvePath(const std::string& path) const override {
        std::filesystem::path p(path);
        return p.is_absolute() ? p : mGraph.desc.directory / p;
    }
    [[noreturn]] void failParam(const std::string& param, const std::string& message) const override {
        throw UserError(mGraph.desc.where(mDecl.pointer() + "/params/" + pointerToken(param)) + ": " + message);
    }

private:
    CompiledGraph& mGraph;
    CompiledPass& mPass;
    const NodeDecl& mDecl;
};

uint32_t scaled(uint32_t v, float s) { return std::max(1u, static_cast<uint32_t>(std::lround(v * s))); }

} // namespace

CompiledGraph compileGraph(GraphDesc desc) { return compileGraph(std::move(desc), NodeRegistry::global()); }

CompiledGraph compileGraph(GraphDesc desc, const NodeRegistry& registry) {
    auto start = std::chrono::steady_clock::now();
    CompiledGraph g;
    g.desc = std::move(desc);
    const GraphDesc& d = g.desc;
    GraphOrder order = orderGraph(d);
    for (uint32_t i : order.culled) g.culled.push_back(d.nodes[i].id);

    // Outputs are created in pass order, so a same-frame input's producer resource exists
    // already; @prev inputs are bound after all passes exist.
    std::vector<int> passOfDecl(d.nodes.size(), -1);
    for (uint32_t passIndex = 0; passIndex < order.order.size(); ++passIndex) {
        const NodeDecl& decl = d.nodes[order.order[passIndex]];
        passOfDecl[order.order[passIndex]] = static_cast<int>(passIndex);
        CompiledPass pass;
        pass.decl = order.order[passIndex];
        pass.id = decl.id;
        pass.schema = decl.schema;
        pass.node = registry.create(decl.schema->type);
        pass.params = std::make_unique<Params>(decl.params, *decl.schema);
        g.passes.push_back(std::move(pass));
        CompiledPass& p = g.passes.back();

        for (const auto& in : decl.schema->inputs) {
            auto it = decl.inputs.find(in.name);
            if (it == decl.inputs.end() || it->second.previous) continue;
            const PortRef& ref = it->second;
            int r = g.findResource(ref.node + "." + ref.port);
            if (r < 0) throw InternalError("compiler: " + ref.text() + " has no resource");
            p.uses.push_back({static_cast<uint32_t>(r), in.name, in.usage, false, false});
        }
        for (const auto& in : decl.schema->inputs) {
            auto it = decl.inputs.find(in.name);
            if (it == decl.inputs.end() || !it->second.previous) continue;
            // Resolved below; its description is only known once the producer ran setup().
            p.uses.push_back({UINT32_MAX, in.name, in.usage, false, true});
        }
        for (const auto& out : decl.schema->outputs) {
            GraphResource res;
            res.name = decl.id + "." + out.name;
            res.producer = passIndex;
            res.kind = out.kind;
            res.persistent = out.persistent;
            res.desc.format = out.format;
            if (!out.formatFrom.empty()) {
                auto it = decl.inputs.find(out.formatFrom);
                if (it != decl.inputs.end() && !it->second.previous)
                    res.desc.format = g.resources[g.findResource(it->second.node + "." + it->second.port)].desc.format;
            }
            switch (out.size.mode) {
            case SizeRule::Mode::Frame:
                res.desc.width = scaled(d.frame.width, out.size.scale);
                res.desc.height = scaled(d.frame.height, out.size.scale);
                break;
            case SizeRule::Mode::Input: {
                auto it = decl.inputs.find(out.size.input);
                if (it == decl.inputs.end() || it->second.previous) {
                    res.desc.width = scaled(d.frame.width, out.size.scale);
                    res.desc.height = scaled(d.frame.height, out.size.scale);
                } else {
                    const ImageDesc& src = g.resources[g.findResource(it->second.node + "." + it->second.port)].desc;
                    res.desc.width = scaled(src.width, out.size.scale);
                    res.desc.height = scaled(src.height, out.size.scale);
                }
                break;
            }
            case SizeRule::Mode::Absolute:
                res.desc.width = out.size.width;
                res.desc.height = out.size.height;
                break;
            }
            g.resources.push_back(res);
            p.uses.push_back({static_cast<uint32_t>(g.resources.size() - 1), out.name, out.usage, true, false});
        }

        // Input format checks, now that producers are resolved.
        for (const auto& u : p.uses) {
            if (u.output || u.previous || !g.resources[u.resource].isTexture()) continue;
            const InputPort* in = decl.schema->findInput(u.port);
            VkFormat f = g.resources[u.resource].desc.format;
            if (in->formats.empty() || std::find(in->formats.begin(), in->formats.end(), f) != in->formats.end()) continue;
            std::string allowed;
            for (VkFormat a : in->formats) allowed += (allowed.empty() ? "" : " or ") + formatName(a);
            throw UserError(d.where(decl.pointer() + "/in/" + pointerToken(u.port)) + ": input '" + u.port + "' of " +
                            decl.schema->type + " takes " + allowed + ", but " + decl.inputs.at(u.port).text() + " is " +
                            formatName(f));
        }

        Setup setup(g, p, decl);
        auto setupStart = std::chrono::steady_clock::now();
        {
            ScopedProgressNode working(decl.id);
            p.node->setup(setup);
        }
        p.setupMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - setupStart).count();
        for (const auto& u : p.uses)
            if (u.output && !g.resources[u.resource].isTexture() && !g.resources[u.resource].object)
                throw InternalError("node " + decl.id + " (" + decl.schema->type + ") set no object on output '" + u.port + "'");
    }

    // @prev inputs: bind to the producer's resource and mark it as history.
    for (auto& p : g.passes) {
        const NodeDecl& decl = d.nodes[p.decl];
        for (auto& u : p.uses) {
            if (!u.previous) continue;
            const PortRef& ref = decl.inputs.at(u.port);
            int r = g.findResource(ref.node + "." + ref.port);
            if (r < 0) throw InternalError("compiler: " + ref.text() + " has no resource");
            u.resource = static_cast<uint32_t>(r);
            g.resources[r].history = true;
            const InputPort* in = decl.schema->findInput(u.port);
            VkFormat f = g.resources[r].desc.format;
            if (!in->formats.empty() && std::find(in->formats.begin(), in->formats.end(), f) == in->formats.end())
                throw UserError(d.where(decl.pointer() + "/in/" + pointerToken(u.port)) + ": input '" + u.port +
                                "' does not accept " + formatName(f) + " (" + ref.text() + ")");
        }
    }

    for (const auto& [name, ref] : d.outputs) {
        int r = g.findResource(ref.node + "." + ref.port);
        g.resources[r].extracted = true;
        g.resources[r].desc.usage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
        g.outputs.push_back({name, static_cast<uint32_t>(r)});
    }

    // Lifetimes and accumulated usage flags.
    for (auto& r : g.resources) {
        r.firstPass = r.producer;
        r.lastPass = r.producer;
    }
    for (uint32_t pi = 0; pi < g.passes.size(); ++pi) {
        for (const auto& u : g.passes[pi].uses) {
            GraphResource& r = g.resources[u.resource];
            r.desc.usage |= usageFlags(u.usage);
            if (!u.output) {
                if (const InputPort* in = g.passes[pi].schema->findInput(u.port); in && in->readBack)
                    r.desc.usage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
            } else if (const OutputPort* out = g.passes[pi].schema->findOutput(u.port); out && out->readBack) {
                r.desc.usage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
            }
            if (!u.previous) r.lastPass = std::max(r.lastPass, pi);
        }
    }
    for (auto& r : g.resources) {
        if (!r.isTexture()) {
            r.desc = ImageDesc{};
            continue;
        }
        // Any texture can be inspected (debug.view, read-back), so every one is sampleable.
        r.desc.usage |= VK_IMAGE_USAGE_SAMPLED_BIT;
        if (r.history) r.desc.usage |= VK_IMAGE_USAGE_TRANSFER_DST_BIT; // cleared before its first frame
        if (debugPoison().enabled) r.desc.usage |= VK_IMAGE_USAGE_TRANSFER_DST_BIT; // poisoned before its first writer
        if (r.history || r.persistent || r.extracted) {
            r.firstPass = 0;
            r.lastPass = static_cast<uint32_t>(g.passes.size() - 1);
        }
    }
    g.compileMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return g;
}

} // namespace vitrine
