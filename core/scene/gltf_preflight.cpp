// Reading a glTF file and checking it before tinygltf sees it: tinygltf indexes some arrays and reads
// some byte ranges without checking, and its messages name neither the file nor the element.

#include "core/scene/gltf.hpp"
#include "core/scene/gltf_detail.hpp"

#include "core/base/error.hpp"
#include "core/base/json_text.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>

#include <tiny_gltf.h>

namespace vitrine::scene::gltf {

namespace {

std::string located(const std::string& file, const std::string& element, const std::string& what) {
    std::string pointer = jsonPointer(element);
    return file + ": " + element + ": " + what + (pointer.empty() ? "" : " (at " + pointer + ")");
}

bool identifierChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; }

} // namespace

void LoadContext::fail(const std::string& element, const std::string& what) const {
    throw UserError(located(file, element, what));
}

std::string LoadContext::message(const std::string& element, const std::string& what) const {
    return located(file, element, what);
}

void LoadContext::warn(const std::string& element, const std::string& what) const {
    if (!warnings) return;
    std::string message = located(file, element, what);
    if (std::find(warnings->begin(), warnings->end(), message) == warnings->end()) warnings->push_back(message);
}

std::string jsonPointer(const std::string& element) {
    static const std::set<std::string> kTopLevel = {
        "accessors", "animations", "asset",  "buffers", "bufferViews", "cameras", "extensions",
        "extensionsRequired", "extensionsUsed", "extras", "images", "materials", "meshes", "nodes",
        "samplers", "scene", "scenes", "skins", "textures"};
    size_t i = 0;
    while (i < element.size() && identifierChar(element[i]))
        ++i;
    std::string first = element.substr(0, i);
    if (!kTopLevel.count(first)) return "";
    std::string pointer = "/" + first;
    while (i < element.size()) {
        if (element[i] == '[') {
            size_t close = element.find(']', i);
            if (close == std::string::npos || close == i + 1) break;
            std::string digits = element.substr(i + 1, close - i - 1);
            if (!std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); })) break;
            pointer += "/" + digits;
            i = close + 1;
        } else if (element[i] == '.' && i + 1 < element.size() && identifierChar(element[i + 1])) {
            size_t start = ++i;
            while (i < element.size() && identifierChar(element[i]))
                ++i;
            pointer += "/" + element.substr(start, i - start); // glTF keys have no '~' or '/' to escape
        } else {
            break;
        }
    }
    return pointer;
}

bool decodeDataUri(const std::string& uri, std::vector<uint8_t>& out, std::string& mediaType, std::string& error) {
    out.clear();
    if (uri.rfind("data:", 0) != 0) {
        error = "expected a URI starting with 'data:'";
        return false;
    }
    size_t comma = uri.find(',');
    if (comma == std::string::npos) {
        error = "data: URI without ','; expected data:[<media type>][;base64],<data>";
        return false;
    }
    std::string header = uri.substr(5, comma - 5);
    std::string lower = header;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
    bool base64 = lower.size() >= 7 && lower.compare(lower.size() - 7, 7, ";base64") == 0;
    mediaType = lower.substr(0, lower.find(';'));
    if (mediaType.empty()) mediaType = "text/plain"; // RFC 2397's default
    // The payload is percent-encoded (RFC 2397 and 3986); a base64 payload rarely is, but may be.
    std::string payload;
    for (size_t i = comma + 1; i < uri.size(); ++i) {
        if (uri[i] != '%') {
            payload += uri[i];
            continue;
        }
        if (i + 2 >= uri.size() || !std::isxdigit(uint8_t(uri[i + 1])) || !std::isxdigit(uint8_t(uri[i + 2]))) {
            error = "data: URI has '%' at character " + std::to_string(i) + " not followed by two hex digits";
            return false;
        }
        payload += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
        i += 2;
    }
    if (!base64) {
        out.assign(payload.begin(), payload.end());
        return true;
    }
    uint32_t bits = 0;
    int count = 0;
    size_t padding = 0;
    for (size_t i = 0; i < payload.size(); ++i) {
        char c = payload[i];
        int v = c >= 'A' && c <= 'Z' ? c - 'A'
                : c >= 'a' && c <= 'z' ? c - 'a' + 26
                : c >= '0' && c <= '9' ? c - '0' + 52
                : c == '+' ? 62
                : c == '/' ? 63
                           : -1;
        if (c == '=') {
            ++padding;
            continue;
        }
        if (v < 0 || padding > 0) {
            error = "data: URI's base64 payload has '" + std::string(1, c) + "' at payload character " +
                    std::to_string(i) + "; expected A-Z a-z 0-9 + / and '=' padding at the end";
            return false;
        }
        bits = (bits << 6) | static_cast<uint32_t>(v);
        count += 6;
        if (count >= 8) {
            count -= 8;
            out.push_back(static_cast<uint8_t>(bits >> count));
        }
    }
    return true;
}

std::string base64Encode(const std::vector<uint8_t>& data) {
    static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((data.size() + 2) / 3 * 4);
    for (size_t i = 0; i < data.size(); i += 3) {
        uint32_t v = uint32_t(data[i]) << 16;
        if (i + 1 < data.size()) v |= uint32_t(data[i + 1]) << 8;
        if (i + 2 < data.size()) v |= data[i + 2];
        out += kAlphabet[(v >> 18) & 63];
        out += kAlphabet[(v >> 12) & 63];
        out += i + 1 < data.size() ? kAlphabet[(v >> 6) & 63] : '=';
        out += i + 2 < data.size() ? kAlphabet[v & 63] : '=';
    }
    return out;
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

namespace {

uint32_t readU32(const std::vector<uint8_t>& b, size_t at) {
    return uint32_t(b[at]) | uint32_t(b[at + 1]) << 8 | uint32_t(b[at + 2]) << 16 | uint32_t(b[at + 3]) << 24;
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
// The largest buffer without readable data that stands in as zeros (readsAsZeros); a larger one is refused.
constexpr uint64_t kMaxZeroBuffer = 64ull << 20;

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

const std::set<std::string> kSupported = {kTextureTransform, kEmissiveStrength,
                                          kLightsPunctual,   kMeshQuantization,
                                          kLayersExtension,  kUnlit,
                                          kTransmission,     kIor,
                                          kProbesExtension,  kSpecGloss,
                                          kVariants,         kSpecular,
                                          kClearcoat,        kSheen,
                                          kVolume,           kMeshopt};

// An extension the file uses but does not require may be ignored (glTF 2.0, 3.12): a warning per extension.
void checkUsedExtensions(const LoadContext& ctx) {
    const Json* used = member(ctx.doc, "extensionsUsed");
    if (!used) return;
    if (!used->is_array()) ctx.fail("extensionsUsed", "expected an array of extension names");
    const Json* required = member(ctx.doc, "extensionsRequired");
    for (size_t i = 0; i < used->size(); ++i) {
        const Json& name = (*used)[i];
        std::string element = "extensionsUsed[" + std::to_string(i) + "]";
        if (!name.is_string()) ctx.fail(element, "expected an extension name");
        std::string n = name.get<std::string>();
        if (kSupported.count(n)) continue;
        bool material = false;
        for (const IgnoredMaterialExtension& ext : kIgnoredMaterialExtensions)
            material = material || n == ext.name;
        if (material) continue; // warned by loadMaterials(), naming what is ignored
        if (required && required->is_array() && std::find(required->begin(), required->end(), name) != required->end())
            continue; // refused by checkRequiredExtensions()
        ctx.warn(element, "extension '" + n + "' is not supported by vitrine; what the file puts under that name in "
                                              "\"extensions\" is ignored and the file is drawn as if it lacked it");
    }
}

void checkRequiredExtensions(const LoadContext& ctx) {
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

// A buffer vitrine reads as byteLength zeros, with a warning: one without a uri that is not a .glb's first buffer (its
// binary chunk) nor an EXT_meshopt_compression fallback, or one whose uri names a remote resource (a scheme such as
// http://). index: the buffer's.
bool readsAsZeros(const LoadContext& ctx, const Json& buffer, size_t index) {
    const Json* uri = member(buffer, "uri");
    if (!uri) return !(!ctx.glbBin.empty() && index == 0) && !isMeshoptFallback(buffer);
    if (!uri->is_string()) return false;
    const std::string& s = uri->get_ref<const std::string&>();
    const size_t scheme = s.find("://");
    return scheme != std::string::npos && scheme > 0 && s.rfind("data:", 0) != 0 &&
           std::all_of(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(scheme), [](char c) {
               return std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '-' || c == '.';
           });
}

void checkExternalFile(const LoadContext& ctx, const Json& obj, const std::string& element, uint64_t minBytes) {
    const Json* uri = member(obj, "uri");
    if (!uri) return;
    if (!uri->is_string()) ctx.fail(element + ".uri", "expected a string");
    std::string s = uri->get<std::string>();
    if (s.rfind("data:", 0) == 0) {
        std::vector<uint8_t> data;
        std::string mediaType, error;
        if (!decodeDataUri(s, data, mediaType, error)) ctx.fail(element + ".uri", error);
        if (minBytes > 0 && data.size() != minBytes) {
            ctx.fail(element + ".uri", "data: URI holds " + std::to_string(data.size()) + " bytes; expected byteLength " +
                                           std::to_string(minBytes));
        }
        if (minBytes == 0 && data.empty()) ctx.fail(element + ".uri", "data: URI holds no bytes; expected an image");
        return;
    }
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

// Fails naming the first of keys that obj lacks: properties glTF 2.0's schema requires, which tinygltf would
// otherwise refuse with a message that names no element (or none at all).
void require(const LoadContext& ctx, const Json& obj, const std::string& element,
             std::initializer_list<std::pair<const char*, const char*>> keys) {
    for (const auto& [key, what] : keys) {
        if (!member(obj, key)) ctx.fail(path(element, key), std::string("missing; expected ") + what + " (required by glTF 2.0)");
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
            const std::string le = std::string("extensions.") + kLightsPunctual;
            forEach(ctx, *lights, "lights", le, [&](const std::string& e, const Json& light) {
                require(ctx, light, e, {{"type", "directional, point or spot"}});
                if (light["type"] == "spot") require(ctx, light, e, {{"spot", "{innerConeAngle, outerConeAngle}"}});
            });
        }
    }
    // Every element of glTF's top-level arrays is an object (forEach says which is not).
    for (const char* name : {"accessors", "animations", "buffers", "bufferViews", "cameras", "images", "materials",
                             "meshes", "nodes", "samplers", "scenes", "skins", "textures"})
        forEach(ctx, d, name, "", [](const std::string&, const Json&) {});
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
        require(ctx, a, e,
                {{"componentType", "the component type (5120..5126)"},
                 {"count", "the number of elements"},
                 {"type", "SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3 or MAT4"}});
        if (integer(ctx, a, "count", 1, e) < 1) ctx.fail(e + ".count", "expected at least 1 element");
        checkOptionalIndex(ctx, a, "bufferView", e, "bufferViews");
        if (const Json* sparse = object(ctx, a, "sparse", e)) {
            std::string se = e + ".sparse";
            require(ctx, *sparse, se,
                    {{"count", "the number of substituted elements"},
                     {"indices", "{bufferView, componentType}"},
                     {"values", "{bufferView}"}});
            if (const Json* idx = object(ctx, *sparse, "indices", se)) {
                require(ctx, *idx, se + ".indices",
                        {{"bufferView", "an index into bufferViews"}, {"componentType", "5121, 5123 or 5125"}});
                checkOptionalIndex(ctx, *idx, "bufferView", se + ".indices", "bufferViews");
            }
            if (const Json* val = object(ctx, *sparse, "values", se)) {
                require(ctx, *val, se + ".values", {{"bufferView", "an index into bufferViews"}});
                checkOptionalIndex(ctx, *val, "bufferView", se + ".values", "bufferViews");
            }
        }
    });
    forEach(ctx, d, "cameras", "", [&](const std::string& e, const Json& c) {
        require(ctx, c, e, {{"type", "perspective or orthographic"}});
        if (c["type"] == "perspective") require(ctx, c, e, {{"perspective", "{yfov, znear}"}});
        if (c["type"] == "orthographic") require(ctx, c, e, {{"orthographic", "{xmag, ymag, zfar, znear}"}});
        if (const Json* p = object(ctx, c, "perspective", e)) {
            require(ctx, *p, e + ".perspective", {{"yfov", "the vertical field of view"}, {"znear", "the near plane"}});
        }
        if (const Json* o = object(ctx, c, "orthographic", e)) {
            require(ctx, *o, e + ".orthographic",
                    {{"xmag", "a number"}, {"ymag", "a number"}, {"zfar", "a number"}, {"znear", "a number"}});
        }
    });
    forEach(ctx, d, "skins", "", [&](const std::string& e, const Json& s) {
        require(ctx, s, e, {{"joints", "a non-empty array of node indices"}});
        const Json& joints = s["joints"];
        if (!joints.is_array() || joints.empty()) ctx.fail(e + ".joints", "expected a non-empty array of node indices");
        for (size_t i = 0; i < joints.size(); ++i)
            checkIndex(ctx, joints[i], e + ".joints[" + std::to_string(i) + "]", "nodes");
        checkOptionalIndex(ctx, s, "skeleton", e, "nodes");
        checkOptionalIndex(ctx, s, "inverseBindMatrices", e, "accessors");
    });
    bool binary = !ctx.glbBin.empty();
    std::vector<uint64_t> bufferLength;
    forEach(ctx, d, "buffers", "", [&](const std::string& e, const Json& b) {
        int64_t length = integer(ctx, b, "byteLength", -1, e);
        if (length < 1) ctx.fail(e + ".byteLength", "missing or < 1; expected the buffer's size in bytes");
        if (readsAsZeros(ctx, b, bufferLength.size())) {
            // Legal (the data may come from elsewhere, or nothing may read it), but vitrine has nothing to read.
            if (static_cast<uint64_t>(length) > kMaxZeroBuffer) {
                ctx.fail(e, "has no data vitrine can read (" + std::to_string(length) +
                                " bytes: no uri, or one that is not a local file); expected a file name or data: URI");
            }
            const Json* uri = member(b, "uri");
            ctx.warn(e, (uri ? "uri '" + uri->get<std::string>() + "' is not a local file (vitrine reads no network)"
                             : std::string("has no uri (only a .glb's first buffer is its binary chunk)")) +
                            "; its bytes (" + std::to_string(length) + ") read as zeros");
        } else if (!member(b, "uri") && !isMeshoptFallback(b)) {
            if (static_cast<uint64_t>(length) > ctx.glbBin.size()) {
                ctx.fail(e + ".byteLength", std::to_string(length) + " bytes, but the GLB binary chunk has " +
                                                std::to_string(ctx.glbBin.size()));
            }
        } else {
            checkExternalFile(ctx, b, e, static_cast<uint64_t>(length));
        }
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
        require(ctx, a, e, {{"channels", "an array of channels"}, {"samplers", "an array of samplers"}});
        forEach(ctx, a, "channels", e, [&](const std::string& ce, const Json& c) {
            require(ctx, c, ce, {{"sampler", "an index into the animation's samplers"}, {"target", "{node, path}"}});
            int64_t s = integer(ctx, c, "sampler", -1, ce);
            if (s < 0 || static_cast<size_t>(s) >= samplerCount) {
                ctx.fail(ce + ".sampler", "index " + std::to_string(s) + " out of range; the animation has " +
                                              std::to_string(samplerCount) + " samplers");
            }
            const Json* target = object(ctx, c, "target", ce);
            if (!target) ctx.fail(ce + ".target", "missing; expected {node, path}");
            require(ctx, *target, ce + ".target", {{"path", "translation, rotation, scale or weights"}});
            checkOptionalIndex(ctx, *target, "node", ce + ".target", "nodes");
        });
        forEach(ctx, a, "samplers", e, [&](const std::string& se, const Json& s) {
            if (!member(s, "input") || !member(s, "output")) ctx.fail(se, "expected input and output accessors");
            checkIndex(ctx, s["input"], se + ".input", "accessors");
            checkIndex(ctx, s["output"], se + ".output", "accessors");
        });
    });
}

void appendU32(std::vector<uint8_t>& out, uint32_t v) {
    for (int i = 0; i < 4; ++i)
        out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}

// What tinygltf cannot read although glTF allows it, rewritten in a copy of the JSON (see LoadContext::tinygltfInput).
void prepareTinygltfInput(LoadContext& ctx) {
    std::optional<Json> copy;
    auto edit = [&]() -> Json& {
        if (!copy) copy = ctx.doc;
        return *copy;
    };
    for (const char* name : {"buffers", "images"}) {
        const Json* list = member(ctx.doc, name);
        for (size_t i = 0; list && i < list->size(); ++i) {
            const Json* uri = member((*list)[i], "uri");
            if (!uri || !uri->is_string()) continue;
            const std::string& s = uri->get_ref<const std::string&>();
            if (s.rfind("data:", 0) != 0 || tinygltf::IsDataURI(s)) continue;
            std::vector<uint8_t> data;
            std::string mediaType, error;
            decodeDataUri(s, data, mediaType, error); // checked by checkExternalFile()
            bool known = mediaType == "image/png" || mediaType == "image/jpeg" || mediaType == "image/bmp" ||
                         mediaType == "image/gif";
            std::string header = std::string(name) == "images" && known ? "data:" + mediaType + ";base64,"
                                                                         : "data:application/octet-stream;base64,";
            edit()[name][i]["uri"] = header + base64Encode(data);
        }
    }
    // An accessor type glTF does not define: the Khronos validator warns, legal while nothing reads the accessor
    // (accessorAt() refuses it then). tinygltf, which refuses the file, is told SCALAR.
    if (const Json* accessors = member(ctx.doc, "accessors")) {
        static const std::set<std::string> types = {"SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4"};
        for (size_t i = 0; i < accessors->size(); ++i) {
            const Json& type = (*accessors)[i]["type"];
            if (type.is_string() && types.count(type.get<std::string>())) continue;
            const std::string e = "accessors[" + std::to_string(i) + "].type";
            ctx.warn(e, type.dump() + " is not SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3 or MAT4; nothing may read this "
                                      "accessor");
            ctx.unknownAccessorTypes[static_cast<int>(i)] = type.dump();
            edit()["accessors"][i]["type"] = "SCALAR";
        }
    }
    // Buffers without data vitrine can read (readsAsZeros) become zeros, as the preflight warned.
    if (const Json* buffers = member(ctx.doc, "buffers")) {
        for (size_t i = 0; i < buffers->size(); ++i) {
            if (!readsAsZeros(ctx, (*buffers)[i], i)) continue;
            const size_t length = (*buffers)[i]["byteLength"].get<size_t>();
            edit()["buffers"][i]["uri"] =
                "data:application/octet-stream;base64," + base64Encode(std::vector<uint8_t>(length, 0));
        }
    }
    // EXT_meshopt_compression, which tinygltf does not know: its views decoded into a buffer of their own.
    decodeMeshoptCompression(ctx, edit);
    // tinygltf refuses an index accessor without a bufferView (glTF: all zeros, plus sparse values).
    const Json* meshes = member(ctx.doc, "meshes");
    const Json* accessors = member(ctx.doc, "accessors");
    for (size_t m = 0; meshes && accessors && m < meshes->size(); ++m) {
        const Json* prims = member((*meshes)[m], "primitives");
        for (size_t p = 0; prims && p < prims->size(); ++p) {
            const Json* indices = member((*prims)[p], "indices");
            if (indices && !member((*accessors)[indices->get<size_t>()], "bufferView"))
                edit()["meshes"][m]["primitives"][p].erase("indices");
        }
    }
    if (!copy && ctx.integersRewritten) copy = ctx.doc; // tinygltf reads some integer properties as integers only
    if (!copy) return;
    // Invalid UTF-8 in a string (a name, say) is replaced rather than thrown on: tinygltf gets valid JSON either way.
    std::string text = copy->dump(-1, ' ', false, Json::error_handler_t::replace);
    if (!ctx.glb) {
        ctx.tinygltfInput.assign(text.begin(), text.end());
        return;
    }
    while (text.size() % 4 != 0)
        text += ' ';
    std::vector<uint8_t>& out = ctx.tinygltfInput;
    uint64_t total = 12 + 8 + text.size() + (ctx.glbBin.empty() ? 0 : 8 + ctx.glbBin.size());
    if (total > UINT32_MAX) ctx.fail("GLB", "too large to rewrite for its data: URIs (over 4 GiB)");
    appendU32(out, kGlbMagic);
    appendU32(out, 2);
    appendU32(out, static_cast<uint32_t>(total));
    appendU32(out, static_cast<uint32_t>(text.size()));
    appendU32(out, kChunkJson);
    out.insert(out.end(), text.begin(), text.end());
    if (!ctx.glbBin.empty()) {
        appendU32(out, static_cast<uint32_t>(ctx.glbBin.size()));
        appendU32(out, kChunkBin);
        out.insert(out.end(), ctx.glbBin.begin(), ctx.glbBin.end());
    }
}

} // namespace

std::vector<uint8_t> readGltfFile(const LoadContext& ctx, const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw UserError(ctx.file + ": cannot open the file (does it exist and is it readable?)");
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

namespace {

// glTF's integer properties (indices, counts, sizes, enums) wherever they stand, the core's and the extensions' that
// vitrine reads.
bool isIntegerKey(const std::string& key) {
    static const std::set<std::string> keys = {"buffer",     "byteLength",
                                               "byteOffset", "byteStride",
                                               "count",      "componentType",
                                               "mode",       "target",
                                               "indices",    "material",
                                               "mesh",       "skin",
                                               "camera",     "node",
                                               "sampler",    "input",
                                               "output",     "source",
                                               "index",      "texCoord",
                                               "bufferView", "scene",
                                               "children",   "joints",
                                               "skeleton",   "inverseBindMatrices",
                                               "magFilter",  "minFilter",
                                               "wrapS",      "wrapT",
                                               "nodes",      "light",
                                               "variants"};
    return keys.count(key) > 0;
}

// An integral number written as a float (1.0, 1e0, 10e-1), which JSON does not tell from 1 and the Khronos validator
// accepts, made an integer. Whether it changed anything.
bool makeInteger(Json& v) {
    if (!v.is_number_float()) return false;
    const double d = v.get<double>();
    if (!std::isfinite(d) || d != std::trunc(d) || std::abs(d) > 9007199254740992.0) return false;
    if (d >= 0.0)
        v = static_cast<uint64_t>(d);
    else
        v = static_cast<int64_t>(d);
    return true;
}

// makeInteger() on the integer properties under v (key: the property v is the value of); extras are the file's own.
bool integersAsIntegers(Json& v, const std::string& key) {
    bool changed = false;
    if (v.is_object()) {
        for (auto it = v.begin(); it != v.end(); ++it) {
            if (it.key() == "extras") continue;
            if (it.key() == "attributes" && it->is_object()) {
                for (Json& a : *it)
                    changed = makeInteger(a) || changed;
            } else if (it.key() == "targets" && it->is_array()) {
                for (Json& t : *it) {
                    for (Json& a : t)
                        changed = makeInteger(a) || changed;
                }
            } else {
                changed = integersAsIntegers(*it, it.key()) || changed;
            }
        }
    } else if (v.is_array()) {
        for (Json& e : v)
            changed = integersAsIntegers(e, key) || changed;
    } else if (isIntegerKey(key)) {
        changed = makeInteger(v);
    }
    return changed;
}

} // namespace

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
    ctx.integersRewritten = integersAsIntegers(ctx.doc, "");
    const Json* asset = object(ctx, ctx.doc, "asset", "");
    if (!asset) ctx.fail("asset", "missing; expected {\"version\": \"2.0\"}");
    std::string version = string(ctx, *asset, "version", "", "asset");
    if (version.rfind("2.", 0) != 0) ctx.fail("asset.version", "'" + version + "'; expected \"2.0\"");
    checkRequiredExtensions(ctx);
    checkUsedExtensions(ctx);
    checkReferences(ctx);
    prepareTinygltfInput(ctx);
}

} // namespace vitrine::scene::gltf
