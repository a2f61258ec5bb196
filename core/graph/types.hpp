#pragma once

#include <vulkan/vulkan.h>

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace vitrine {

enum class PortKind { Texture, Buffer, Scene, Camera };
const char* toString(PortKind kind);

// How a pass touches a resource. The compiler derives layouts, stages and access masks from it;
// nodes never name layouts or issue barriers themselves. DepthRead: a read-only depth attachment that the same
// pass also samples (DEPTH_STENCIL_READ_ONLY_OPTIMAL): light volumes depth-test against it and rebuild positions.
enum class Usage {
    Sampled,
    StorageRead,
    StorageWrite,
    StorageReadWrite,
    ColorAttachment,
    DepthAttachment,
    DepthRead,
    TransferSrc,
    TransferDst
};
enum class PassKind { Compute, Raster, Transfer };

// Size of an output texture as data (after Granite): relative to the frame, relative to an
// input, or absolute. setup() may still override it (image.load takes the file's size).
struct SizeRule {
    enum class Mode { Frame, Input, Absolute };
    Mode mode = Mode::Frame;
    float scale = 1.0f;
    std::string input;
    uint32_t width = 0;
    uint32_t height = 0;

    static SizeRule frame(float scale = 1.0f) { return {Mode::Frame, scale, {}, 0, 0}; }
    static SizeRule ofInput(std::string name, float scale = 1.0f) { return {Mode::Input, scale, std::move(name), 0, 0}; }
    static SizeRule absolute(uint32_t w, uint32_t h) { return {Mode::Absolute, 1.0f, {}, w, h}; }
};

struct InputPort {
    std::string name;
    PortKind kind = PortKind::Texture;
    std::vector<VkFormat> formats; // empty: any
    bool optional = false;
    Usage usage = Usage::Sampled;
    std::string doc;
    // The node also copies this input to the host (after ExecuteContext::splitSubmission, with readImage): its
    // image gets VK_IMAGE_USAGE_TRANSFER_SRC_BIT.
    bool readBack = false;
};

struct OutputPort {
    std::string name;
    PortKind kind = PortKind::Texture;
    VkFormat format = VK_FORMAT_R16G16B16A16_SFLOAT;
    std::string formatFrom; // non-empty: same format as this input
    SizeRule size;
    Usage usage = Usage::StorageWrite;
    bool persistent = false; // contents survive across frames (uploaded once, accumulated, ...)
    std::string doc;
    // The node copies this output to the host itself (after ExecuteContext::splitSubmission, with readImage):
    // its image gets VK_IMAGE_USAGE_TRANSFER_SRC_BIT.
    bool readBack = false;
};

enum class ParamType { Bool, Int, Float, Vec2, Vec3, Vec4, String, Enum, Path };
const char* toString(ParamType type);

struct ParamSpec {
    std::string name;
    ParamType type = ParamType::Float;
    nlohmann::json defaultValue;
    std::optional<double> min;
    std::optional<double> max;
    std::vector<std::string> choices; // Enum
    std::string doc;
};

// The description half of a node: everything the loader, validator, editor and docs need.
struct NodeSchema {
    std::string type;
    std::string doc;
    PassKind pass = PassKind::Compute;
    std::vector<InputPort> inputs;
    std::vector<OutputPort> outputs;
    std::vector<ParamSpec> params;

    const InputPort* findInput(const std::string& name) const;
    const OutputPort* findOutput(const std::string& name) const;
    const ParamSpec* findParam(const std::string& name) const;
    nlohmann::json toJson() const;
};

// Checks `value` against `spec`; returns an empty string when valid, else what was expected.
std::string checkParam(const ParamSpec& spec, const nlohmann::json& value);

} // namespace vitrine
