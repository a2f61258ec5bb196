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

    // A key light from the camera side (scene.gltf's key_light): when `on` and the scene has no sun, publish() gives
    // it one, `elevation` degrees above the horizon and `azimuth` degrees to the right of the direction back to the
    // camera at the first frame (0: straight from behind the camera).
    struct KeyLight {
        bool on = false;
        float elevation = 35.0f, azimuth = 30.0f;
    };
    KeyLight mKeyLight;

private:
    scene::CameraState cameraAt(double t) const;
    // Thin-lens mode: this frame's aperture sample (metres, camera x right / y up) and the focus distance.
    glm::vec2 lensOffset(const scene::Camera& lens, uint32_t frame, float& focus) const;
    static void applyLens(scene::CameraState& state, glm::mat4& proj, glm::vec2 offset, float focus);

    std::shared_ptr<SceneObject> mScene;
    std::shared_ptr<CameraObject> mCamera;
    std::string mCameraPath; // empty: a glTF camera node or a framing of the bounds
    int mCameraNode = -1;
    float mFps = 24.0f;
    float mStart = 0.0f;
    bool mHold = false;
    scene::JitterPattern mJitter = scene::JitterPattern::Off;
    uint32_t mJitterGrid = 16;
    float mVertexJitterThreshold = 0.0f; // 0: frustum jitter
    bool mThinLens = false;
    uint32_t mLensSamples = 1;
    float mLensFNumber = 0.0f, mLensFocus = 0.0f, mLensRoundness = 0.0f, mLensRotation = 0.0f, mLensWideOpen = 1.4f;
    int mLensBlades = -1;
    scene::CameraState mUnshiftedState; // this frame's camera before the lens offset (next frame's `before`)
    bool mEvaluated = false; // pose and camera of mLastFrame are in mScene / mCamera
    uint32_t mLastFrame = 0;
};

} // namespace vitrine
