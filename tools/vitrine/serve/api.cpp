#include "tools/vitrine/serve/api.hpp"

#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/graph/json_schema.hpp"
#include "core/graph/registry.hpp"
#include "tools/vitrine/serve/http_util.hpp"

#include <algorithm>
#include <cctype>

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
    : mOptions(options), mSandbox(options.dir), mGpu(gpu), mEvents(events),
      // Byte for byte what `vitrine nodes --json` and `vitrine schema` print.
      mNodesJson(NodeRegistry::global().toJson().dump(2) + "\n"),
      mSchemaJson(graphJsonSchema(NodeRegistry::global()).dump(2) + "\n") {}

std::shared_ptr<void> Api::waitSlot() {
    if (mWaiting.fetch_add(1) >= kMaxWaitingRequests) {
        --mWaiting;
        throw mGpu.queueFull();
    }
    return std::shared_ptr<void>(nullptr, [this](void*) { --mWaiting; });
}

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
            // A 503 (the GPU queue or the event streams are full) says when to come back.
            if (e.detail().contains("retry_after"))
                res.set_header("Retry-After", std::to_string(e.detail()["retry_after"].get<int>()));
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

std::string lowered(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
    return s;
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

// Refusals of checkAccess: {"error", "status", "reason"}. A body the request has is left unread, so the connection
// cannot carry another request.
void refuse(const httplib::Request& req, httplib::Response& res, int status, const std::string& reason,
            const std::string& message) {
    replyError(res, status, message, {{"reason", reason}});
    const std::string length = req.get_header_value("Content-Length");
    if (req.has_header("Transfer-Encoding") || (!length.empty() && length != "0"))
        res.set_header("Connection", "close");
}

const char* kTokenPage = R"(<!doctype html>
<html><head><meta charset="utf-8"><title>vitrine serve: access token required</title></head><body>
<h1>Access token required</h1>
<p>This <code>vitrine serve</code> answers only to requests with its access token. Open the URL it printed when it
started (<code>http://127.0.0.1:PORT/?token=...</code>); the browser then keeps the token as a cookie.</p>
</body></html>
)";

} // namespace

bool Api::isOwnHost(const std::string& header) const {
    const std::string host = lowered(header);
    std::vector<std::string> names = {"localhost", "127.0.0.1", "[::1]"};
    if (!mOptions.bindHost.empty()) {
        const std::string bind = lowered(mOptions.bindHost);
        // A wildcard address is reached under names this server cannot know: the token is what guards it.
        if (bind == "0.0.0.0" || bind == "::" || bind == "[::]") return true;
        names.push_back(bind.find(':') != std::string::npos && bind[0] != '[' ? "[" + bind + "]" : bind);
    }
    const std::string port = std::to_string(mPort);
    for (const std::string& name : names)
        if (host == name + ":" + port || (mPort == 80 && host == name)) return true;
    return false;
}

void Api::securityHeaders(const httplib::Request& req, httplib::Response& res) {
    auto set = [&](const char* name, const char* value) {
        if (!res.has_header(name)) res.set_header(name, value);
    };
    // The editor's bundle is external module scripts and styles from this server; images are its own URLs, blob:
    // (fetched previews) or data: (an empty pixel). No inline or remote script, no framing.
    set("Content-Security-Policy",
        "default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' blob: data:; "
        "connect-src 'self'; font-src 'self'; object-src 'none'; base-uri 'none'; form-action 'self'; "
        "frame-ancestors 'none'");
    set("X-Frame-Options", "DENY");
    set("X-Content-Type-Options", "nosniff");
    set("Referrer-Policy", "no-referrer");
    if (req.path.rfind("/api/", 0) == 0 || req.path == "/api") set("Cache-Control", "no-store");
}

httplib::Server::HandlerResponse Api::checkAccess(const httplib::Request& req, httplib::Response& res) {
    using R = httplib::Server::HandlerResponse;
    // A web page may make a name it controls resolve to 127.0.0.1 (DNS rebinding, e.g. 127.0.0.1.attacker.example);
    // its requests then carry that name: only this server's own names and port are answered.
    const std::string host = req.get_header_value("Host");
    if (!isOwnHost(host)) {
        refuse(req, res, 403, "host",
               "Host '" + host + "' refused: this server answers only to localhost, 127.0.0.1 or [::1]" +
                   (mOptions.bindHost.empty() || mOptions.loopbackOnly ? std::string() : " or " + mOptions.bindHost) +
                   " with its port " + std::to_string(mPort) + " (against DNS rebinding)");
        return R::Handled;
    }
    // Requests from another site's page (a browser says which in Origin; "null" from sandboxed frames and files)
    // are refused: what changes state (PUT, POST, DELETE), the event stream, and any other that names one.
    if (req.has_header("Origin")) {
        const std::string origin = req.get_header_value("Origin");
        const std::string scheme = "http://";
        if (lowered(origin).rfind(scheme, 0) != 0 || !isOwnHost(origin.substr(scheme.size()))) {
            refuse(req, res, 403, "origin",
                   "cross-origin request refused: Origin '" + origin + "' is not this server's own page");
            return R::Handled;
        }
    }
    if (mOptions.token.empty()) return R::Unhandled;
    // As Jupyter does: the token from the query (the printed URL), the header, or the cookie the query set. The
    // cookie's name has the port: cookies do not tell ports apart, and two servers must not replace each other's.
    const std::string cookieName = "vitrine_token_" + std::to_string(mPort);
    std::string given;
    if (req.has_param("token")) {
        given = req.get_param_value("token");
        if (constantTimeEqual(given, mOptions.token))
            res.set_header("Set-Cookie", cookieName + "=" + given + "; Path=/; HttpOnly; SameSite=Strict");
    } else if (req.has_header("Authorization")) {
        const std::string auth = req.get_header_value("Authorization");
        for (const char* scheme : {"token ", "Token ", "Bearer "})
            if (auth.rfind(scheme, 0) == 0) given = auth.substr(std::string(scheme).size());
    } else if (req.has_header("Cookie")) {
        given = cookieValue(req.get_header_value("Cookie"), cookieName);
    }
    if (!given.empty() && constantTimeEqual(given, mOptions.token)) return R::Unhandled;
    if (req.path.rfind("/api/", 0) != 0 && req.method == "GET") {
        res.status = 401;
        res.set_content(kTokenPage, "text/html; charset=utf-8");
        return R::Handled;
    }
    refuse(req, res, 401, "token",
           "access token required: open the URL `vitrine serve` printed (…/?token=…), or send the header "
           "'Authorization: token TOKEN'");
    return R::Handled;
}

void Api::installWithBody(httplib::Server& server, const std::string& method, const std::string& pattern,
                          Handler handler) {
    Handler checked = guarded(std::move(handler));
    // Before the body is read: a JSON body must say so. What an HTML form can send without the browser asking first
    // (text/plain, form encodings) is refused, so that another site's page cannot post to the API.
    auto contentTypeRefused = [](const httplib::Request& req, httplib::Response& res) {
        std::string type = lowered(req.get_header_value("Content-Type"));
        type = type.substr(0, type.find(';'));
        while (!type.empty() && type.back() == ' ')
            type.pop_back();
        if (type == "application/json") return false;
        replyError(res, 415,
                   "Content-Type '" + req.get_header_value("Content-Type") +
                       "' refused: send the JSON body with Content-Type: application/json",
                   {{"reason", "content-type"}});
        // The body is left unread: the connection cannot carry another request.
        res.set_header("Connection", "close");
        return true;
    };
    httplib::Server::HandlerWithContentReader withReader = [this, checked, contentTypeRefused](
                                                              const httplib::Request& req, httplib::Response& res,
                                                              const httplib::ContentReader& reader) {
        if (contentTypeRefused(req, res)) return;
        // --max-body counts the bytes received: cpp-httplib checks only Content-Length, not chunked bodies. Past
        // the limit nothing more is kept; the rest is read and dropped (so that the connection stays usable) up to
        // 64 MiB more, after which the connection is cut.
        const size_t limit = mOptions.maxBodyBytes;
        const size_t drainLimit = limit + (64u << 20);
        std::string body;
        size_t received = 0;
        const bool complete = reader([&](const char* data, size_t size) {
            received += size;
            if (received > limit) {
                body.clear();
                body.shrink_to_fit();
                return received <= drainLimit;
            }
            body.append(data, size);
            return true;
        });
        if (received > limit || res.status == 413) {
            replyError(res, 413,
                       "request body too large: more than --max-body " + std::to_string(limit) + " bytes",
                       {{"reason", "max-body"}});
            if (!complete) res.set_header("Connection", "close");
            return;
        }
        if (!complete) {
            replyError(res, 400, "request body: cannot be read (malformed chunked encoding or connection lost)");
            res.set_header("Connection", "close");
            return;
        }
        // The request object is the server's own (not const); its body is filled here, as a route without a
        // content reader would have it.
        const_cast<httplib::Request&>(req).body = std::move(body);
        checked(req, res);
    };
    // Requests without a body (no Content-Length, not chunked) do not go through the content reader.
    Handler withoutBody = [checked, contentTypeRefused](const httplib::Request& req, httplib::Response& res) {
        if (contentTypeRefused(req, res)) return;
        checked(req, res);
    };
    if (method == "PUT") {
        server.Put(pattern, withReader);
        server.Put(pattern, withoutBody);
    } else {
        server.Post(pattern, withReader);
        server.Post(pattern, withoutBody);
    }
}

void Api::status(const httplib::Request&, httplib::Response& res) {
    int streams = 0;
    {
        std::lock_guard lock(mStreamMutex);
        streams = mStreams;
    }
    replyJson(res, 200,
              {{"format", "vitrine-serve/1"},
               {"device", mGpu.deviceName()},
               {"queued", mGpu.queued()},
               {"max_queued", mGpu.maxQueued()},
               {"busy", mGpu.busy()},
               {"waiting_requests", mWaiting.load()},
               {"max_waiting_requests", kMaxWaitingRequests},
               {"event_streams", streams},
               {"max_event_streams", kMaxEventStreams},
               {"max_event_streams_per_client", kMaxEventStreamsPerClient},
               {"warm_graphs", mGpu.warmGraphs()},
               {"editor", fs::is_directory(mOptions.editorDist)}});
}

void Api::install(httplib::Server& server) {
    server.set_payload_max_length(mOptions.maxBodyBytes);
    server.set_post_routing_handler(&Api::securityHeaders);
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
    server.Get("/api/nodes", guarded([this](const httplib::Request&, httplib::Response& res) {
                   res.set_content(mNodesJson, "application/json");
               }));
    server.Get("/api/schema", guarded([this](const httplib::Request&, httplib::Response& res) {
                   res.set_content(mSchemaJson, "application/json");
               }));
    server.Get("/api/graphs", bind(&Api::listGraphs));
    server.Get("/api/files", bind(&Api::listFiles));
    server.Get("/api/graphs/(.+)", bind(&Api::getGraph));
    auto route = [this](void (Api::*method)(const httplib::Request&, httplib::Response&)) -> Handler {
        return [this, method](const httplib::Request& req, httplib::Response& res) { (this->*method)(req, res); };
    };
    installWithBody(server, "PUT", "/api/graphs/(.+)", route(&Api::putGraph));
    installWithBody(server, "POST", "/api/validate", route(&Api::validate));
    installWithBody(server, "POST", "/api/render", route(&Api::render));
    installWithBody(server, "POST", "/api/compare", route(&Api::compare));
    server.Get("/api/images/([^/]+)", bind(&Api::image));
    server.Get("/api/events", bind(&Api::events));
    server.Get("/(.*)", bind(&Api::staticFile));
}

} // namespace vitrine::serve
