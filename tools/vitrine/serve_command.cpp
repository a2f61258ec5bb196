// `vitrine serve [DIR] [--port N] [--host ADDR] [--token T | --no-token] [--max-queue N]`: the graph editor's server
// (tools/vitrine/serve/).
#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/base/paths.hpp"
#include "tools/vitrine/cli.hpp"
#include "tools/vitrine/render_output.hpp"
#include "tools/vitrine/serve/api.hpp"

#include <httplib.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <random>
#include <thread>

#include <sys/socket.h>

namespace vitrine::cli {

namespace fs = std::filesystem;

namespace {

std::atomic<int> gStopSignal{0};
constexpr int kListenBacklog = 128;

void onStopSignal(int signal) {
    gStopSignal = signal;
}

// The names that need no token. Any other address, even another 127.x.y.z, counts as opening the server: a user who
// chose one may have forwarded it.
bool isLoopback(const std::string& host) {
    return host == "127.0.0.1" || host == "localhost" || host == "::1" || host == "[::1]";
}

// 192 random bits as hex, as Jupyter's token.
std::string newToken() {
    std::random_device random;
    std::string token;
    const char* hex = "0123456789abcdef";
    for (int i = 0; i < 48; ++i)
        token += hex[random() & 15u];
    return token;
}

} // namespace

int serveCommand(const Args& args) {
    if (args.positional.size() > 1) throw UserError("serve: expected at most one DIR argument (default: .)");
    serve::ServeOptions options;
    options.dir = args.positional.empty() ? fs::path(".") : fs::path(args.positional[0]);
    // The bundle next to an installed binary (share/vitrine/editor/dist), else the source tree's editor/dist.
    options.editorDist = args.get("editor", (resourceRoot() / "editor" / "dist").string());
    // A PUT never writes the editor's own files: its bundle, the sources around a bundle called dist/, and the
    // repository's editor/ (when DIR is the repository).
    options.readOnlyDirs = {options.editorDist, resourceRoot() / "editor"};
    fs::path dist = options.editorDist.lexically_normal();
    if (dist.filename().empty()) dist = dist.parent_path(); // "editor/dist/"
    if (dist.filename() == "dist") options.readOnlyDirs.push_back(dist.parent_path());
    const std::string host = args.get("host", "127.0.0.1");
    const uint32_t port = args.getUint("port", 8420);
    if (port > 65535) throw UserError("--port: expected 0..65535 (0: any free port), got " + std::to_string(port));
    options.maxBodyBytes = args.getUint("max-body", 16u << 20);
    if (options.maxBodyBytes == 0) throw UserError("--max-body: expected at least 1 byte");
    options.loopbackOnly = isLoopback(host);
    options.bindHost = host;
    options.token = args.get("token");
    const bool noToken = args.has("no-token");
    if (noToken && !options.token.empty()) throw UserError("serve: give --token T or --no-token, not both");
    if (noToken && !options.loopbackOnly)
        throw UserError("serve: --no-token is refused with --host " + host +
                        ": a server other machines can reach needs its access token");
    if (!options.loopbackOnly)
        logWarning("serve: --host " + host + " opens the server to other machines: anyone who can reach it and has " +
                   "the token can read and write the graphs under the served directory and use the GPU");
    // As Jupyter: a token on the loopback too, since any local user or program (and any web page, through the
    // browser) can reach 127.0.0.1.
    if (noToken)
        std::fprintf(stderr, "vitrine serve: warning: --no-token: no access token is asked; every program and user on "
                             "this machine can read and write the graphs under the served directory\n");
    else if (options.token.empty())
        options.token = newToken();
    const uint32_t warm = args.getUint("warm", 4);
    const uint32_t maxQueue = args.getUint("max-queue", 16);
    if (maxQueue == 0 || maxQueue > 4096)
        throw UserError("--max-queue: expected 1..4096 GPU jobs waiting, got " + std::to_string(maxQueue));

    serve::EventHub events;
    logInfo("serve: creating the Vulkan device");
    serve::GpuWorker gpu(contextOptions(args), std::max(1u, warm), maxQueue);
    serve::Api api(options, gpu, events);
    httplib::Server server;
    // Event streams and requests waiting on the GPU hold a thread each; both are bounded below the pool's size
    // (api.hpp).
    server.new_task_queue = [] { return new httplib::ThreadPool(serve::Api::kServerThreads); };
    api.install(server);
    // cpp-httplib 0.11 listens with a backlog of 5: 32 clients connecting at once (a page's requests, a load test)
    // overflow it and the kernel drops their SYNs, which costs each a 1 s retransmission before its request is even
    // read. The listening socket is remembered here and its backlog raised once bound (listen() again on Linux).
    int listening = -1;
    server.set_socket_options([&listening](socket_t sock) {
        httplib::default_socket_options(sock);
        listening = sock;
    });

    const int bound = port == 0 ? server.bind_to_any_port(host)
                                : (server.bind_to_port(host, static_cast<int>(port)) ? static_cast<int>(port) : -1);
    if (bound < 0) throw UserError("serve: cannot listen on " + host + ":" + std::to_string(port) + " (in use?)");
    if (listening >= 0 && ::listen(listening, kListenBacklog) != 0)
        logWarning("serve: cannot raise the listen backlog: " + std::string(std::strerror(errno)));
    api.setPort(bound); // the Host and Origin headers must name it
    const std::string shownHost = host.find(':') != std::string::npos && host[0] != '[' ? "[" + host + "]" : host;
    const std::string url = "http://" + shownHost + ":" + std::to_string(bound) + "/";
    std::printf("vitrine serve: %s on %s\n", fs::canonical(options.dir).string().c_str(), gpu.deviceName().c_str());
    std::printf("vitrine serve: listening on %s%s\n", url.c_str(),
                options.token.empty() ? "" : ("?token=" + options.token).c_str());
    std::printf("vitrine serve: Ctrl-C stops it\n");
    std::fflush(stdout);

    std::signal(SIGPIPE, SIG_IGN);
    auto previousInt = std::signal(SIGINT, onStopSignal);
    auto previousTerm = std::signal(SIGTERM, onStopSignal);
    std::thread watcher([&] {
        while (!gStopSignal && !events.closed())
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        events.close(); // ends the events streams, so the server's threads can finish
        server.stop();
    });
    const bool listened = server.listen_after_bind();
    events.close();
    watcher.join();
    gpu.stop(); // runs what is queued (async renders refer to the API), then frees the device
    std::signal(SIGINT, previousInt);
    std::signal(SIGTERM, previousTerm);
    logInfo("serve: stopped");
    if (!listened && !gStopSignal) throw InternalError("serve: the server stopped unexpectedly");
    return 0;
}

} // namespace vitrine::cli
