// Files under the served directory: the list of graphs, reading and writing one, and the editor's static bundle.
#include "tools/vitrine/serve/api.hpp"

#include "core/base/atomic_file.hpp"
#include "core/base/error.hpp"
#include "core/base/json_text.hpp"
#include "tools/vitrine/serve/http_util.hpp"
#include "tools/vitrine/serve/sandbox.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <functional>
#include <sstream>

namespace vitrine::serve {

namespace fs = std::filesystem;

namespace {

// How many files GET /api/graphs looks at before it stops (a DIR like / must not hang the server).
constexpr size_t kMaxListedFiles = 20000;
constexpr uintmax_t kMaxGraphBytes = 4u << 20;

std::string readFile(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw HttpError(404, path.filename().string() + ": cannot be read");
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

bool skippedDirectory(const fs::path& dir) {
    const std::string name = dir.filename().string();
    std::error_code ec;
    return (!name.empty() && name[0] == '.') || name == "node_modules" ||
           fs::exists(dir / "CMakeCache.txt", ec); // a build tree
}

// A strong ETag of a file's bytes (FNV-1a, 64 bits, and the size): what If-Match compares.
std::string etagOf(const std::string& bytes) {
    uint64_t hash = 14695981039346656037ull;
    for (unsigned char c : bytes) {
        hash ^= c;
        hash *= 1099511628211ull;
    }
    char text[48];
    std::snprintf(text, sizeof text, "\"%016llx-%zx\"", static_cast<unsigned long long>(hash), bytes.size());
    return text;
}

// If-Match: "*" (any existing file) or a list of ETags, one of which must be the file's.
bool ifMatchAccepts(const std::string& header, const std::string& current) {
    if (current.empty()) return false; // no file: nothing can match
    std::stringstream list(header);
    for (std::string item; std::getline(list, item, ',');) {
        item.erase(0, item.find_first_not_of(" \t"));
        item.erase(item.find_last_not_of(" \t") + 1);
        if (item.rfind("W/", 0) == 0) item.erase(0, 2); // a weak ETag names the same bytes here
        if (item == "*" || item == current) return true;
    }
    return false;
}

const char* contentType(const std::string& extension) {
    static const std::pair<const char*, const char*> kTypes[] = {{".html", "text/html; charset=utf-8"},
                                                                 {".js", "text/javascript"},
                                                                 {".mjs", "text/javascript"},
                                                                 {".css", "text/css"},
                                                                 {".json", "application/json"},
                                                                 {".svg", "image/svg+xml"},
                                                                 {".png", "image/png"},
                                                                 {".ico", "image/x-icon"},
                                                                 {".woff2", "font/woff2"},
                                                                 {".map", "application/json"},
                                                                 {".txt", "text/plain"},
                                                                 {".wasm", "application/wasm"}};
    for (const auto& [ext, type] : kTypes)
        if (extension == ext) return type;
    return "application/octet-stream";
}

const char* kPlaceholder = R"(<!doctype html>
<html><head><meta charset="utf-8"><title>vitrine serve</title>
<style>body{font:15px/1.5 system-ui,sans-serif;max-width:46em;margin:3em auto;padding:0 1em}code{background:#eee;padding:0 .3em}</style>
</head><body>
<h1>vitrine serve</h1>
<p>The server is running, but the graph editor is not built: <code>editor/dist/</code> does not exist.</p>
<p>Build it (Node.js and npm from Debian: <code>tools/install-deps.sh</code>), then reload this page:</p>
<pre><code>npm --prefix editor ci
npm --prefix editor run build</code></pre>
<p>or start the server with <code>--editor DIR</code> pointing at a built bundle.</p>
<p>The JSON API works without it: <a href="api/nodes">/api/nodes</a>, <a href="api/graphs">/api/graphs</a>,
<a href="api/status">/api/status</a> (see the README, "Serving graphs: vitrine serve").</p>
</body></html>
)";

// Calls `visit` for every regular file under the served directory that stays inside it (hidden folders,
// node_modules and build trees skipped); true when it stopped after kMaxListedFiles entries.
bool forEachServedFile(const Sandbox& sandbox, const std::function<void(const fs::directory_entry&)>& visit) {
    std::error_code ec;
    size_t seen = 0;
    fs::recursive_directory_iterator it(sandbox.root(), fs::directory_options::skip_permission_denied, ec), end;
    for (; !ec && it != end; it.increment(ec)) {
        if (++seen > kMaxListedFiles) return true;
        const fs::directory_entry& entry = *it;
        if (entry.is_directory(ec)) {
            if (skippedDirectory(entry.path())) it.disable_recursion_pending();
            continue;
        }
        if (entry.is_regular_file(ec) && sandbox.contains(entry.path())) visit(entry);
    }
    return false;
}

} // namespace

void Api::listGraphs(const httplib::Request&, httplib::Response& res) {
    nlohmann::json graphs = nlohmann::json::array();
    const bool truncated = forEachServedFile(mSandbox, [&](const fs::directory_entry& entry) {
        std::error_code ec;
        if (entry.path().extension() != ".json" || entry.file_size(ec) > kMaxGraphBytes) return;
        JsonTextError error;
        std::optional<nlohmann::json> doc = parseJsonText(readFile(entry.path()), error);
        // Graphs have nodes, variants extend a graph; other JSON (the schema, glTF, metrics) is not listed.
        if (!doc || !doc->is_object() || !(doc->contains("nodes") || doc->contains("extends"))) return;
        const bool variant = doc->contains("extends");
        nlohmann::json item = {{"path", mSandbox.relative(fs::weakly_canonical(entry.path()))},
                               {"kind", variant ? "variant" : "graph"}};
        if (variant && (*doc)["extends"].is_string()) item["extends"] = (*doc)["extends"];
        if (doc->contains("description") && (*doc)["description"].is_string())
            item["description"] = (*doc)["description"];
        graphs.push_back(std::move(item));
    });
    std::sort(graphs.begin(), graphs.end(),
              [](const nlohmann::json& a, const nlohmann::json& b) { return a["path"] < b["path"]; });
    nlohmann::json body = {{"graphs", graphs}};
    if (truncated) body["truncated"] = true;
    replyJson(res, 200, body);
}

void Api::listFiles(const httplib::Request& req, httplib::Response& res) {
    // For the editor's path pickers: regular files under DIR, optionally only some extensions ("?ext=.cube,.png").
    std::vector<std::string> extensions;
    if (req.has_param("ext")) {
        std::stringstream list(req.get_param_value("ext"));
        for (std::string e; std::getline(list, e, ',');) {
            if (e.empty()) continue;
            if (e[0] != '.') e = "." + e;
            std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
            extensions.push_back(e);
        }
    }
    std::vector<std::string> files;
    const bool truncated = forEachServedFile(mSandbox, [&](const fs::directory_entry& entry) {
        std::string ext = entry.path().extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
        if (!extensions.empty() && std::find(extensions.begin(), extensions.end(), ext) == extensions.end()) return;
        files.push_back(mSandbox.relative(fs::weakly_canonical(entry.path())));
    });
    std::sort(files.begin(), files.end());
    nlohmann::json body = {{"files", files}};
    if (truncated) body["truncated"] = true;
    replyJson(res, 200, body);
}

void Api::getGraph(const httplib::Request& req, httplib::Response& res) {
    const std::string relative = req.matches[1];
    const fs::path path = mSandbox.resolve(relative);
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw HttpError(404, relative + ": no such file under the served directory");
    if (path.extension() != ".json") throw HttpError(403, relative + ": refused: only graph files (.json) are served");
    std::string bytes = readFile(path);
    // The editor sends it back as If-Match when it saves: a file changed since (another tab, an editor) gets 412.
    res.set_header("ETag", etagOf(bytes));
    res.set_content(std::move(bytes), "application/json");
}

void Api::checkWritable(const fs::path& path, const std::string& shown) const {
    // Only where GET /api/graphs looks: never a dot-folder or dot-file (.git/, .vscode/), node_modules, a build tree
    // or the editor's own sources.
    const fs::path inside = fs::path(mSandbox.relative(path));
    fs::path dir = mSandbox.root();
    for (auto part = inside.begin(); part != inside.end(); ++part) {
        const std::string name = part->string();
        if (!name.empty() && name[0] == '.')
            throw HttpError(403, shown + ": refused: vitrine serve does not write dot-files or under dot-folders ('" +
                                     name + "')", {{"reason", "location"}});
        if (name == "node_modules")
            throw HttpError(403, shown + ": refused: vitrine serve does not write under node_modules",
                            {{"reason", "location"}});
        if (std::next(part) == inside.end()) break;
        dir /= *part;
        std::error_code ec;
        if (fs::exists(dir / "CMakeCache.txt", ec))
            throw HttpError(403, shown + ": refused: vitrine serve does not write into a build tree",
                            {{"reason", "location"}});
    }
    for (const fs::path& readOnly : mOptions.readOnlyDirs) {
        std::error_code ec;
        const fs::path canonical = fs::weakly_canonical(readOnly, ec);
        if (!ec && isInside(canonical, path))
            throw HttpError(403, shown + ": refused: vitrine serve does not write the editor's own files",
                            {{"reason", "location"}});
    }
}

void Api::putGraph(const httplib::Request& req, httplib::Response& res) {
    const std::string relative = req.matches[1];
    const fs::path path = mSandbox.resolve(relative);
    if (path.extension() != ".json") throw HttpError(403, relative + ": refused: only graph files (.json) are written");
    checkWritable(path, relative);
    std::error_code ec;
    if (fs::is_directory(path, ec)) throw HttpError(409, relative + ": is a directory");
    // The body must be a graph or a variant as the loader reads them: an object with "nodes" (an object) or
    // "extends" (the base graph's path), and no other "format" than vitrine-graph/1. It is written as sent, so that
    // a file read and written back unchanged stays byte for byte the same.
    const nlohmann::json doc = parseRequestBody(req.body);
    if (doc.contains("format") && doc["format"] != "vitrine-graph/1")
        throw HttpError(422, relative + ": refused: /format: a graph's format is \"vitrine-graph/1\"",
                        {{"pointer", "/format"}, {"reason", "not-a-graph"}});
    const bool graph = doc.contains("nodes") && doc["nodes"].is_object();
    const bool variant = doc.contains("extends") && doc["extends"].is_string();
    if (!graph && !variant)
        throw HttpError(422,
                        relative + ": refused: not a vitrine graph (an object with \"nodes\") or variant (with " +
                            "\"extends\"); vitrine serve writes nothing else",
                        {{"pointer", ""}, {"reason", "not-a-graph"}});

    // The If-Match check, the .bak and the write are one step: two PUTs do not interleave.
    std::lock_guard lock(mPutMutex);
    const bool existed = fs::is_regular_file(path, ec);
    std::string previous;
    if (existed) previous = readFile(path);
    if (req.has_header("If-Match")) {
        const std::string current = existed ? etagOf(previous) : std::string();
        if (!ifMatchAccepts(req.get_header_value("If-Match"), current))
            throw HttpError(412,
                            relative + ": " +
                                (existed ? "changed since it was read (If-Match " + req.get_header_value("If-Match") +
                                               ", now " + current + "): reload it, or save under another name"
                                         : "does not exist any more (If-Match " + req.get_header_value("If-Match") +
                                               ")"),
                            {{"etag", current}, {"reason", "if-match"}});
    }
    fs::create_directories(path.parent_path(), ec);
    if (ec) throw HttpError(500, relative + ": cannot create its directory");
    // What the write replaces stays as NAME.json.bak (one generation).
    if (existed) writeFileAtomically(fs::path(path.string() + ".bak"), previous);
    writeFileAtomically(path, req.body);
    res.set_header("ETag", etagOf(req.body));
    replyJson(res, existed ? 200 : 201, {{"path", mSandbox.relative(path)}, {"bytes", req.body.size()}});
}

void Api::staticFile(const httplib::Request& req, httplib::Response& res) {
    const std::string relative = req.matches[1];
    if (relative.rfind("api/", 0) == 0 || relative == "api")
        throw HttpError(404, "no such route: " + req.method + " " + req.path);
    std::error_code ec;
    if (!fs::is_directory(mOptions.editorDist, ec)) {
        if (!relative.empty() && relative != "index.html")
            throw HttpError(404, req.path + ": not found (the editor is not built)");
        res.set_content(kPlaceholder, "text/html; charset=utf-8");
        return;
    }
    Sandbox dist(mOptions.editorDist);
    fs::path path = dist.resolve(relative.empty() ? "index.html" : relative);
    // Paths without an extension are the single-page app's own routes: its index page answers them.
    if (!fs::is_regular_file(path, ec) && fs::path(relative).extension().empty()) path = dist.resolve("index.html");
    if (!fs::is_regular_file(path, ec)) throw HttpError(404, req.path + ": not found");
    res.set_content(readFile(path), contentType(path.extension().string()));
}

} // namespace vitrine::serve
