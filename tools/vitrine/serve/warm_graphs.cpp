#include "tools/vitrine/serve/warm_graphs.hpp"

#include "core/graph/executor.hpp"

namespace vitrine::serve {

struct WarmGraphs::Entry {
    std::string key;
    CompiledGraph graph;
    std::unique_ptr<Executor> executor; // refers to `graph`, so the entry never moves (held by unique_ptr)
};

WarmGraphs::WarmGraphs(size_t capacity) : mCapacity(capacity) {}

WarmGraphs::~WarmGraphs() {
    clear();
}

WarmGraphs::Entry& WarmGraphs::get(Context& ctx, ShaderCompiler& shaders, const PreparedGraph& prepared,
                                   bool& compiled) {
    const GraphDesc& desc = prepared.desc;
    const std::string key = desc.file + '\n' + desc.directory.string() + '\n' + desc.document.dump();
    for (auto it = mEntries.begin(); it != mEntries.end(); ++it)
        if ((*it)->key == key) {
            mEntries.splice(mEntries.begin(), mEntries, it);
            compiled = false;
            return *mEntries.front();
        }
    auto entry = std::make_unique<Entry>();
    entry->key = key;
    entry->graph = compileGraph(desc);
    entry->executor = std::make_unique<Executor>(ctx, entry->graph, shaders);
    mEntries.push_front(std::move(entry));
    while (mEntries.size() > mCapacity)
        mEntries.pop_back();
    compiled = true;
    return *mEntries.front();
}

Executor& WarmGraphs::executor(Entry& entry) {
    return *entry.executor;
}

const CompiledGraph& WarmGraphs::graph(const Entry& entry) const {
    return entry.graph;
}

void WarmGraphs::drop(const Entry& entry) {
    mEntries.remove_if([&](const std::unique_ptr<Entry>& e) { return e.get() == &entry; });
}

void WarmGraphs::clear() {
    // Executors first (they free GPU objects), most recent last: the order does not matter to Vulkan, only that
    // every executor goes before the context does, which the owner guarantees.
    mEntries.clear();
}

} // namespace vitrine::serve
