#pragma once
// The `multiscatter` param of lighting.deferred and forward.transparent (off / environment / all) as the shaders'
// defines: VITRINE_MULTISCATTER compensates the GGX lobe for every light (common/brdf.glsl ggxSpecular*),
// VITRINE_MULTISCATTER_ENVIRONMENT the split sum's environment term. Without either the shaders are the
// single-scattering ones to the bit.
#include "core/graph/node.hpp"
#include "core/shader/compiler.hpp"

namespace vitrine {

inline ShaderDefines multiscatterDefines(const Params& p) {
    const std::string mode = p.getString("multiscatter");
    ShaderDefines d;
    if (mode == "environment" || mode == "all") d.push_back({"VITRINE_MULTISCATTER_ENVIRONMENT", "1"});
    if (mode == "all") d.push_back({"VITRINE_MULTISCATTER", "1"});
    return d;
}

} // namespace vitrine
