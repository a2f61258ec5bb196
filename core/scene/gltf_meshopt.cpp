// EXT_meshopt_compression (github.com/KhronosGroup/glTF/tree/main/extensions/2.0/Vendor/EXT_meshopt_compression):
// bufferViews whose bytes are stored compressed by meshoptimizer's codecs, in another buffer; the view's own buffer
// is often a "fallback" that holds no data. tinygltf knows nothing of it, so the preflight decodes every compressed
// view (Debian's libmeshoptimizer, the codec's reference implementation) into one new buffer and points the views
// there: tinygltf and the accessor code then read plain bytes.

#include "core/scene/gltf_detail.hpp"

#include <meshoptimizer.h>

#include <fstream>
#include <iterator>
#include <map>
#include <optional>

namespace vitrine::scene::gltf {

namespace {

constexpr int64_t kMaxDecodedBytes = int64_t(1) << 30;
constexpr const char* kModes = "\"ATTRIBUTES\", \"TRIANGLES\" or \"INDICES\"";
constexpr const char* kFilters = "\"NONE\", \"OCTAHEDRAL\", \"QUATERNION\" or \"EXPONENTIAL\"";

// The bytes of buffer `index`: a GLB's binary chunk (its buffer 0 without a uri), a data: URI or a file beside the
// glTF (checked to exist and to be long enough by the preflight). Empty when the buffer has no data of its own.
std::vector<uint8_t> bufferBytes(const LoadContext& ctx, uint32_t index) {
    const Json& buffer = ctx.doc["buffers"][index];
    const std::string element = "buffers[" + std::to_string(index) + "]";
    const Json* uri = member(buffer, "uri");
    if (!uri) return index == 0 && ctx.glb ? ctx.glbBin : std::vector<uint8_t>();
    const std::string s = uri->get<std::string>();
    std::vector<uint8_t> bytes;
    if (s.rfind("data:", 0) == 0) {
        std::string mediaType, error;
        if (!decodeDataUri(s, bytes, mediaType, error)) ctx.fail(element + ".uri", error);
        return bytes;
    }
    std::ifstream in(ctx.baseDir / urlDecode(s), std::ios::binary);
    if (!in) ctx.fail(element + ".uri", "cannot read '" + s + "'");
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// One compressed view decoded into `out` (count × byteStride bytes), its fields checked as the extension's spec
// states them.
void decodeView(const LoadContext& ctx, const Json& view, const std::string& viewElement, const Json& ext,
                const std::string& element, const std::function<const std::vector<uint8_t>&(uint32_t)>& source,
                std::vector<uint8_t>& out) {
    for (const char* key : {"buffer", "byteLength", "byteStride", "count", "mode"}) {
        if (!member(ext, key)) ctx.fail(path(element, key), "missing; required by EXT_meshopt_compression");
    }
    const uint32_t buffer = checkIndex(ctx, ext["buffer"], path(element, "buffer"), "buffers");
    const int64_t offset = integer(ctx, ext, "byteOffset", 0, element);
    const int64_t length = integer(ctx, ext, "byteLength", 0, element);
    const int64_t stride = integer(ctx, ext, "byteStride", 0, element);
    const int64_t count = integer(ctx, ext, "count", 0, element);
    const std::string mode = string(ctx, ext, "mode", "", element);
    const std::string filter = string(ctx, ext, "filter", "NONE", element);
    if (offset < 0) ctx.fail(path(element, "byteOffset"), std::to_string(offset) + "; expected >= 0");
    if (length < 1) ctx.fail(path(element, "byteLength"), std::to_string(length) + "; expected >= 1");
    if (count < 1) ctx.fail(path(element, "count"), std::to_string(count) + "; expected >= 1");
    if (mode != "ATTRIBUTES" && mode != "TRIANGLES" && mode != "INDICES")
        ctx.fail(path(element, "mode"), "'" + mode + "'; expected " + kModes);
    if (filter != "NONE" && filter != "OCTAHEDRAL" && filter != "QUATERNION" && filter != "EXPONENTIAL")
        ctx.fail(path(element, "filter"), "'" + filter + "'; expected " + kFilters);
    if (mode == "ATTRIBUTES" && (stride < 4 || stride > 256 || stride % 4 != 0))
        ctx.fail(path(element, "byteStride"),
                 std::to_string(stride) + "; mode ATTRIBUTES expects a multiple of 4 up to 256");
    if (mode != "ATTRIBUTES" && stride != 2 && stride != 4)
        ctx.fail(path(element, "byteStride"), std::to_string(stride) + "; mode " + mode + " expects 2 or 4");
    if (mode == "TRIANGLES" && count % 3 != 0)
        ctx.fail(path(element, "count"), std::to_string(count) + "; mode TRIANGLES expects a multiple of 3");
    if (filter != "NONE" && mode != "ATTRIBUTES")
        ctx.fail(path(element, "filter"), "'" + filter + "' with mode " + mode + "; filters apply to ATTRIBUTES only");
    if (filter == "OCTAHEDRAL" && stride != 4 && stride != 8)
        ctx.fail(path(element, "byteStride"), std::to_string(stride) + "; filter OCTAHEDRAL expects 4 or 8");
    if (filter == "QUATERNION" && stride != 8)
        ctx.fail(path(element, "byteStride"), std::to_string(stride) + "; filter QUATERNION expects 8");
    const int64_t viewLength = integer(ctx, view, "byteLength", 0, viewElement);
    if (viewLength > kMaxDecodedBytes)
        ctx.fail(path(viewElement, "byteLength"),
                 std::to_string(viewLength) + "; vitrine decodes views of up to 1 GiB");
    if (count * stride != viewLength) {
        ctx.fail(path(element, "count"), std::to_string(count) + " × byteStride " + std::to_string(stride) + " = " +
                                             std::to_string(count * stride) +
                                             " bytes decoded; expected the bufferView's byteLength " +
                                             std::to_string(viewLength));
    }
    const std::vector<uint8_t>& bytes = source(buffer);
    if (static_cast<uint64_t>(offset + length) > bytes.size()) {
        ctx.fail(element, "bytes " + std::to_string(offset) + " to " + std::to_string(offset + length) + " of buffer " +
                              std::to_string(buffer) + ", which holds " + std::to_string(bytes.size()) +
                              (bytes.empty() ? " (no data: a fallback buffer, or a buffer without a uri)" : ""));
    }
    out.assign(static_cast<size_t>(count * stride), 0);
    const unsigned char* in = bytes.data() + offset;
    int rc = 0;
    const char* codec = nullptr;
    if (mode == "ATTRIBUTES") {
        codec = "meshopt_decodeVertexBuffer";
        rc = meshopt_decodeVertexBuffer(out.data(), count, stride, in, length);
    } else if (mode == "TRIANGLES") {
        codec = "meshopt_decodeIndexBuffer";
        rc = meshopt_decodeIndexBuffer(out.data(), count, stride, in, length);
    } else {
        codec = "meshopt_decodeIndexSequence";
        rc = meshopt_decodeIndexSequence(out.data(), count, stride, in, length);
    }
    if (rc != 0) {
        ctx.fail(element, "the " + std::to_string(length) + " compressed bytes do not decode as mode " + mode + " (" +
                              codec + " returned " + std::to_string(rc) +
                              "): corrupt data, or an encoding newer than libmeshoptimizer " +
                              std::to_string(MESHOPTIMIZER_VERSION / 1000) + "." + // 180: 0.18
                              std::to_string(MESHOPTIMIZER_VERSION % 1000 / 10) + " reads");
    }
    if (filter == "OCTAHEDRAL") meshopt_decodeFilterOct(out.data(), count, stride);
    if (filter == "QUATERNION") meshopt_decodeFilterQuat(out.data(), count, stride);
    if (filter == "EXPONENTIAL") meshopt_decodeFilterExp(out.data(), count, stride);
}

} // namespace

bool isMeshoptFallback(const Json& buffer) {
    const Json* ext = member(buffer, "extensions");
    const Json* meshopt = ext && ext->is_object() ? member(*ext, kMeshopt) : nullptr;
    const Json* fallback = meshopt && meshopt->is_object() ? member(*meshopt, "fallback") : nullptr;
    return fallback && fallback->is_boolean() && fallback->get<bool>();
}

void decodeMeshoptCompression(const LoadContext& ctx, const std::function<Json&()>& edit) {
    const Json* views = member(ctx.doc, "bufferViews");
    if (!views) return;
    std::map<uint32_t, std::vector<uint8_t>> sources; // each compressed buffer read once
    auto source = [&](uint32_t index) -> const std::vector<uint8_t>& {
        auto it = sources.find(index);
        if (it == sources.end()) it = sources.emplace(index, bufferBytes(ctx, index)).first;
        return it->second;
    };
    std::vector<uint8_t> decoded;                  // the new buffer
    std::vector<std::pair<size_t, size_t>> placed; // (view, its byteOffset in `decoded`)
    for (size_t i = 0; i < views->size(); ++i) {
        const Json& view = (*views)[i];
        const Json* ext = member(view, "extensions");
        const Json* meshopt = ext && ext->is_object() ? member(*ext, kMeshopt) : nullptr;
        if (!meshopt) continue;
        const std::string element = "bufferViews[" + std::to_string(i) + "].extensions." + kMeshopt;
        if (!meshopt->is_object()) ctx.fail(element, "expected a JSON object");
        std::vector<uint8_t> bytes;
        decodeView(ctx, view, "bufferViews[" + std::to_string(i) + "]", *meshopt, element, source, bytes);
        if (static_cast<int64_t>(decoded.size() + bytes.size()) > 2 * kMaxDecodedBytes)
            ctx.fail(element, "the file's compressed views decode to over 2 GiB; vitrine decodes up to that");
        decoded.resize((decoded.size() + 15) / 16 * 16); // every view 16-byte aligned, as any accessor needs
        placed.emplace_back(i, decoded.size());
        decoded.insert(decoded.end(), bytes.begin(), bytes.end());
    }
    if (placed.empty()) return;

    Json& doc = edit();
    const size_t buffer = doc["buffers"].size();
    Json out = Json::object();
    out["byteLength"] = decoded.size();
    out["uri"] = "data:application/octet-stream;base64," + base64Encode(decoded);
    doc["buffers"].push_back(std::move(out));
    std::vector<bool> compressed(views->size(), false);
    for (const auto& [i, offset] : placed) {
        Json& view = doc["bufferViews"][i];
        view["buffer"] = buffer;
        view["byteOffset"] = offset;
        view["extensions"].erase(kMeshopt);
        if (view["extensions"].empty()) view.erase("extensions");
        compressed[i] = true;
    }
    // Fallback buffers without data: nothing reads them now but tinygltf loads every buffer, and one without a uri
    // (other than a GLB's first) is an error to it.
    for (size_t b = 0; b < buffer; ++b) {
        Json& entry = doc["buffers"][b];
        if (!isMeshoptFallback(entry) || member(entry, "uri") || (b == 0 && ctx.glb)) continue;
        for (size_t i = 0; i < views->size(); ++i) {
            const Json* target = member((*views)[i], "buffer");
            if (!compressed[i] && target && target->is_number_unsigned() && target->get<size_t>() == b) {
                ctx.fail("bufferViews[" + std::to_string(i) + "].buffer",
                         std::to_string(b) + ": an EXT_meshopt_compression fallback buffer, which holds no data, read "
                                             "by a view that is not compressed");
            }
        }
        entry["byteLength"] = 1;
        entry["uri"] = "data:application/octet-stream;base64,AA==";
    }
}

} // namespace vitrine::scene::gltf
