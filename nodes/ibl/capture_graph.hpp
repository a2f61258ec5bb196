#pragma once
// The graph ibl.capture runs for every face of every probe: the frame's own G-buffer, sun-shadow and deferred-lighting
// nodes (gbuffer.layered -> shadow.directional -> lighting.deferred), fed by a view node that hands them the parent
// graph's scene, sky and baked lighting and a 90-degree camera at the probe for each frame. Frame f of the inner
// graph is face f % 6 of probe f / 6; its output `color` is that face's lit radiance.
#include "core/graph/compiler.hpp"
#include "core/graph/registry.hpp"
#include "core/image/image.hpp"
#include "core/scene/gpu_scene.hpp"

#include <glm/glm.hpp>

#include <memory>
#include <optional>
#include <vector>

namespace vitrine {

class BakedLightingObject;

// What the parent graph lends the capture: its scene (the capture uploads its own GPU copy, so the parent's
// camera and pose are left alone), its sky and baked lighting read back as images.
struct CaptureInputs {
    std::shared_ptr<const scene::Scene> scene;
    float anisotropy = 1.0f;
    double time = 0.0; // the scene's pose at this time
    std::vector<Image> sky; // 6 faces
    Image skySh;
    std::optional<Image> lightmap, volume;
    std::shared_ptr<BakedLightingObject> baked; // with lightmap and volume
};

// The lighting nodes' params (they match the frame's lighting nodes when the graph author sets them alike).
struct CaptureLighting {
    uint32_t size = 32;
    float znear = 0.05f;
    float skyAmbient = 0.15f, sunScale = 1.0f, emissiveScale = 1.0f;
    bool shadows = true;
    uint32_t shadowResolution = 512, shadowCascades = 2;
    float shadowDistance = 30.0f;
};

// The camera looking at cube face `face` (Vulkan order +X, -X, +Y, -Y, +Z, -Z) from `position`, 90 degrees. A
// right-handed camera sees the face mirrored left to right (cube faces are left-handed): image column x is face
// texel column size - 1 - x.
scene::CameraState cubeFaceCamera(glm::vec3 position, int face, float znear);

// The inner graph, compiled and ready for an Executor on the parent's context. The registry it was compiled
// against (the global one plus the view node) lives as long as the graph.
struct CaptureGraph {
    NodeRegistry registry;
    CompiledGraph graph;
};
std::unique_ptr<CaptureGraph> buildCaptureGraph(std::shared_ptr<const CaptureInputs> inputs, const CaptureLighting& lighting);

} // namespace vitrine
