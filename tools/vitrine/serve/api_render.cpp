// Routes that compile or render graphs: validate, render, compare, the rendered images and the progress events.
#include "tools/vitrine/serve/api.hpp"

#include "core/base/error.hpp"
#include "core/compare/report.hpp"
#include "core/graph/compiler.hpp"
#include "core/graph/json_util.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"
#include "core/image/io.hpp"
#include "tools/vitrine/render_output.hpp"
#include "tools/vitrine/serve/http_util.hpp"

#include <chrono>
#include <cmath>
#include <future>

namespace vitrine::serve {

namespace fs = std::filesystem;

namespace {

constexpr uint32_t kMaxSide = 8192;
constexpr uint64_t kMaxPixels = 4096ull * 4096ull;
constexpr uint32_t kMaxFrames = 4096;
constexpr int kKeepAliveSeconds = 3;

// "display": "thumbnail": what a preview of any texture shows. A texture whose green and blue are zero everywhere
// (a single-channel one: AO, depth, CoC) becomes grey; one with values above 1 (scene-referred HDR, hundreds of cd/m²)
// is exposed so that its log-average luminance sits at 0.18 and compressed with Reinhard's L / (1 + L) on luminance,
// instead of clipping to white. Display only: the data the nodes exchange is untouched.
Image thumbnail(Image image) {
    const size_t n = static_cast<size_t>(image.width) * image.height;
    float* px = image.pixels.data();
    bool single = true;
    float peak = 0.0f;
    for (size_t i = 0; i < n; ++i) {
        const float* p = px + 4 * i;
        single = single && p[1] == 0.0f && p[2] == 0.0f;
        for (int c = 0; c < 3; ++c)
            if (std::isfinite(p[c])) peak = std::max(peak, p[c]);
    }
    if (single)
        for (size_t i = 0; i < n; ++i) px[4 * i + 1] = px[4 * i + 2] = px[4 * i];
    if (peak <= 1.0f) return image;
    double logSum = 0.0;
    size_t counted = 0;
    auto luminance = [](const float* p) { return 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]; };
    for (size_t i = 0; i < n; ++i) {
        const float l = luminance(px + 4 * i);
        if (!std::isfinite(l) || l <= 0.0f) continue;
        logSum += std::log(1e-4 + l);
        ++counted;
    }
    const float scale = counted ? 0.18f / static_cast<float>(std::exp(logSum / counted)) : 1.0f;
    for (size_t i = 0; i < n; ++i) {
        float* p = px + 4 * i;
        const float l = luminance(p) * scale;
        const float k = l > 0.0f && std::isfinite(l) ? scale / (1.0f + l) : 0.0f;
        for (int c = 0; c < 3; ++c) p[c] = std::isfinite(p[c]) ? std::max(p[c], 0.0f) * k : 0.0f;
    }
    return image;
}

std::string pngString(const Image& image) {
    std::vector<unsigned char> png = encodePng(image);
    return std::string(reinterpret_cast<const char*>(png.data()), png.size());
}

double msSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// A side of a compare request: "graphs/x.json" stands for {"graph": "graphs/x.json"}.
nlohmann::json specOf(const nlohmann::json& value, const std::string& pointer) {
    if (value.is_string()) return {{"graph", value}};
    if (!value.is_object())
        throw HttpError(400, "request body: " + pointer + ": expected a graph path or an object",
                        {{"pointer", pointer}});
    return value;
}

} // namespace

Api::PreparedDocument Api::prepareDocument(const nlohmann::json& spec, const std::string& pointer,
                                           const Defaults& defaults) {
    // Where the document comes from: a file under the served directory, or the request itself (the editor's unsaved
    // graph; `base` is the file it stands for, from whose directory its relative paths and `extends` resolve).
    nlohmann::json document;
    fs::path file;
    std::string label;
    if (spec.contains("graph")) {
        label = optionalString(spec, "graph", pointer);
        file = mSandbox.resolve(label);
        std::error_code ec;
        if (!fs::is_regular_file(file, ec))
            throw HttpError(404, label + ": no such graph file under the served directory",
                            {{"pointer", pointer + "/graph"}});
        document = readJsonFile(file);
    } else if (spec.contains("document")) {
        document = spec["document"];
        if (!document.is_object())
            throw HttpError(400, "request body: " + pointer + "/document: expected a graph (a JSON object)",
                            {{"pointer", pointer + "/document"}});
        const std::string base = optionalString(spec, "base", pointer);
        file = base.empty() ? mSandbox.root() / "request.json" : mSandbox.resolve(base);
        label = base.empty() ? "request.json" : base;
    } else {
        throw HttpError(400,
                        "request body: " + pointer +
                            ": expected \"graph\" (a graph or variant file under the served directory) or "
                            "\"document\" (a graph as JSON)",
                        {{"pointer", pointer.empty() ? "" : pointer}});
    }
    mSandbox.checkExtends(document, file.parent_path(), label);

    std::vector<std::string> sets;
    if (spec.contains("set")) {
        const nlohmann::json& s = spec["set"];
        const std::string at = pointer + "/set";
        if (!s.is_array())
            throw HttpError(400, "request body: " + at + ": expected an array of \"KEY=VALUE\"", {{"pointer", at}});
        for (size_t i = 0; i < s.size(); ++i) {
            if (!s[i].is_string())
                throw HttpError(400, "request body: " + at + "/" + std::to_string(i) + ": expected \"KEY=VALUE\"",
                                {{"pointer", at + "/" + std::to_string(i)}});
            sets.push_back(s[i].get<std::string>());
        }
    }
    document = mergeGraphDocument(std::move(document), file, sets);
    // Path params out of DIR are refused before anything else looks at the graph (validation, node setups).
    mSandbox.checkPathParams(document, file.parent_path(), label);

    // The preview: size, frame count and the one output rendered, written into the document before it is validated
    // (so a frame.write beyond a shortened run is not an error, and the warm-graph key is the document).
    const uint32_t width = optionalUint(spec, "width", 1, kMaxSide, defaults.width, pointer);
    const uint32_t height = optionalUint(spec, "height", 1, kMaxSide, defaults.height, pointer);
    const uint32_t frames = optionalUint(spec, "frames", 1, kMaxFrames, defaults.frames, pointer);
    std::string output = optionalString(spec, "output", pointer);
    if (output.empty()) output = defaults.output;
    if (document.contains("frame") && !document["frame"].is_object())
        throw UserError(label + ": /frame: expected an object with width, height, frames");
    if (width) document["frame"]["width"] = width;
    if (height) document["frame"]["height"] = height;
    if (frames) {
        document["frame"]["frames"] = frames;
        document["frame"]["write"] = {frames - 1};
    }
    // "outputs": several outputs of one run at once (the editor's thumbnails), each a graph output's name or any
    // node's texture output "node.port"; they become the graph outputs preview_0, preview_1, ...
    std::vector<std::string> previews;
    if (spec.contains("outputs")) {
        const nlohmann::json& list = spec["outputs"];
        const std::string at = pointer + "/outputs";
        if (!output.empty() && spec.contains("output"))
            throw HttpError(400, "request body: " + at + ": give \"output\" or \"outputs\", not both",
                            {{"pointer", at}});
        if (!list.is_array() || list.empty() || list.size() > 256)
            throw HttpError(400, "request body: " + at + ": expected an array of 1 to 256 outputs (\"node.port\")",
                            {{"pointer", at}});
        if (!document.contains("outputs") || !document["outputs"].is_object())
            throw UserError(label + ": /outputs: expected an object {name: \"node.port\"}");
        nlohmann::json outputs = nlohmann::json::object();
        for (size_t i = 0; i < list.size(); ++i) {
            const std::string item = pointer + "/outputs/" + std::to_string(i);
            if (!list[i].is_string())
                throw HttpError(400, "request body: " + item + ": expected \"node.port\" or an output's name",
                                {{"pointer", item}});
            const std::string ref = list[i].get<std::string>();
            const auto named = document["outputs"].find(ref);
            if (named != document["outputs"].end()) outputs["preview_" + std::to_string(i)] = *named;
            else if (ref.find('.') != std::string::npos) outputs["preview_" + std::to_string(i)] = ref;
            else
                throw HttpError(400, "request body: " + item + ": \"" + ref +
                                         "\" is neither a graph output nor \"node.port\"",
                                {{"pointer", item}});
            previews.push_back(ref);
        }
        document["outputs"] = outputs;
        output.clear();
    }
    // "node.port" that is not a graph output: any node's texture output as a preview.
    else if (!output.empty() && output.find('.') != std::string::npos && document.contains("outputs") &&
        document["outputs"].is_object() && !document["outputs"].contains(output)) {
        document["outputs"] = {{"preview", output}};
        output = "preview";
    }

    return {std::move(document), std::move(file), std::move(label), std::move(output), std::move(previews)};
}

PreparedGraph Api::prepare(const nlohmann::json& spec, const std::string& pointer, const Defaults& defaults) {
    return prepare(prepareDocument(spec, pointer, defaults), pointer);
}

PreparedGraph Api::prepare(const PreparedDocument& doc, const std::string& pointer) {
    const std::string& label = doc.label;
    PreparedGraph prepared;
    prepared.desc = validateGraph(doc.document, label, NodeRegistry::global());
    prepared.desc.directory = doc.file.parent_path();
    const FrameSettings& frame = prepared.desc.frame;
    if (static_cast<uint64_t>(frame.width) * frame.height > kMaxPixels)
        throw HttpError(400,
                        label + ": " + std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                            " is larger than vitrine serve renders (at most 4096x4096 pixels); ask for a preview "
                            "size with \"width\" and \"height\"",
                        {{"pointer", pointer + "/width"}});
    mSandbox.checkPathParams(prepared.desc);
    if (!doc.previews.empty()) {
        prepared.previews = doc.previews;
        return prepared;
    }
    prepared.output = cli::pickOutput(prepared.desc, doc.output);
    std::erase_if(prepared.desc.outputs, [&](const OutputDecl& o) { return o.name != prepared.output; });
    nlohmann::json kept = {{prepared.output, prepared.desc.document["outputs"][prepared.output]}};
    prepared.desc.document["outputs"] = kept;
    return prepared;
}

ProgressFn Api::jobProgress(const std::string& job, const std::string& kind, const std::string& file) {
    return [this, job, kind, file](const std::string& stage, uint32_t done, uint32_t total) {
        mEvents.publish(
            "job", {{"job", job}, {"kind", kind}, {"graph", file}, {"stage", stage}, {"done", done}, {"total", total}});
    };
}

NodeProgressFn Api::nodeProgress(const std::string& job, const std::string& kind, const std::string& file) {
    return [this, job, kind, file](const std::string& node, const std::string& label, size_t done, size_t total) {
        mEvents.publish("job", {{"job", job},
                                {"kind", kind},
                                {"graph", file},
                                {"stage", "node"},
                                {"node", node},
                                {"label", label},
                                {"done", done},
                                {"total", total}});
    };
}

RenderResult Api::renderJob(const std::string& job, const std::string& kind, const PreparedGraph& graph,
                            const std::string& tag) {
    const std::string& file = graph.desc.file;
    return mGpu.render(graph, jobProgress(job, kind, file), nodeProgress(job, kind, file), tag);
}

void Api::validate(const httplib::Request& req, httplib::Response& res) {
    const nlohmann::json request = parseRequestBody(req.body);
    // As `vitrine validate`: the graph is loaded and compiled (every node's setup runs), nothing is rendered. The
    // compile runs on the GPU thread, after the jobs before it, because node setups build scenes and load files.
    try {
        PreparedDocument doc = prepareDocument(request, "", Defaults{});
        // Every error the document has, each with its pointer, so that the editor marks them all at once.
        std::vector<std::string> errors = validateGraphErrors(doc.document, doc.label, NodeRegistry::global());
        if (!errors.empty()) {
            nlohmann::json bodies = nlohmann::json::array();
            for (const std::string& e : errors) bodies.push_back(userErrorBody(e));
            replyJson(res, 200, {{"ok", false}, {"errors", bodies}});
            return;
        }
        PreparedGraph prepared = prepare(doc, "");
        const auto slot = waitSlot();
        std::promise<nlohmann::json> done;
        std::future<nlohmann::json> result = done.get_future();
        mGpu.post([&] {
            try {
                CompiledGraph graph = compileGraph(prepared.desc);
                done.set_value({{"ok", true},
                                {"passes", graph.passes.size()},
                                {"textures", graph.resources.size()},
                                {"culled", graph.culled}});
            } catch (...) {
                done.set_exception(std::current_exception());
            }
        });
        replyJson(res, 200, result.get());
    } catch (const PathRefused& e) {
        replyJson(res, 200, {{"ok", false}, {"errors", {userErrorBody(e.what())}}});
    } catch (const UserError& e) {
        replyJson(res, 200, {{"ok", false}, {"errors", {userErrorBody(e.what())}}});
    }
}

void Api::render(const httplib::Request& req, httplib::Response& res) {
    const auto start = std::chrono::steady_clock::now();
    const nlohmann::json request = parseRequestBody(req.body);
    const bool async = optionalBool(request, "async", false);
    // A render with a tag replaces the queued one with the same tag that has not started yet (the editor tags its
    // previews: only the latest edit's are worth rendering).
    const std::string tag = optionalString(request, "tag");
    const std::string display = optionalString(request, "display");
    if (!display.empty() && display != "thumbnail")
        throw HttpError(400, "request body: /display: expected \"thumbnail\" (or leave it out), got \"" + display + "\"",
                        {{"pointer", "/display"}});
    auto png = [thumb = display == "thumbnail"](const Image& image) {
        return pngString(thumb ? thumbnail(image) : image);
    };
    // A render without "async" holds its request thread until the GPU is done: one of kMaxWaitingRequests.
    const std::shared_ptr<void> slot = async ? nullptr : waitSlot();
    PreparedGraph prepared = prepare(request, "", Defaults{});
    const std::string job = newJobId();
    const std::string file = prepared.desc.file;
    mEvents.publish("job", {{"job", job}, {"kind", "render"}, {"graph", file}, {"stage", "queued"}});

    // Where a finished job's images go: the image store, and the answer's {"images": {output: url}}.
    auto publishImages = [this, png](const PreparedGraph& graph, const RenderResult& r,
                                     const std::vector<std::string>& ids) {
        nlohmann::json urls = nlohmann::json::object();
        for (size_t i = 0; i < graph.previews.size(); ++i) {
            const auto it = r.images.find("preview_" + std::to_string(i));
            if (it == r.images.end()) throw InternalError("render: preview " + graph.previews[i] + " was not written");
            const std::string id = ids.empty() ? mImages.reserve() : ids[i];
            mImages.fulfil(id, png(it->second), it->second.width, it->second.height);
            urls[graph.previews[i]] = "/api/images/" + id;
        }
        return urls;
    };

    if (async) {
        // The job runs on the GPU thread after the queue; the client fetches /api/images/ID (202 until it is done).
        std::vector<std::string> ids(std::max<size_t>(prepared.previews.size(), 1));
        for (auto& id : ids) id = mImages.reserve();
        auto shared = std::make_shared<PreparedGraph>(std::move(prepared));
        const ProgressFn progress = jobProgress(job, "render", file);
        auto fail = [this, ids, job](int status, const nlohmann::json& body, const std::string& stage) {
            for (const auto& id : ids) mImages.fail(id, status, body);
            mEvents.publish("job", {{"job", job}, {"kind", "render"}, {"stage", stage}, {"error", body.value("error", "")}});
        };
        // A full queue refuses the job (503): its images fail with the same answer, so none is left pending.
        try {
            mGpu.post(
                [this, shared, job, ids, start, progress, fail, publishImages, file, png] {
                    try {
                        RenderResult r = mGpu.renderNow(*shared, progress, nodeProgress(job, "render", file));
                        if (shared->previews.empty())
                            mImages.fulfil(ids[0], png(r.image), r.image.width, r.image.height);
                        else
                            publishImages(*shared, r, ids);
                        mEvents.publish("job", {{"job", job},
                                                {"kind", "render"},
                                                {"stage", "done"},
                                                {"image", ids[0]},
                                                {"ms", msSince(start)},
                                                {"warm", r.warm}});
                    } catch (const UserError& e) {
                        fail(422, userErrorBody(e.what()), "error");
                    } catch (const std::exception& e) {
                        fail(500, {{"error", std::string("internal error: ") + e.what()}}, "error");
                    }
                },
                tag,
                [fail, tag] {
                    fail(
                        409,
                        {{"error", "superseded: a newer request with tag \"" + tag + "\" came before this one started"},
                         {"superseded", true}},
                        "superseded");
                });
        } catch (const HttpError& e) {
            nlohmann::json body = e.detail();
            body["error"] = e.what();
            body["status"] = e.status();
            fail(e.status(), body, "refused");
            throw;
        }
        nlohmann::json answer = {{"job", job}, {"image", ids[0]}, {"url", "/api/images/" + ids[0]}};
        if (!shared->previews.empty()) {
            nlohmann::json urls = nlohmann::json::object();
            for (size_t i = 0; i < shared->previews.size(); ++i)
                urls[shared->previews[i]] = "/api/images/" + ids[i];
            answer = {{"job", job}, {"images", urls}};
        }
        replyJson(res, 202, answer);
        return;
    }

    try {
        RenderResult r = renderJob(job, "render", prepared, tag);
        const double ms = msSince(start);
        mEvents.publish("job", {{"job", job}, {"kind", "render"}, {"stage", "done"}, {"ms", ms}, {"warm", r.warm}});
        res.set_header("X-Vitrine-Job", job);
        res.set_header("X-Vitrine-Warm", r.warm ? "1" : "0");
        res.set_header("X-Vitrine-Ms", std::to_string(ms));
        res.set_header("X-Vitrine-Validation-Messages", std::to_string(r.validationMessages));
        if (!prepared.previews.empty()) {
            replyJson(res, 200,
                      {{"job", job},
                       {"images", publishImages(prepared, r, {})},
                       {"width", r.image.width},
                       {"height", r.image.height},
                       {"ms", ms},
                       {"warm", r.warm},
                       {"validation_messages", r.validationMessages}});
            return;
        }
        res.set_header("X-Vitrine-Output", prepared.output);
        res.set_header("X-Vitrine-Width", std::to_string(r.image.width));
        res.set_header("X-Vitrine-Height", std::to_string(r.image.height));
        res.set_content(png(r.image), "image/png");
    } catch (const HttpError& e) {
        mEvents.publish("job", {{"job", job},
                                {"kind", "render"},
                                {"stage", e.status() == 409   ? "superseded"
                                          : e.status() == 503 ? "refused"
                                                              : "error"},
                                {"error", e.what()}});
        throw;
    } catch (const std::exception& e) {
        mEvents.publish("job", {{"job", job}, {"kind", "render"}, {"stage", "error"}, {"error", e.what()}});
        throw;
    }
}

void Api::compare(const httplib::Request& req, httplib::Response& res) {
    const nlohmann::json request = parseRequestBody(req.body);
    for (const char* side : {"a", "b"})
        if (!request.contains(side))
            throw HttpError(400, std::string("request body: /") + side + ": missing; expected a graph path or object",
                            {{"pointer", std::string("/") + side}});
    Defaults defaults;
    defaults.width = optionalUint(request, "width", 1, kMaxSide, 0);
    defaults.height = optionalUint(request, "height", 1, kMaxSide, 0);
    defaults.frames = optionalUint(request, "frames", 1, kMaxFrames, 0);
    defaults.output = optionalString(request, "output");
    compare::PairOptions options;
    options.hdr = optionalBool(request, "hdr", false);
    const auto slot = waitSlot();
    PreparedGraph a = prepare(specOf(request["a"], "/a"), "/a", defaults);
    PreparedGraph b = prepare(specOf(request["b"], "/b"), "/b", defaults);

    const std::string job = newJobId();
    mEvents.publish("job", {{"job", job}, {"kind", "compare"}, {"stage", "queued"}});
    Image imageA, imageB;
    try {
        imageA = renderJob(job, "compare", a).image;
        imageB = renderJob(job, "compare", b).image;
    } catch (const std::exception& e) {
        mEvents.publish("job", {{"job", job}, {"kind", "compare"}, {"stage", "error"}, {"error", e.what()}});
        throw;
    }
    if (imageA.width != imageB.width || imageA.height != imageB.height)
        throw HttpError(422, "compare: A (" + a.desc.file + ") is " + std::to_string(imageA.width) + "x" +
                                 std::to_string(imageA.height) + " but B (" + b.desc.file + ") is " +
                                 std::to_string(imageB.width) + "x" + std::to_string(imageB.height) +
                                 "; expected the same size (give \"width\" and \"height\")");

    // The metrics and maps of `vitrine compare`, from the same core/compare functions.
    compare::PairComparison pair = compare::comparePair("A", imageA, "B", imageB, options);
    compare::ReportInput report;
    report.title = a.desc.file + " vs " + b.desc.file;
    report.a = {"A: " + a.desc.file + " → " + a.output, {}, imageA.width, imageA.height};
    report.b = {"B: " + b.desc.file + " → " + b.output, {}, imageB.width, imageB.height};
    report.metrics.push_back(pair.metrics);
    report.graphA = a.desc.document;
    report.graphB = b.desc.document;
    nlohmann::json images;
    auto store = [&](const std::string& name, const Image& image) {
        const std::string id = mImages.reserve();
        mImages.fulfil(id, pngString(image), image.width, image.height);
        images[name] = "/api/images/" + id;
    };
    store("a", imageA);
    store("b", imageB);
    store("diff", compare::falseColor(compare::absoluteDifference(imageA, imageB), 1.0));
    store("flip", compare::flipColorMap(pair.flipErrorMap));
    mEvents.publish("job", {{"job", job}, {"kind", "compare"}, {"stage", "done"}});
    replyJson(res, 200, {{"job", job}, {"metrics", compare::metricsJson(report)}, {"images", images}});
}

void Api::image(const httplib::Request& req, httplib::Response& res) {
    const std::string id = req.matches[1];
    std::optional<ImageStore::Entry> entry = mImages.get(id);
    if (!entry) throw HttpError(404, "no image " + id + " (unknown, or dropped: the server keeps the latest 64)");
    switch (entry->state) {
    case ImageStore::Entry::State::Pending:
        replyJson(res, 202, {{"image", id}, {"state", "pending"}});
        return;
    case ImageStore::Entry::State::Failed:
        replyError(res, entry->status, entry->error.value("error", ""), entry->error);
        return;
    case ImageStore::Entry::State::Done:
        res.set_header("X-Vitrine-Width", std::to_string(entry->width));
        res.set_header("X-Vitrine-Height", std::to_string(entry->height));
        res.set_content(entry->png, "image/png");
        return;
    }
}

void Api::events(const httplib::Request& req, httplib::Response& res) {
    // A reconnecting EventSource sends the last id it saw and gets what it missed (of the kept events).
    uint64_t after = mEvents.lastId();
    if (req.has_header("Last-Event-ID")) {
        const std::string last = req.get_header_value("Last-Event-ID");
        if (!last.empty() && last.size() < 19 && last.find_first_not_of("0123456789") == std::string::npos)
            after = std::stoull(last);
    }
    // Each open stream holds one of the server's threads: past kMaxEventStreams (or kMaxEventStreamsPerClient from
    // one address) a new one gets 503 (the editor tries again 5 s later), so that open tabs or scripts never starve
    // the API of threads, and one client cannot take every stream.
    const std::string client = req.remote_addr;
    {
        std::lock_guard lock(mStreamMutex);
        const bool full = mStreams >= kMaxEventStreams;
        if (full || mStreamsByClient[client] >= kMaxEventStreamsPerClient) {
            if (mStreamsByClient[client] == 0) mStreamsByClient.erase(client);
            throw HttpError(503,
                            full ? "too many event streams open (" + std::to_string(kMaxEventStreams) +
                                       "): close another editor tab, or retry"
                                 : "too many event streams open from " + client + " (" +
                                       std::to_string(kMaxEventStreamsPerClient) +
                                       "): close another editor tab, or retry",
                            {{"reason", "event-streams"}, {"retry_after", 5}});
        }
        ++mStreams;
        ++mStreamsByClient[client];
    }
    // Frees the slot when the response (and the provider holding this) goes away, however the stream ends.
    auto slot = std::shared_ptr<void>(nullptr, [this, client](void*) {
        std::lock_guard lock(mStreamMutex);
        --mStreams;
        if (--mStreamsByClient[client] <= 0) mStreamsByClient.erase(client);
    });
    res.set_header("Cache-Control", "no-store");
    EventHub* hub = &mEvents;
    auto first = std::make_shared<bool>(true);
    res.set_chunked_content_provider("text/event-stream", [hub, after, first, slot](size_t, httplib::DataSink& sink) mutable {
        if (*first) {
            *first = false;
            const std::string hello = "retry: 2000\nevent: hello\ndata: {}\n\n";
            return sink.write(hello.data(), hello.size());
        }
        std::vector<Event> events = hub->waitAfter(after, std::chrono::seconds(kKeepAliveSeconds));
        if (hub->closed()) {
            sink.done();
            return true;
        }
        // A comment line every kKeepAliveSeconds without events: a client that went away shows up as a failed write
        // (the second after it left), which frees its stream slot and thread.
        std::string text = events.empty() ? std::string(": keep-alive\n\n") : std::string();
        for (const Event& e : events) {
            text += EventHub::format(e);
            after = e.id;
        }
        return sink.write(text.data(), text.size()) && sink.is_writable();
    });
}

} // namespace vitrine::serve
