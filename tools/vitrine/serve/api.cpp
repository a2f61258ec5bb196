#include "tools/vitrine/serve/api.hpp"

#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/graph/json_schema.hpp"
#include "core/graph/registry.hpp"
#include "tools/vitrine/serve/http_util.hpp"

namespace vitrine::serve {

namespace fs = std::filesystem;

std::string ImageStore::reserve() {
    std::lock_guard lock(mMutex);
    const uint64_t id = mNext++;
    mEntries[id] = {};
    // Past capacity the oldest finished entries go; pending ones stay until they finish.
    for (auto it = mEntries.begin(); mEntries.size() > mCapacity && it != mEntries.end();)
        it = it->second.state == Entry::State::Pending ? std::next(it) : mEntries.erase(it);
    return std::to_string(id);
}

void ImageStore::fulfil(const std::string& id, std::string png, int width, int height) {
    std::lock_guard lock(mMutex);
    auto it = mEntries.find(std::stoull(id));
    if (it == mEntries.end()) return;
    it->second = {Entry::State::Done, std::move(png), width, height, nullptr, 200};
}

void ImageStore::fail(const std::string& id, int status, nlohmann::json error) {
    std::lock_guard lock(mMutex);
    auto it = mEntries.find(std::stoull(id));
    if (it == mEntries.end()) return;
    it->second = {Entry::State::Failed, {}, 0, 0, std::move(error), status};
}

std::optional<ImageStore::Entry> ImageStore::get(const std::string& id) const {
    if (id.empty() || id.size() > 18 || id.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
    std::lock_guard lock(mMutex);
    auto it = mEntries.find(std::stoull(id));
    if (it == mEntries.end()) return std::nullopt;
    return it->second;
}

Api::Api(const ServeOptions& options, GpuWorker& gpu, EventHub& events)
    : mOptions(options), mSandbox(options.dir), mGpu(gpu), mEvents(events) {}

std::string Api::newJobId() {
    return std::to_string(++mJobs);
}

nlohmann::json Api::userErrorBody(const std::string& raw) const {
    // Messages name files by the paths the server opened (absolute, under the served directory): shown relative.
    std::string message = raw;
    const std::string prefix = mSandbox.root().string() + "/";
    for (size_t at; (at = message.find(prefix)) != std::string::npos;)
        message.erase(at, prefix.size());
    nlohmann::json body = {{"error", message}};
    // "FILE: /json/pointer: what was expected" (the format of every graph error; `vitrine validate` prints it).
    const size_t colon = message.find(": ");
    if (colon != std::string::npos && colon > 0 && message.find(' ') > colon) body["file"] = message.substr(0, colon);
    const size_t slash = message.find(": /");
    if (slash != std::string::npos) {
        const size_t end = message.find(": ", slash + 2);
        body["pointer"] = message.substr(slash + 2, end == std::string::npos ? std::string::npos : end - slash - 2);
    }
    return body;
}

Api::Handler Api::guarded(Handler handler) {
    return [this, handler](const httplib::Request& req, httplib::Response& res) {
        try {
            handler(req, res);
        } catch (const HttpError& e) {
            replyError(res, e.status(), e.what(), e.detail());
        } catch (const PathRefused& e) {
            nlohmann::json body = userErrorBody(e.what());
            replyError(res, 403, body["error"], body);
        } catch (const UserError& e) {
            nlohmann::json body = userErrorBody(e.what());
            replyError(res, 422, body["error"], body);
        } catch (const std::exception& e) {
            logWarning(std::string("vitrine serve: ") + req.method + " " + req.path + ": " + e.what());
            replyError(res, 500, std::string("internal error: ") + e.what());
        }
    };
}

namespace {

// The host part of a Host header ("127.0.0.1:8080", "[::1]:8080", "localhost").
std::string hostName(const std::string& header) {
    if (!header.empty() && header[0] == '[') return header.substr(0, header.find(']') + 1);
    return header.substr(0, header.find(':'));
}

bool constantTimeEqual(const std::string& a, const std::string& b) {
    if (a.size() != b.size()) return false;
    unsigned char diff = 0;
    for (size_t i = 0; i < a.size(); ++i)
        diff |= static_cast<unsigned char>(a[i] ^ b[i]);
    return diff == 0;
}

std::string cookieValue(const std::string& cookies, const std::string& name) {
    for (size_t at = 0; at < cookies.size();) {
        size_t end = cookies.find(';', at);
        std::string item = cookies.substr(at, end == std::string::npos ? std::string::npos : end - at);
        item.erase(0, item.find_first_not_of(' '));
        if (item.rfind(name + "=", 0) == 0) return item.substr(name.size() + 1);
        if (end == std::string::npos) break;
        at = end + 1;
    }
    return {};
}

} // namespace

httplib::Server::HandlerResponse Api::checkAccess(const httplib::Request& req, httplib::Response& res) {
    using R = httplib::Server::HandlerResponse;
    const std::string host = req.get_header_value("Host");
    // A web page may make a name it controls resolve to 127.0.0.1 (DNS rebinding); its requests then carry that name.
    if (mOptions.loopbackOnly && req.has_header("Host")) {
        const std::string name = hostName(host);
        if (name != "localhost" && name != "[::1]" && name.rfind("127.", 0) != 0) {
            replyError(res, 403, "Host '" + host + "' refused: this server answers only to the loopback names");
            return R::Handled;
        }
    }
    // Requests from another site's page (a browser says which in Origin) are refused.
    if (req.has_header("Origin") && req.get_header_value("Origin") != "http://" + host) {
        replyError(res, 403, "Origin '" + req.get_header_value("Origin") + "' refused: not this server's own page");
        return R::Handled;
    }
    if (mOptions.token.empty()) return R::Unhandled;
    std::string given;
    if (req.has_param("token")) {
        given = req.get_param_value("token");
        // As Jupyter does: the browser that opened the printed URL keeps the token as a cookie for the page's own
        // requests (scripts, styles, the events stream).
        if (constantTimeEqual(given, mOptions.token))
            res.set_header("Set-Cookie", "vitrine_token=" + given + "; Path=/; HttpOnly; SameSite=Strict");
    } else if (req.has_header("Authorization")) {
        const std::string auth = req.get_header_value("Authorization");
        for (const char* scheme : {"token ", "Token ", "Bearer "})
            if (auth.rfind(scheme, 0) == 0) given = auth.substr(std::string(scheme).size());
    } else if (req.has_header("Cookie")) {
        given = cookieValue(req.get_header_value("Cookie"), "vitrine_token");
    }
    if (!given.empty() && constantTimeEqual(given, mOptions.token)) return R::Unhandled;
    replyError(res, 401,
               "access token required: open the URL `vitrine serve` printed (…/?token=…), or send the header "
               "'Authorization: token TOKEN'");
    return R::Handled;
}

void Api::status(const httplib::Request&, httplib::Response& res) {
    replyJson(res, 200,
              {{"format", "vitrine-serve/1"},
               {"device", mGpu.deviceName()},
               {"queued", mGpu.queued()},
               {"warm_graphs", mGpu.warmGraphs()},
               {"editor", fs::is_directory(mOptions.editorDist)}});
}

void Api::install(httplib::Server& server) {
    server.set_payload_max_length(mOptions.maxBodyBytes);
    server.set_pre_routing_handler(
        [this](const httplib::Request& req, httplib::Response& res) { return checkAccess(req, res); });
    server.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
        std::string what = "unknown exception";
        try {
            std::rethrow_exception(ep);
        } catch (const std::exception& e) {
            what = e.what();
        } catch (...) {
        }
        replyError(res, 500, "internal error: " + what);
    });
    server.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
        if (!res.body.empty()) return;
        const std::string what = res.status == 413   ? "request body too large"
                                 : res.status == 404 ? "no such route: " + req.method + " " + req.path
                                                     : "request refused";
        replyError(res, res.status, what);
    });
    server.set_logger([](const httplib::Request& req, const httplib::Response& res) {
        logDebug("serve: " + req.method + " " + req.path + " -> " + std::to_string(res.status));
    });
    auto bind = [this](void (Api::*route)(const httplib::Request&, httplib::Response&)) {
        return guarded(
            [this, route](const httplib::Request& req, httplib::Response& res) { (this->*route)(req, res); });
    };
    server.Get("/api/status", bind(&Api::status));
    server.Get("/api/nodes", guarded([](const httplib::Request&, httplib::Response& res) {
                   // Byte for byte what `vitrine nodes --json` prints.
                   res.set_content(NodeRegistry::global().toJson().dump(2) + "\n", "application/json");
               }));
    server.Get("/api/schema", guarded([](const httplib::Request&, httplib::Response& res) {
                   res.set_content(graphJsonSchema(NodeRegistry::global()).dump(2) + "\n", "application/json");
               }));
    server.Get("/api/graphs", bind(&Api::listGraphs));
    server.Get("/api/files", bind(&Api::listFiles));
    server.Get("/api/graphs/(.+)", bind(&Api::getGraph));
    server.Put("/api/graphs/(.+)", bind(&Api::putGraph));
    server.Post("/api/validate", bind(&Api::validate));
    server.Post("/api/render", bind(&Api::render));
    server.Post("/api/compare", bind(&Api::compare));
    server.Get("/api/images/([^/]+)", bind(&Api::image));
    server.Get("/api/events", bind(&Api::events));
    server.Get("/(.*)", bind(&Api::staticFile));
}

} // namespace vitrine::serve
