// Reading a glTF file and checking it before tinygltf sees it: tinygltf indexes some arrays and reads
// some byte ranges without checking, and its messages name neither the file nor the element.

#include "core/scene/gltf.hpp"
#include "core/scene/gltf_detail.hpp"

#include "core/base/error.hpp"
#include "core/base/json_text.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>

namespace vitrine::scene::gltf {

void LoadContext::fail(const std::string& element, const std::string& what) const {
    throw UserError(file + ": " + element + ": " + what);
}

void LoadContext::warn(const std::string& element, const std::string& what) const {
    if (warnings) warnings->push_back(file + ": " + element + ": " + what);
}

std::string path(const std::string& element, const char* key) {
    return element.empty() ? std::string(key) : element + "." + key;
}

const Json* member(const Json& obj, const char* key) {
    if (!obj.is_object()) return nullptr;
    auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
}

double number(const LoadContext& ctx, const Json& obj, const char* key, double def, const std::string& element) {
    const Json* v = member(obj, key);
    if (!v) return def;
    if (!v->is_number()) ctx.fail(path(element, key), "expected a number, got " + v->dump());
    return v->get<double>();
}

int64_t integer(const LoadContext& ctx, const Json& obj, const char* key, int64_t def, const std::string& element) {
    const Json* v = member(obj, key);
    if (!v) return def;
    if (!v->is_number_integer()) ctx.fail(path(element, key), "expected an integer, got " + v->dump());
    return v->get<int64_t>();
}

bool boolean(const LoadContext& ctx, const Json& obj, const char* key, bool def, const std::string& element) {
    const Json* v = member(obj, key);
    if (!v) return def;
    if (!v->is_boolean()) ctx.fail(path(element, key), "expected true or false, got " + v->dump());
    return v->get<bool>();
}

std::string string(const LoadContext& ctx, const Json& obj, const char* key, const std::string& def,
                   const std::string& element) {
    const Json* v = member(obj, key);
    if (!v) return def;
    if (!v->is_string()) ctx.fail(path(element, key), "expected a string, got " + v->dump());
    return v->get<std::string>();
}

glm::vec4 numbers(const LoadContext& ctx, const Json& obj, const char* key, int n, glm::vec4 def,
                  const std::string& element) {
    const Json* v = member(obj, key);
    if (!v) return def;
    if (!v->is_array() || v->size() != static_cast<size_t>(n)) {
        ctx.fail(path(element, key), "expected an array of " + std::to_string(n) + " numbers, got " + v->dump());
    }
    for (int i = 0; i < n; ++i) {
        if (!(*v)[i].is_number()) ctx.fail(path(element, key), "expected numbers, got " + v->dump());
        def[i] = (*v)[i].get<float>();
    }
    return def;
}

const Json* object(const LoadContext& ctx, const Json& obj, const char* key, const std::string& element) {
    const Json* v = member(obj, key);
    if (v && !v->is_object()) ctx.fail(path(element, key), "expected a JSON object, got " + v->dump());
    return v;
}

size_t topLevelCount(const LoadContext& ctx, const char* name) {
    const Json* v = member(ctx.doc, name);
    return v && v->is_array() ? v->size() : 0;
}

uint32_t checkIndex(const LoadContext& ctx, const Json& value, const std::string& element, const char* target) {
    size_t count = topLevelCount(ctx, target);
    if (!value.is_number_integer()) ctx.fail(element, std::string("expected an index into ") + target);
    int64_t i = value.get<int64_t>();
    if (i < 0 || static_cast<size_t>(i) >= count) {
        ctx.fail(element, "index " + std::to_string(i) + " out of range; expected 0.." +
                              std::to_string(static_cast<int64_t>(count) - 1) + " (the file has " +
                              std::to_string(count) + " " + target + ")");
    }
    return static_cast<uint32_t>(i);
}

namespace {

uint32_t readU32(const std::vector<uint8_t>& b, size_t at) {
    return uint32_t(b[at]) | uint32_t(b[at + 1]) << 8 | uint32_t(b[at + 2]) << 16 | uint32_t(b[at + 3]) << 24;
}

std::string urlDecode(const std::string& s) {
    std::string out;
    for (size_t i = 0; i < s.size(); ++i) {
        if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(uint8_t(s[i + 1])) && std::isxdigit(uint8_t(s[i + 2]))) {
            out += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
            i += 2;
        } else {
            out += s[i];
        }
    }
    return out;
}

// A chunk type or magic number as text and hex, e.g. "'BIN\0' (0x004E4942)", for messages.
std::string fourCC(uint32_t v) {
    std::string text;
    for (int i = 0; i < 4; ++i) {
        auto c = static_cast<unsigned char>(v >> (8 * i));
        if (c >= 0x20 && c < 0x7F)
            text += static_cast<char>(c);
        else {
            char esc[8];
            std::snprintf(esc, sizeof esc, "\\x%02X", c);
            text += c == 0 ? std::string("\\0") : std::string(esc);
        }
    }
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%08X", v);
    return "'" + text + "' (" + hex + ")";
}

constexpr uint32_t kGlbMagic = 0x46546C67u; // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534Au;
constexpr uint32_t kChunkBin = 0x004E4942u;

// Splits a GLB into its JSON text and binary chunk, checking the header (magic, version, length) and each chunk's
// type and length against the file, with messages that say which field is wrong.
std::string unwrapGlb(LoadContext& ctx, const std::vector<uint8_t>& bytes) {
    size_t size = bytes.size();
    if (size < 12) {
        ctx.fail("GLB header",
                 "the file has " + std::to_string(size) + " bytes; expected a 12-byte header (magic, version, length)");
    }
    uint32_t magic = readU32(bytes, 0), version = readU32(bytes, 4), length = readU32(bytes, 8);
    if (magic != kGlbMagic)
        ctx.fail("GLB header", "magic is " + fourCC(magic) + "; expected " + fourCC(kGlbMagic) + " (a binary glTF)");
    if (version != 2) ctx.fail("GLB header", "version " + std::to_string(version) + "; expected 2 (glTF 2.0)");
    if (length > size) {
        ctx.fail("GLB header", "length declares " + std::to_string(length) + " bytes but the file has " +
                                   std::to_string(size) + " (truncated file?)");
    }
    if (length < size) {
        ctx.warn("GLB header", "length declares " + std::to_string(length) + " bytes but the file has " +
                                   std::to_string(size) + "; the rest is ignored");
    }
    if (length < 20) {
        ctx.fail("GLB header",
                 "length " + std::to_string(length) +
                     " leaves no room for the JSON chunk; expected at least 20 bytes (header + chunk header)");
    }
    uint32_t jsonLength = readU32(bytes, 12), jsonType = readU32(bytes, 16);
    if (jsonType != kChunkJson)
        ctx.fail("GLB chunk 0", "type is " + fourCC(jsonType) + "; expected " + fourCC(kChunkJson) + " first");
    if (jsonLength == 0) ctx.fail("GLB chunk 0 (JSON)", "is empty; expected the glTF JSON");
    if (uint64_t(20) + jsonLength > length) {
        ctx.fail("GLB chunk 0 (JSON)", "declares " + std::to_string(jsonLength) + " bytes but only " +
                                           std::to_string(length - 20) + " remain (truncated file?)");
    }
    std::string text(reinterpret_cast<const char*>(bytes.data() + 20), jsonLength);
    uint64_t at = 20ull + jsonLength;
    if (at < length) {
        if (at + 8 > length) ctx.fail("GLB chunk 1", "header is cut short (truncated file?)");
        uint32_t binLength = readU32(bytes, at), binType = readU32(bytes, at + 4);
        if (binType != kChunkBin)
            ctx.fail("GLB chunk 1", "type is " + fourCC(binType) + "; expected " + fourCC(kChunkBin));
        if (at + 8 + binLength > length) {
            ctx.fail("GLB chunk 1 (BIN)", "declares " + std::to_string(binLength) + " bytes but only " +
                                              std::to_string(length - at - 8) + " remain (truncated file?)");
        }
        if (binLength < 4 || binLength % 4 != 0) {
            ctx.fail("GLB chunk 1 (BIN)", "length " + std::to_string(binLength) +
                                              "; expected a multiple of 4 (chunks are padded to 4 bytes), at least 4");
        }
        ctx.glbBin.assign(bytes.begin() + at + 8, bytes.begin() + at + 8 + binLength);
    }
    return text;
}

// A GLB is recognised by its magic whatever the file is called; a file named .glb, or one that starts with bytes no
// JSON text has, is read as a GLB too, so that a damaged header is reported as such and not as "not valid JSON".
bool looksLikeGlb(const std::filesystem::path& file, const std::vector<uint8_t>& bytes) {
    if (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0) return true;
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext == ".glb") return true;
    if (ext == ".gltf") return false;
    for (size_t i = 0; i < std::min<size_t>(bytes.size(), 12); ++i)
        if (bytes[i] < 0x09 || (bytes[i] > 0x0D && bytes[i] < 0x20)) return true;
    return false;
}

void checkRequiredExtensions(const LoadContext& ctx) {
    static const std::set<std::string> kSupported = {kTextureTransform, kEmissiveStrength, kLightsPunctual,
                                                     kMeshQuantization, kLayersExtension, kUnlit,
                                                     kTransmission, kIor, kProbesExtension};
    const Json* required = member(ctx.doc, "extensionsRequired");
    if (!required) return;
    if (!required->is_array()) ctx.fail("extensionsRequired", "expected an array of extension names");
    for (size_t i = 0; i < required->size(); ++i) {
        const Json& name = (*required)[i];
        std::string element = "extensionsRequired[" + std::to_string(i) + "]";
        if (!name.is_string()) ctx.fail(element, "expected an extension name");
        if (!kSupported.count(name.get<std::string>())) {
            std::string list;
            for (const std::string& s : kSupported)
                list += (list.empty() ? "" : ", ") + s;
            ctx.fail(element, "extension '" + name.get<std::string>() +
                                  "' is required by the file but not supported; "
                                  "expected only: " +
                                  list);
        }
    }
}

// Calls f(element, item) for each item of the top-level array `name`; fails when items are not objects.
template <typename F>
void forEach(const LoadContext& ctx, const Json& parent, const char* name, const std::string& path, F f) {
    const Json* arr = member(parent, name);
    if (!arr) return;
    std::string base = path.empty() ? std::string(name) : path + "." + name;
    if (!arr->is_array()) ctx.fail(base, "expected an array");
    for (size_t i = 0; i < arr->size(); ++i) {
        std::string element = base + "[" + std::to_string(i) + "]";
        if (!(*arr)[i].is_object()) ctx.fail(element, "expected a JSON object");
        f(element, (*arr)[i]);
    }
}

void checkOptionalIndex(const LoadContext& ctx, const Json& obj, const char* key, const std::string& element,
                        const char* target) {
    if (const Json* v = member(obj, key)) checkIndex(ctx, *v, path(element, key), target);
}

void checkExternalFile(const LoadContext& ctx, const Json& obj, const std::string& element, uint64_t minBytes) {
    const Json* uri = member(obj, "uri");
    if (!uri) return;
    if (!uri->is_string()) ctx.fail(element + ".uri", "expected a string");
    std::string s = uri->get<std::string>();
    if (s.rfind("data:", 0) == 0) return; // tinygltf decodes it and checks its length
    std::filesystem::path path = ctx.baseDir / urlDecode(s);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
        ctx.fail(element + ".uri", "file '" + s + "' not found (looked for " + path.string() + ")");
    }
    uint64_t size = std::filesystem::file_size(path, ec);
    if (!ec && size < minBytes) {
        ctx.fail(element, "file '" + s + "' has " + std::to_string(size) + " bytes; expected byteLength " +
                              std::to_string(minBytes));
    }
}

void checkReferences(const LoadContext& ctx) {
    const Json& d = ctx.doc;
    checkOptionalIndex(ctx, d, "scene", "", "scenes");
    forEach(ctx, d, "scenes", "", [&](const std::string& e, const Json& s) {
        if (const Json* nodes = member(s, "nodes")) {
            if (!nodes->is_array()) ctx.fail(e + ".nodes", "expected an array of node indices");
            for (size_t i = 0; i < nodes->size(); ++i)
                checkIndex(ctx, (*nodes)[i], e + ".nodes[" + std::to_string(i) + "]", "nodes");
        }
    });
    size_t lightCount = 0;
    if (const Json* ext = member(d, "extensions")) {
        if (const Json* lights = member(*ext, kLightsPunctual)) {
            if (const Json* list = member(*lights, "lights"); list && list->is_array()) lightCount = list->size();
        }
    }
    forEach(ctx, d, "nodes", "", [&](const std::string& e, const Json& n) {
        if (const Json* children = member(n, "children")) {
            if (!children->is_array()) ctx.fail(e + ".children", "expected an array of node indices");
            for (size_t i = 0; i < children->size(); ++i) {
                checkIndex(ctx, (*children)[i], e + ".children[" + std::to_string(i) + "]", "nodes");
            }
        }
        checkOptionalIndex(ctx, n, "mesh", e, "meshes");
        checkOptionalIndex(ctx, n, "camera", e, "cameras");
        checkOptionalIndex(ctx, n, "skin", e, "skins");
        if (const Json* ext = member(n, "extensions")) {
            if (const Json* light = member(*ext, kLightsPunctual)) {
                int64_t i = integer(ctx, *light, "light", -1, e + ".extensions." + kLightsPunctual);
                if (i < 0 || static_cast<size_t>(i) >= lightCount) {
                    ctx.fail(e + ".extensions." + kLightsPunctual + ".light", "index out of range of the lights");
                }
            }
        }
    });
    forEach(ctx, d, "meshes", "", [&](const std::string& e, const Json& m) {
        const Json* prims = member(m, "primitives");
        if (!prims || !prims->is_array() || prims->empty()) ctx.fail(e + ".primitives", "expected a non-empty array");
        forEach(ctx, m, "primitives", e, [&](const std::string& pe, const Json& p) {
            const Json* attributes = object(ctx, p, "attributes", pe);
            if (!attributes) ctx.fail(pe + ".attributes", "missing; expected at least POSITION");
            for (auto it = attributes->begin(); it != attributes->end(); ++it) {
                checkIndex(ctx, it.value(), pe + ".attributes." + it.key(), "accessors");
            }
            checkOptionalIndex(ctx, p, "indices", pe, "accessors");
            checkOptionalIndex(ctx, p, "material", pe, "materials");
            forEach(ctx, p, "targets", pe, [&](const std::string& te, const Json& t) {
                for (auto it = t.begin(); it != t.end(); ++it)
                    checkIndex(ctx, it.value(), te + "." + it.key(), "accessors");
            });
        });
    });
    forEach(ctx, d, "accessors", "", [&](const std::string& e, const Json& a) {
        checkOptionalIndex(ctx, a, "bufferView", e, "bufferViews");
        if (const Json* sparse = object(ctx, a, "sparse", e)) {
            if (const Json* idx = object(ctx, *sparse, "indices", e + ".sparse")) {
                checkOptionalIndex(ctx, *idx, "bufferView", e + ".sparse.indices", "bufferViews");
            }
            if (const Json* val = object(ctx, *sparse, "values", e + ".sparse")) {
                checkOptionalIndex(ctx, *val, "bufferView", e + ".sparse.values", "bufferViews");
            }
        }
    });
    bool binary = !ctx.glbBin.empty();
    std::vector<uint64_t> bufferLength;
    forEach(ctx, d, "buffers", "", [&](const std::string& e, const Json& b) {
        int64_t length = integer(ctx, b, "byteLength", -1, e);
        if (length < 1) ctx.fail(e + ".byteLength", "missing or < 1; expected the buffer's size in bytes");
        if (!member(b, "uri")) {
            if (!binary || !bufferLength.empty()) {
                ctx.fail(e, "has no uri; expected a file name or data: URI (only a .glb's first buffer may omit it)");
            }
            if (static_cast<uint64_t>(length) > ctx.glbBin.size()) {
                ctx.fail(e + ".byteLength", std::to_string(length) + " bytes, but the GLB binary chunk has " +
                                                std::to_string(ctx.glbBin.size()));
            }
        }
        checkExternalFile(ctx, b, e, static_cast<uint64_t>(length));
        bufferLength.push_back(static_cast<uint64_t>(length));
    });
    forEach(ctx, d, "bufferViews", "", [&](const std::string& e, const Json& v) {
        const Json* buffer = member(v, "buffer");
        if (!buffer) ctx.fail(e + ".buffer", "missing; expected an index into buffers");
        uint32_t b = checkIndex(ctx, *buffer, e + ".buffer", "buffers");
        int64_t offset = integer(ctx, v, "byteOffset", 0, e), length = integer(ctx, v, "byteLength", -1, e);
        if (offset < 0) ctx.fail(e + ".byteOffset", "expected >= 0");
        if (length < 1) ctx.fail(e + ".byteLength", "missing or < 1; expected the view's size in bytes");
        if (static_cast<uint64_t>(offset) + static_cast<uint64_t>(length) > bufferLength[b]) {
            ctx.fail(e, "bytes " + std::to_string(offset) + ".." + std::to_string(offset + length) +
                            " exceed buffers[" + std::to_string(b) + "] (" + std::to_string(bufferLength[b]) +
                            " bytes)");
        }
        int64_t stride = integer(ctx, v, "byteStride", 0, e);
        if (stride != 0 && (stride < 4 || stride > 252 || stride % 4 != 0)) {
            ctx.fail(e + ".byteStride", "expected a multiple of 4 in 4..252, got " + std::to_string(stride));
        }
    });
    forEach(ctx, d, "images", "", [&](const std::string& e, const Json& i) {
        checkOptionalIndex(ctx, i, "bufferView", e, "bufferViews");
        if (!member(i, "uri") && !member(i, "bufferView")) ctx.fail(e, "expected a uri or a bufferView");
        checkExternalFile(ctx, i, e, 0);
    });
    forEach(ctx, d, "textures", "", [&](const std::string& e, const Json& t) {
        checkOptionalIndex(ctx, t, "source", e, "images");
        checkOptionalIndex(ctx, t, "sampler", e, "samplers");
    });
    forEach(ctx, d, "animations", "", [&](const std::string& e, const Json& a) {
        const Json* samplers = member(a, "samplers");
        size_t samplerCount = samplers && samplers->is_array() ? samplers->size() : 0;
        forEach(ctx, a, "channels", e, [&](const std::string& ce, const Json& c) {
            int64_t s = integer(ctx, c, "sampler", -1, ce);
            if (s < 0 || static_cast<size_t>(s) >= samplerCount) {
                ctx.fail(ce + ".sampler", "index " + std::to_string(s) + " out of range; the animation has " +
                                              std::to_string(samplerCount) + " samplers");
            }
            const Json* target = object(ctx, c, "target", ce);
            if (!target) ctx.fail(ce + ".target", "missing; expected {node, path}");
            checkOptionalIndex(ctx, *target, "node", ce + ".target", "nodes");
        });
        forEach(ctx, a, "samplers", e, [&](const std::string& se, const Json& s) {
            if (!member(s, "input") || !member(s, "output")) ctx.fail(se, "expected input and output accessors");
            checkIndex(ctx, s["input"], se + ".input", "accessors");
            checkIndex(ctx, s["output"], se + ".output", "accessors");
        });
    });
}

} // namespace

std::vector<uint8_t> readGltfFile(const LoadContext& ctx, const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw UserError(ctx.file + ": cannot open the file (does it exist and is it readable?)");
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void preflight(LoadContext& ctx, const std::filesystem::path& file, const std::vector<uint8_t>& bytes) {
    if (bytes.empty()) ctx.fail("file", "is empty; expected glTF JSON or a GLB container");

    bool glb = looksLikeGlb(file, bytes);
    ctx.glb = glb;
    std::string text = glb ? unwrapGlb(ctx, bytes) : std::string(bytes.begin(), bytes.end());
    JsonTextError error;
    std::optional<Json> doc = parseJsonText(text, error);
    if (!doc) {
        std::string where = "line " + std::to_string(error.line) + ", column " + std::to_string(error.column);
        std::string element = glb ? "GLB JSON chunk" : "JSON";
        if (error.kind == JsonTextError::Kind::Syntax)
            ctx.fail(element, "not valid JSON (" + where + ": " + error.message + ")");
        ctx.fail(element + " " + where, error.message);
    }
    ctx.doc = std::move(*doc);
    if (!ctx.doc.is_object()) ctx.fail("(root)", "expected a JSON object");
    const Json* asset = object(ctx, ctx.doc, "asset", "");
    if (!asset) ctx.fail("asset", "missing; expected {\"version\": \"2.0\"}");
    std::string version = string(ctx, *asset, "version", "", "asset");
    if (version.rfind("2.", 0) != 0) ctx.fail("asset.version", "'" + version + "'; expected \"2.0\"");
    checkRequiredExtensions(ctx);
    checkReferences(ctx);
}

} // namespace vitrine::scene::gltf
