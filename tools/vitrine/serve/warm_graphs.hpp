#pragma once

#include "core/gpu/context.hpp"
#include "core/graph/compiler.hpp"
#include "core/graph/graph_desc.hpp"
#include "core/shader/compiler.hpp"

#include <list>
#include <memory>
#include <string>
#include <vector>

namespace vitrine {
class Executor;
}

// The compiled graphs `vitrine serve` keeps between requests (and the Python module between runs of a graph object):
// no HTTP here, so that both link it.
namespace vitrine::serve {

// A graph ready to render: the document merged (extends), edited for the preview (size, frames, the one output
// kept) and validated. WarmGraphs is keyed on its document, directory and file.
struct PreparedGraph {
    GraphDesc desc;     // validated, its paths checked against the served directory
    std::string output; // the one graph output left in it ("" with previews)
    // A request for several outputs at once ("outputs": [...], the editor's thumbnails): what it asked for, in order;
    // preview i is the graph output "preview_i".
    std::vector<std::string> previews;
};

// Compiled graphs with their executors (pipelines, images, uploaded scenes, baked resources) kept between requests,
// so that rendering the same document again runs frames only. Least recently used first out.
class WarmGraphs {
public:
    explicit WarmGraphs(size_t capacity);
    ~WarmGraphs();
    struct Entry;
    // The entry for `graph`, compiled (and its executor created) when not kept; `compiled` says whether it was.
    Entry& get(Context& ctx, ShaderCompiler& shaders, const PreparedGraph& graph, bool& compiled);
    Executor& executor(Entry& entry);
    const CompiledGraph& graph(const Entry& entry) const;
    void drop(const Entry& entry);
    void clear();
    size_t size() const { return mEntries.size(); }

private:
    size_t mCapacity;
    std::list<std::unique_ptr<Entry>> mEntries; // front: most recently used
};

} // namespace vitrine::serve
