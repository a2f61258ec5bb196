#pragma once
// What scene.museum and scene.gltf share: the scene/camera outputs, the camera choice, the frame clock,
// sub-pixel jitter, reflection probes from a file (`probes`), and the per-frame pose + camera update of the GPU scene.

#include "core/graph/node.hpp"
#include "core/scene/gpu_scene.hpp"
#include "core/scene/jitter.hpp"

#include <memory>
#include <string>

namespace vitrine {

// Ports and params common to every scene node (appended to the node's own).
void addSceneNodeSchema(NodeSchema& s);

class SceneNode : public Node {
public:
    void execute(ExecuteContext& ctx) override;

protected:
    // Subclasses load or build the scene, then call this.
    void publish(SetupContext& ctx, std::shared_ptr<const scene::Scene> scene);

private:
    scene::CameraState cameraAt(double t) const;

    std::shared_ptr<SceneObject> mScene;
    std::shared_ptr<CameraObject> mCamera;
    std::string mCameraPath; // empty: a glTF camera node or a framing of the bounds
    int mCameraNode = -1;
    float mFps = 24.0f;
    float mStart = 0.0f;
    scene::JitterPattern mJitter = scene::JitterPattern::Off;
    uint32_t mJitterGrid = 16;
    float mVertexJitterThreshold = 0.0f; // 0: frustum jitter
    bool mEvaluated = false; // pose and camera of mLastFrame are in mScene / mCamera
    uint32_t mLastFrame = 0;
};

} // namespace vitrine
