#pragma once

#include "tools/vitrine/serve/events.hpp"
#include "tools/vitrine/serve/gpu_worker.hpp"
#include "tools/vitrine/serve/sandbox.hpp"

#include <httplib.h>

#include <atomic>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

// The HTTP side of `vitrine serve`: the JSON API under /api/ and the editor's static files at /. Routes read and
// write files through the Sandbox only, and hand every render to the GpuWorker.
namespace vitrine::serve {

struct ServeOptions {
    std::filesystem::path dir;        // the served directory
    std::filesystem::path editorDist; // the editor's built bundle (editor/dist); a placeholder page when absent
    std::string token;                // required on every request when not empty (--no-token: empty)
    bool loopbackOnly = true;         // bound to a loopback address
    std::string bindHost;             // --host: besides the loopback names, the one name the Host header may give
    size_t maxBodyBytes = 16u << 20;  // larger request bodies get 413, whatever their transfer encoding
    // Folders a PUT never writes into besides dot-folders, node_modules and build trees: the editor's own sources.
    std::vector<std::filesystem::path> readOnlyDirs;
};

// PNGs of finished renders and compares, fetched with GET /api/images/ID; the oldest go first past `capacity`.
class ImageStore {
public:
    explicit ImageStore(size_t capacity = 64) : mCapacity(capacity) {}
    struct Entry {
        enum class State { Pending, Done, Failed } state = State::Pending;
        std::string png;
        int width = 0;
        int height = 0;
        nlohmann::json error; // Failed: the error body
        int status = 0;       // Failed: the HTTP status the error had
    };
    std::string reserve();
    void fulfil(const std::string& id, std::string png, int width, int height);
    void fail(const std::string& id, int status, nlohmann::json error);
    std::optional<Entry> get(const std::string& id) const;

private:
    mutable std::mutex mMutex;
    std::map<uint64_t, Entry> mEntries;
    uint64_t mNext = 1;
    size_t mCapacity;
};

class Api {
public:
    Api(const ServeOptions& options, GpuWorker& gpu, EventHub& events);
    void install(httplib::Server& server);
    // The port the server listens on (known once bound): the Host and Origin headers must name it.
    void setPort(int port) { mPort = port; }

private:
    using Handler = std::function<void(const httplib::Request&, httplib::Response&)>;
    // A route with a JSON body (PUT, POST): refuses another Content-Type with 415 before reading it, reads it with
    // --max-body counted on the bytes received (chunked or not: 413 before anything is stored), then runs `handler`
    // with req.body set. Errors as guarded().
    void installWithBody(httplib::Server& server, const std::string& method, const std::string& pattern,
                         Handler handler);
    // True when `host` (a Host header, or an Origin without its scheme) names this server: localhost, 127.0.0.1,
    // [::1] or --host, with the port it listens on.
    bool isOwnHost(const std::string& host) const;
    // Content-Security-Policy, X-Frame-Options, nosniff, Referrer-Policy on every answer; no-store on /api/.
    static void securityHeaders(const httplib::Request& req, httplib::Response& res);
    // Maps what a route throws to a status and a JSON error body (HttpError, PathRefused 403, UserError 422 with the
    // file and JSON pointer of the culprit, anything else 500).
    Handler guarded(Handler handler);
    httplib::Server::HandlerResponse checkAccess(const httplib::Request& req, httplib::Response& res);

    // api_files.cpp
    void listGraphs(const httplib::Request& req, httplib::Response& res);
    void listFiles(const httplib::Request& req, httplib::Response& res);
    void getGraph(const httplib::Request& req, httplib::Response& res);
    void putGraph(const httplib::Request& req, httplib::Response& res);
    // Refuses (403) a PUT to `path` (canonical, inside DIR) under a dot-folder, node_modules, a build tree or a
    // readOnlyDirs folder; `shown` names it in the error.
    void checkWritable(const std::filesystem::path& path, const std::string& shown) const;
    void staticFile(const httplib::Request& req, httplib::Response& res);

    // api_render.cpp
    struct Defaults {
        uint32_t width = 0, height = 0, frames = 0; // 0: the graph's own
        std::string output;
    };
    // The document a request names (a file under DIR or sent inline), merged (extends, "set") and edited for the
    // preview (size, frames, the output): not yet validated.
    struct PreparedDocument {
        nlohmann::json document;
        std::filesystem::path file; // the file it is or stands for
        std::string label;          // how errors name it
        std::string output;
        std::vector<std::string> previews; // "outputs": [...] asked for several at once
    };
    PreparedDocument prepareDocument(const nlohmann::json& spec, const std::string& pointer, const Defaults& defaults);
    PreparedGraph prepare(const PreparedDocument& document, const std::string& pointer);
    PreparedGraph prepare(const nlohmann::json& spec, const std::string& pointer, const Defaults& defaults);
    // Publishes a job's stages (compiling, rendering frame k of n) as events.
    ProgressFn jobProgress(const std::string& job, const std::string& kind, const std::string& file);
    // Publishes a node's long work (a bake) as `stage: "node"` events of the job.
    NodeProgressFn nodeProgress(const std::string& job, const std::string& kind, const std::string& file);
    RenderResult renderJob(const std::string& job, const std::string& kind, const PreparedGraph& graph,
                           const std::string& tag = {});
    void validate(const httplib::Request& req, httplib::Response& res);
    void render(const httplib::Request& req, httplib::Response& res);
    void compare(const httplib::Request& req, httplib::Response& res);
    void image(const httplib::Request& req, httplib::Response& res);
    void events(const httplib::Request& req, httplib::Response& res);
    void status(const httplib::Request& req, httplib::Response& res);

    // The JSON error body of a UserError: the message (paths inside the served directory made relative), and the
    // file and JSON pointer it names.
    nlohmann::json userErrorBody(const std::string& message) const;
    std::string newJobId();

    ServeOptions mOptions;
    int mPort = 0;
    std::mutex mPutMutex; // one PUT at a time: its If-Match check, .bak and write are one step
    Sandbox mSandbox;
    GpuWorker& mGpu;
    EventHub& mEvents;
    ImageStore mImages;
    std::atomic<uint64_t> mJobs{0};
    // /api/nodes and /api/schema: the registry does not change while serving, so the answers are made once.
    std::string mNodesJson;
    std::string mSchemaJson;

public:
    // Request threads are the scarce resource: an open event stream holds one, and so does a request that waits for
    // the GPU (a render without "async", validate, compare). Both are bounded so that, whatever clients do, threads
    // stay free to answer status, nodes, files and refusals at once.
    static constexpr int kMaxEventStreams = 8;          // open /api/events streams, all clients together
    static constexpr int kMaxEventStreamsPerClient = 4; // ... and from one client address
    static constexpr int kMaxWaitingRequests = 8;       // requests waiting on the GPU queue
    static constexpr int kServerThreads = 32;           // the HTTP thread pool (serve_command.cpp)
    static_assert(kServerThreads >= kMaxEventStreams + kMaxWaitingRequests + 8,
                  "threads must be left for the quick routes");

private:
    // A slot of kMaxWaitingRequests for a request that waits on the GPU; throws the queue's 503 when none is free.
    std::shared_ptr<void> waitSlot();
    std::atomic<int> mWaiting{0};
    std::mutex mStreamMutex;
    int mStreams = 0;
    std::map<std::string, int> mStreamsByClient; // remote address -> open streams
};

} // namespace vitrine::serve
