// Accessor reads with every byte range checked against its buffer view and buffer.

#include "core/scene/gltf_detail.hpp"

#include <cmath>
#include <cstring>

#include <tiny_gltf.h>

namespace vitrine::scene::gltf {

namespace {

constexpr size_t kMaxZeroElements = size_t(1) << 26;

int componentSize(int type) {
    switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return 4;
    default:
        return 0;
    }
}

int componentCount(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR:
        return 1;
    case TINYGLTF_TYPE_VEC2:
        return 2;
    case TINYGLTF_TYPE_VEC3:
        return 3;
    case TINYGLTF_TYPE_VEC4:
        return 4;
    case TINYGLTF_TYPE_MAT2:
        return 4;
    case TINYGLTF_TYPE_MAT3:
        return 9;
    case TINYGLTF_TYPE_MAT4:
        return 16;
    default:
        return 0;
    }
}

float readComponent(const uint8_t* p, int type, bool normalized) {
    switch (type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float f;
        std::memcpy(&f, p, 4);
        return f;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        auto v = static_cast<int8_t>(*p);
        return normalized ? std::max(v / 127.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return normalized ? *p / 255.0f : float(*p);
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? std::max(v / 32767.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? v / 65535.0f : float(v);
    }
    default: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return normalized ? float(v / 4294967295.0) : float(v);
    }
    }
}

uint32_t readUnsigned(const uint8_t* p, int type) {
    if (type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) return *p;
    if (type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return v;
    }
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

// The bytes of count elements of elementSize bytes, stride apart, from byteOffset into bufferView; fails
// unless all of them lie inside the view and the view inside its buffer.
const uint8_t* viewBytes(const LoadContext& ctx, int viewIndex, uint64_t byteOffset, uint64_t count,
                         uint64_t elementSize, uint64_t& stride, const std::string& element) {
    const tinygltf::Model& model = *ctx.model;
    std::string ve = "bufferViews[" + std::to_string(viewIndex) + "]";
    if (viewIndex < 0 || static_cast<size_t>(viewIndex) >= model.bufferViews.size()) {
        ctx.fail(element, ve + " does not exist");
    }
    const tinygltf::BufferView& view = model.bufferViews[viewIndex];
    if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model.buffers.size())
        ctx.fail(ve, "buffer does not exist");
    const tinygltf::Buffer& buffer = model.buffers[view.buffer];
    if (uint64_t(view.byteOffset) + view.byteLength > buffer.data.size()) {
        ctx.fail(ve, "bytes " + std::to_string(view.byteOffset) + ".." +
                         std::to_string(view.byteOffset + view.byteLength) + " exceed buffers[" +
                         std::to_string(view.buffer) + "], which holds " + std::to_string(buffer.data.size()) +
                         " bytes");
    }
    stride = view.byteStride ? view.byteStride : elementSize;
    if (stride < elementSize) {
        ctx.fail(element, ve + ".byteStride " + std::to_string(stride) + " is smaller than an element (" +
                              std::to_string(elementSize) + " bytes)");
    }
    // The last element must end inside the view; written to avoid overflow for absurd counts.
    bool fits = count == 0 || (byteOffset + elementSize <= view.byteLength &&
                               (count - 1) <= (view.byteLength - byteOffset - elementSize) / stride);
    if (!fits) {
        ctx.fail(element, std::to_string(count) + " elements of " + std::to_string(elementSize) + " bytes, stride " +
                              std::to_string(stride) + ", from byte " + std::to_string(byteOffset) + " exceed " + ve +
                              " (" + std::to_string(view.byteLength) +
                              " bytes); expected the accessor to fit inside its buffer view");
    }
    return buffer.data.data() + view.byteOffset + byteOffset;
}

const tinygltf::Accessor& accessorAt(const LoadContext& ctx, int index, const std::string& element) {
    if (index < 0 || static_cast<size_t>(index) >= ctx.model->accessors.size()) {
        ctx.fail(element, "accessor index " + std::to_string(index) + " out of range");
    }
    if (auto it = ctx.unknownAccessorTypes.find(index); it != ctx.unknownAccessorTypes.end()) {
        ctx.fail(element, "reads accessors[" + std::to_string(index) + "], whose type '" + it->second +
                              "' is not SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3 or MAT4");
    }
    return ctx.model->accessors[index];
}

// Calls set(target, valueBytes) for each of a sparse accessor's substitutions, in file order, after checking its
// count, index type and byte ranges (glTF: sparse indices and values are tightly packed).
template <typename F>
void forEachSparse(const LoadContext& ctx, const tinygltf::Accessor& a, uint64_t elementSize, const std::string& element,
                   F set) {
    std::string se = element + ".sparse";
    uint64_t n = a.sparse.count > 0 ? uint64_t(a.sparse.count) : 0;
    if (n == 0 || n > a.count) ctx.fail(se + ".count", "expected 1.." + std::to_string(a.count));
    int itype = a.sparse.indices.componentType;
    if (itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
        ctx.fail(se + ".indices.componentType", "expected an unsigned integer type");
    }
    uint64_t istride = 0, vstride = 0;
    const uint8_t* ip = viewBytes(ctx, a.sparse.indices.bufferView, a.sparse.indices.byteOffset, n,
                                  componentSize(itype), istride, se + ".indices");
    const uint8_t* vp =
        viewBytes(ctx, a.sparse.values.bufferView, a.sparse.values.byteOffset, n, elementSize, vstride, se + ".values");
    istride = componentSize(itype); // sparse data is tightly packed whatever the view says
    vstride = elementSize;
    for (uint64_t k = 0; k < n; ++k) {
        uint32_t target = readUnsigned(ip + k * istride, itype);
        if (target >= a.count) {
            ctx.fail(se + ".indices", "index " + std::to_string(target) + " at position " + std::to_string(k) +
                                          " >= count " + std::to_string(a.count));
        }
        set(target, vp + k * vstride);
    }
}

} // namespace

glm::vec4 AccessorValues::get(size_t i) const {
    glm::vec4 v(0.0f);
    for (int c = 0; c < components && c < 4; ++c)
        v[c] = data[i * components + c];
    return v;
}

AccessorValues readAccessor(const LoadContext& ctx, int index, const std::string& use,
                            std::initializer_list<int> allowedComponents, bool floatOnly) {
    const tinygltf::Accessor& a = accessorAt(ctx, index, use);
    std::string element = use + " (accessors[" + std::to_string(index) + "])";
    int csize = componentSize(a.componentType);
    int comps = componentCount(a.type);
    if (csize == 0) ctx.fail(element, "unknown componentType " + std::to_string(a.componentType));
    if (floatOnly && a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT) ctx.fail(element, "expected FLOAT components");
    bool allowed = false;
    for (int c : allowedComponents)
        allowed = allowed || c == comps;
    if (!allowed) {
        std::string list;
        for (int c : allowedComponents)
            list += (list.empty() ? "" : " or ") + std::to_string(c);
        ctx.fail(element, "has " + std::to_string(comps) + " components; expected " + list);
    }
    if (a.count == 0) ctx.fail(element, "count is 0; expected at least one element");

    // Without a buffer view the data is zeros (plus sparse values): nothing bounds the count but sense.
    if (a.bufferView < 0 && a.count > kMaxZeroElements) {
        ctx.fail(element, "count " + std::to_string(a.count) + " without a bufferView; expected at most " +
                              std::to_string(kMaxZeroElements));
    }
    uint64_t stride = 0;
    const uint8_t* base = a.bufferView >= 0 ? viewBytes(ctx, a.bufferView, a.byteOffset, a.count,
                                                        uint64_t(csize) * comps, stride, element)
                                            : nullptr;
    AccessorValues out; // allocated only once the count is known to be backed by data
    out.count = a.count;
    out.components = comps;
    out.data.assign(a.count * comps, 0.0f);
    if (base) {
        for (size_t i = 0; i < a.count; ++i) {
            for (int c = 0; c < comps; ++c) {
                out.data[i * comps + c] = readComponent(base + i * stride + c * csize, a.componentType, a.normalized);
            }
        }
    }
    if (a.sparse.isSparse) {
        forEachSparse(ctx, a, uint64_t(csize) * comps, element, [&](uint32_t target, const uint8_t* value) {
            for (int c = 0; c < comps; ++c)
                out.data[target * comps + c] = readComponent(value + c * csize, a.componentType, a.normalized);
        });
    }
    for (size_t i = 0; i < out.data.size(); ++i) {
        if (!std::isfinite(out.data[i])) {
            ctx.fail(element, "element " + std::to_string(i / comps) + " is not a finite number");
        }
    }
    return out;
}

std::vector<uint32_t> readIndices(const LoadContext& ctx, int index, const std::string& use) {
    const tinygltf::Accessor& a = accessorAt(ctx, index, use);
    std::string element = use + " (accessors[" + std::to_string(index) + "])";
    int t = a.componentType;
    if (t != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && t != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        t != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
        ctx.fail(element,
                 "componentType " + std::to_string(t) + "; expected UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
    }
    if (a.type != TINYGLTF_TYPE_SCALAR) ctx.fail(element, "expected type SCALAR");
    if (a.count == 0) ctx.fail(element, "count is 0; expected at least one index");
    // Without a bufferView the indices are zeros (glTF 2.0, 3.6.2.3), then the sparse substitutions if any.
    if (a.bufferView < 0 && a.count > kMaxZeroElements) {
        ctx.fail(element, "count " + std::to_string(a.count) + " without a bufferView; expected at most " +
                              std::to_string(kMaxZeroElements));
    }
    std::vector<uint32_t> out(a.count, 0u);
    if (a.bufferView >= 0) {
        uint64_t stride = 0;
        const uint8_t* base = viewBytes(ctx, a.bufferView, a.byteOffset, a.count, componentSize(t), stride, element);
        for (size_t i = 0; i < a.count; ++i)
            out[i] = readUnsigned(base + i * stride, t);
    }
    if (a.sparse.isSparse) {
        forEachSparse(ctx, a, componentSize(t), element,
                      [&](uint32_t target, const uint8_t* value) { out[target] = readUnsigned(value, t); });
    }
    return out;
}

} // namespace vitrine::scene::gltf
