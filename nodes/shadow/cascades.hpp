#pragma once
// What shadow.directional hands to lighting nodes on its `cascades` port (a Buffer-kind object): the
// per-frame cascade matrices and filter parameters, uploaded by the consumer as uniforms.
#include "core/graph/node.hpp"
#include "shaders/shadow/cascades.h"

namespace vitrine {

class ShadowCascadesObject final : public PortObject {
public:
    gpu_types::ShadowCascades data{};
};

} // namespace vitrine
