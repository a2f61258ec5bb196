#pragma once
// `vitrine bench --bvh`: the ray-tracing BVH of a graph's scene, measured (see bench_bvh.cpp).

#include <nlohmann/json.hpp>

namespace vitrine {
class Context;
class ShaderCompiler;
class SceneObject;
struct CameraFrame;
} // namespace vitrine

namespace vitrine::cli {

// Builds the scene's BVH (CPU ms), stores it in the bake cache and loads it back (ms), uploads it, and
// traces one primary ray per pixel of the camera's frame and one cosine-distributed bounce ray from
// each primary hit (closest hit), timing each dispatch with timestamp queries and from submit to fence,
// and the same rays through the CPU traversal on one thread. camera may be null
// (no rays then). Called after the graph ran, so the scene is posed as in the last frame.
nlohmann::json benchSceneBvh(Context& ctx, ShaderCompiler& shaders, const std::string& resource,
                             const SceneObject& scene, const CameraFrame* camera);
// The summary lines of benchSceneBvh's JSON.
void printSceneBvhBench(const nlohmann::json& bvh);

} // namespace vitrine::cli
