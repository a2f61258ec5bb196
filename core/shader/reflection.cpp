#include "core/shader/reflection.hpp"

#include "core/base/error.hpp"

#include <glslang/Include/Types.h>
#include <glslang/Public/ShaderLang.h>
#include <nlohmann/json.hpp>

#include <algorithm>

namespace vitrine {

namespace {

VkDescriptorType descriptorTypeOf(const glslang::TType& type) {
    if (type.getBasicType() != glslang::EbtSampler) return VK_DESCRIPTOR_TYPE_MAX_ENUM;
    const glslang::TSampler& s = type.getSampler();
    if (s.isImage()) return s.isBuffer() ? VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    if (s.isBuffer()) return VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
    if (s.isPureSampler()) return VK_DESCRIPTOR_TYPE_SAMPLER;
    if (s.isCombined()) return VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    return VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
}

uint32_t setOf(const glslang::TType& type) {
    const auto& q = type.getQualifier();
    return q.hasSet() ? q.layoutSet : 0;
}

} // namespace

ShaderReflection reflect(const glslang::TProgram& program, VkShaderStageFlagBits stage) {
    ShaderReflection r;
    r.stage = stage;
    for (int i = 0; i < program.getNumUniformVariables(); ++i) {
        const glslang::TObjectReflection& u = program.getUniform(i);
        const glslang::TType* type = u.getType();
        if (!type) continue;
        VkDescriptorType dt = descriptorTypeOf(*type);
        if (dt == VK_DESCRIPTOR_TYPE_MAX_ENUM) continue; // members of blocks are reported too
        ShaderBinding b;
        b.name = u.name;
        b.set = setOf(*type);
        b.binding = static_cast<uint32_t>(u.getBinding());
        b.type = dt;
        b.count = type->isArray() ? static_cast<uint32_t>(std::max(1, type->getOuterArraySize())) : 1;
        r.bindings.push_back(b);
    }
    for (int i = 0; i < program.getNumUniformBlocks(); ++i) {
        const glslang::TObjectReflection& u = program.getUniformBlock(i);
        const glslang::TType* type = u.getType();
        if (type && type->getQualifier().isPushConstant()) {
            r.pushConstantSize = static_cast<uint32_t>(u.size);
            continue;
        }
        ShaderBinding b;
        b.name = u.name;
        b.set = type ? setOf(*type) : 0;
        b.binding = static_cast<uint32_t>(u.getBinding());
        b.type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
        r.bindings.push_back(b);
    }
    for (int i = 0; i < program.getNumBufferBlocks(); ++i) {
        const glslang::TObjectReflection& u = program.getBufferBlock(i);
        ShaderBinding b;
        b.name = u.name;
        b.set = u.getType() ? setOf(*u.getType()) : 0;
        b.binding = static_cast<uint32_t>(u.getBinding());
        b.type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        r.bindings.push_back(b);
    }
    if (stage == VK_SHADER_STAGE_COMPUTE_BIT)
        for (int d = 0; d < 3; ++d) r.localSize[d] = program.getLocalSize(d);
    std::sort(r.bindings.begin(), r.bindings.end(),
              [](const auto& a, const auto& b) { return std::tie(a.set, a.binding) < std::tie(b.set, b.binding); });
    return r;
}

std::string reflectionToJson(const ShaderReflection& r) {
    nlohmann::json j;
    j["stage"] = static_cast<uint32_t>(r.stage);
    j["pushConstantSize"] = r.pushConstantSize;
    j["localSize"] = {r.localSize[0], r.localSize[1], r.localSize[2]};
    j["bindings"] = nlohmann::json::array();
    for (const auto& b : r.bindings)
        j["bindings"].push_back(
            {{"name", b.name}, {"set", b.set}, {"binding", b.binding}, {"type", static_cast<int>(b.type)}, {"count", b.count}});
    return j.dump();
}

bool reflectionFromJson(const std::string& text, ShaderReflection& r) {
    auto j = nlohmann::json::parse(text, nullptr, false);
    if (j.is_discarded() || !j.is_object()) return false;
    try {
        r.stage = static_cast<VkShaderStageFlagBits>(j.at("stage").get<uint32_t>());
        r.pushConstantSize = j.at("pushConstantSize").get<uint32_t>();
        for (int d = 0; d < 3; ++d) r.localSize[d] = j.at("localSize").at(d).get<uint32_t>();
        r.bindings.clear();
        for (const auto& b : j.at("bindings"))
            r.bindings.push_back({b.at("name").get<std::string>(), b.at("set").get<uint32_t>(),
                                  b.at("binding").get<uint32_t>(), static_cast<VkDescriptorType>(b.at("type").get<int>()),
                                  b.at("count").get<uint32_t>()});
    } catch (const nlohmann::json::exception&) {
        return false;
    }
    return true;
}

const ShaderBinding* findBinding(const ShaderReflection& reflection, const std::string& name) {
    for (const auto& b : reflection.bindings)
        if (b.name == name) return &b;
    return nullptr;
}

} // namespace vitrine
