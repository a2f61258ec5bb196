#include "nodes/scene/scene_node.hpp"

#include "core/accel/gpu_bvh.hpp"
#include "core/base/error.hpp"
#include "core/scene/aperture.hpp"
#include "core/gpu/context.hpp"
#include "core/scene/probes.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

namespace vitrine {

void addSceneNodeSchema(NodeSchema& s) {
    OutputPort scene;
    scene.name = "scene";
    scene.kind = PortKind::Scene;
    scene.doc = "Geometry, layered materials, textures and this frame's pose (uploaded on the first frame)";
    OutputPort camera;
    camera.name = "camera";
    camera.kind = PortKind::Camera;
    camera.doc = "This frame's camera (matrices with and without jitter, last frame's)";
    s.outputs.push_back(scene);
    s.outputs.push_back(camera);
    s.params.push_back({"camera", ParamType::String, "", {}, {}, {},
                        "Camera path to follow (the museum: walkthrough, dolly, static). Empty: the first path, else the "
                        "first glTF camera, else a view framing the scene"});
    s.params.push_back({"fps", ParamType::Float, 24.0, 1.0, 1000.0, {}, "Frames per second of the frame clock"});
    s.params.push_back({"start", ParamType::Float, 0.0, -1e6, 1e6, {}, "Time of frame 0 in seconds"});
    const char* holdDoc = "Hold the clock at `start`: every frame shows the same instant, still (zero velocity), while "
                          "the jitter and lens samples still move per frame (temporal AA's or accumulation's steady "
                          "state of one shot)";
    s.params.push_back({"hold", ParamType::Bool, false, {}, {}, {}, holdDoc});
    s.params.push_back({"anisotropy", ParamType::Float, -1.0, -1.0, 16.0, {},
                        "Anisotropic texture filtering (1 = off). -1: 8x on GPUs, off on CPU devices (lavapipe's "
                        "software anisotropic filtering takes minutes per frame)"});
    s.params.push_back({"jitter", ParamType::Enum, "off", {}, {}, scene::jitterPatternNames(),
                        "Sub-pixel jitter of the projection, for temporal AA (core/scene/jitter.hpp): halton (2,3); "
                        "ordered 4x4 grid; rotated grid (16-rooks); improved (16-rooks, no weak edge direction); the "
                        "16-sample grids move inside their sub-grid cells every 16 frames. stratified: jitter_grid^2 "
                        "cell centres in turn, for aa.accumulate's supersampled ground truth"});
    s.params.push_back({"jitter_grid", ParamType::Int, 0, 0.0, 64.0, {},
                        "N of the stratified pattern: N x N sub-pixel positions, one per frame. 0: the largest N with "
                        "N^2 <= the graph's frame count (as aa.accumulate's grid 0)"});
    s.params.push_back({"jitter_space", ParamType::Enum, "frustum", {}, {}, {"frustum", "vertex"},
                        "frustum: the whole projection is shifted; vertex: each vertex is shifted in the vertex stage, "
                        "less the faster it moves on screen (static pixels supersample, moving ones do not wobble)"});
    s.params.push_back({"vertex_jitter_threshold", ParamType::Float, 2.0, 0.01, 1000.0, {},
                        "jitter_space vertex: screen speed (pixels per frame) at and above which a vertex is not "
                        "jittered; slower vertices get (1 - speed / threshold) of the jitter"});
    s.params.push_back({"lens", ParamType::Enum, "pinhole", {}, {}, {"pinhole", "thin_lens"},
                        "pinhole: everything sharp. thin_lens: the ground truth of depth of field by accumulation: each "
                        "frame moves the eye to a sample of the aperture polygon (lens_samples low-discrepancy samples, "
                        "one per frame, in turn) and shears the projection so the focus plane stays put; the mean of "
                        "lens_samples frames (aa.accumulate) is the thin lens's image"});
    s.params.push_back({"lens_samples", ParamType::Int, 0, 0.0, 65536.0, {},
                        "thin_lens: aperture samples, one per frame, then repeated. 0: the graph's frame count"});
    s.params.push_back({"lens_f_number", ParamType::Float, 0.0, 0.0, 256.0, {},
                        "thin_lens: f-number (aperture diameter = focal length / f-number). 0: the scene camera's"});
    s.params.push_back({"lens_focus_distance", ParamType::Float, 0.0, 0.0, 1e6, {},
                        "thin_lens: distance of the plane in focus along the view axis (m). 0: the scene camera's"});
    s.params.push_back({"lens_blades", ParamType::Int, -1, -1.0, 32.0, {},
                        "thin_lens: aperture blades (0: a circle). -1: the scene camera's"});
    s.params.push_back({"lens_blade_roundness", ParamType::Float, 0.0, 0.0, 1.0, {},
                        "thin_lens: 0 straight blades (a polygon) .. 1 a circle, once stopped down (core/scene/aperture.hpp)"});
    s.params.push_back({"lens_blade_rotation", ParamType::Float, 0.0, -360.0, 360.0, {},
                        "thin_lens: angle of the first corner in degrees, counter-clockwise from the camera's +x"});
    s.params.push_back({"lens_wide_open_f_number", ParamType::Float, 1.4, 0.5, 256.0, {},
                        "thin_lens: the lens's largest aperture; at it the aperture is round, one stop down the blades' shape"});
    s.params.push_back({"probes", ParamType::Path, "", {}, {}, {},
                        "Reflection probes from a JSON file {\"probes\": [...]} (relative to the graph file; each probe "
                        "as in core/scene/VITRINE_reflection_probes.md), combined with the scene's as probes_mode says. "
                        "Empty: the scene's own probes"});
    s.params.push_back({"probes_mode", ParamType::Enum, "merge", {}, {}, {"merge", "replace"},
                        "How the probes file combines with the scene's probes: merge (a file probe named like a scene "
                        "probe replaces it, the others are added) or replace (the file's probes only; [] removes all)"});
}

namespace {

// The scene with the `probes` param's file applied; the scene itself when the param is empty.
std::shared_ptr<const scene::Scene> withProbeFile(SetupContext& ctx, std::shared_ptr<const scene::Scene> scene) {
    const Params& p = ctx.params();
    const std::string path = p.getString("probes");
    if (path.empty()) return scene;
    auto mode = p.getString("probes_mode") == "replace" ? scene::ProbeMerge::Replace : scene::ProbeMerge::Merge;
    auto edited = std::make_shared<scene::Scene>(*scene);
    try {
        scene::applyProbes(edited->probes, scene::readProbeFile(ctx.resolvePath(path)), mode);
    } catch (const UserError& e) {
        // The probe file's error names its file and JSON pointer; the graph's file and param say where it came from.
        ctx.failParam("probes", e.what());
    }
    edited->validate();
    return edited;
}

} // namespace

void SceneNode::publish(SetupContext& ctx, std::shared_ptr<const scene::Scene> scene) {
    const Params& p = ctx.params();
    scene = withProbeFile(ctx, std::move(scene));
    mFps = p.getFloat("fps");
    mStart = p.getFloat("start");
    mHold = p.getBool("hold");
    mJitter = static_cast<scene::JitterPattern>(p.getEnumIndex("jitter"));
    mJitterGrid = scene::jitterGridFor(static_cast<uint32_t>(p.getInt("jitter_grid")), ctx.frame().frames);
    mVertexJitterThreshold = p.getString("jitter_space") == "vertex" ? p.getFloat("vertex_jitter_threshold") : 0.0f;
    mThinLens = p.getString("lens") == "thin_lens";
    mLensSamples = p.getInt("lens_samples") > 0 ? static_cast<uint32_t>(p.getInt("lens_samples")) : ctx.frame().frames;
    mLensFNumber = p.getFloat("lens_f_number");
    mLensFocus = p.getFloat("lens_focus_distance");
    mLensBlades = p.getInt("lens_blades");
    mLensRoundness = p.getFloat("lens_blade_roundness");
    mLensRotation = glm::radians(p.getFloat("lens_blade_rotation"));
    mLensWideOpen = p.getFloat("lens_wide_open_f_number");
    if (mThinLens && mLensFNumber > 0.0f && mLensFNumber < mLensWideOpen)
        ctx.failParam("lens_f_number", "f/" + std::to_string(mLensFNumber) + " is wider than the lens opens (lens_wide_open_f_number f/" +
                                           std::to_string(mLensWideOpen) + ")");
    mCameraPath = p.getString("camera");
    if (!mCameraPath.empty()) {
        if (!scene->findCameraPath(mCameraPath)) {
            std::string known;
            for (const auto& path : scene->cameraPaths) known += (known.empty() ? "" : ", ") + path.name;
            ctx.failParam("camera", "scene '" + scene->name + "' has no camera path '" + mCameraPath +
                                        "'; expected one of: " + (known.empty() ? "(none)" : known));
        }
    } else if (!scene->cameraPaths.empty()) {
        mCameraPath = scene->cameraPaths.front().name;
    } else {
        for (size_t n = 0; n < scene->nodes.size(); ++n)
            if (scene->nodes[n].camera >= 0) {
                mCameraNode = static_cast<int>(n);
                break;
            }
    }
    mScene = std::make_shared<SceneObject>(std::move(scene));
    if (mKeyLight.on && !mScene->scene().hasSun) {
        // The sun goes where the camera of the first frame looks from, turned and raised by the key light's angles.
        const scene::CameraState view = cameraAt(mStart);
        const glm::vec3 forward = view.orientation * glm::vec3(0.0f, 0.0f, -1.0f);
        glm::vec3 heading(forward.x, 0.0f, forward.z);
        heading = glm::length(heading) > 1e-4f ? glm::normalize(heading) : glm::vec3(0.0f, 0.0f, -1.0f);
        const glm::vec3 right = glm::cross(heading, glm::vec3(0.0f, 1.0f, 0.0f));
        const float az = glm::radians(mKeyLight.azimuth), el = glm::radians(mKeyLight.elevation);
        const glm::vec3 horizontal = -heading * std::cos(az) + right * std::sin(az);
        auto lit = std::make_shared<scene::Scene>(mScene->scene());
        lit->hasSun = true;
        lit->sun.toSun = glm::normalize(horizontal * std::cos(el) + glm::vec3(0.0f, std::sin(el), 0.0f));
        mScene = std::make_shared<SceneObject>(std::move(lit));
    }
    mScene->anisotropy = p.getFloat("anisotropy");
    mCamera = std::make_shared<CameraObject>();
    mCamera->jitterPattern = mJitter;
    mCamera->jitterGrid = mJitterGrid;
    ctx.setObject("scene", mScene);
    ctx.setObject("camera", mCamera);
    mCamera->current.width = ctx.frame().width;
    mCamera->current.height = ctx.frame().height;
}

scene::CameraState SceneNode::cameraAt(double t) const {
    const scene::Scene& s = mScene->scene();
    if (!mCameraPath.empty()) return s.cameraAt(mCameraPath, t);
    scene::CameraState state;
    if (mCameraNode >= 0) {
        scene::ScenePose pose = s.evaluate(t);
        const glm::mat4& world = pose.nodeWorld[mCameraNode];
        state.lens = s.cameras[s.nodes[mCameraNode].camera];
        state.position = glm::vec3(world[3]);
        state.orientation = glm::quat_cast(glm::mat3(glm::normalize(glm::vec3(world[0])), glm::normalize(glm::vec3(world[1])),
                                                     glm::normalize(glm::vec3(world[2]))));
    } else {
        // Framing: from the +Z side and a little above, far enough to see the whole bounding sphere.
        glm::vec3 c = s.bounds.empty() ? glm::vec3(0.0f) : s.bounds.center();
        float r = s.bounds.empty() ? 1.0f : 0.5f * glm::length(s.bounds.extent());
        float dist = r / std::sin(0.5f * state.lens.yfov);
        glm::vec3 dir = glm::normalize(glm::vec3(0.0f, 0.35f, 1.0f));
        state.position = c + dir * dist;
        glm::mat4 view = glm::lookAt(state.position, c, glm::vec3(0.0f, 1.0f, 0.0f));
        state.orientation = glm::quat_cast(glm::mat3(glm::inverse(view)));
        state.lens.znear = std::max(0.01f, dist - 2.0f * r) * 0.5f;
    }
    state.world = glm::translate(glm::mat4(1.0f), state.position) * glm::mat4_cast(state.orientation);
    state.view = glm::inverse(state.world);
    return state;
}

glm::vec2 SceneNode::lensOffset(const scene::Camera& lens, uint32_t frame, float& focus) const {
    const float fNumber = mLensFNumber > 0.0f ? mLensFNumber : lens.fNumber;
    const uint32_t blades = mLensBlades >= 0 ? static_cast<uint32_t>(mLensBlades) : lens.apertureBlades;
    focus = mLensFocus > 0.0f ? mLensFocus : lens.focusDistance;
    const scene::ApertureShape shape = scene::apertureAt(blades, mLensRoundness, mLensRotation, fNumber, mLensWideOpen);
    // The eye moves over the aperture (radius f / 2N) scaled by zf / (zf - f): the render keeps the frame's field
    // of view (no focus breathing: the image distance stays f, not the thin lens's f zf / (zf - f)), and with this
    // scale a point at depth z spreads over exactly the thin lens's CoC, A f (z - zf) / (z (zf - f)) on the sensor.
    const float f = lens.focalLengthMm() * 1e-3f;
    const float radius = 0.5f * f / fNumber * focus / std::max(focus - f, 1e-6f);
    return radius * scene::apertureSample(shape, frame % mLensSamples);
}

// The eye moved by `offset` (camera x right, y up, metres) on the lens and the projection sheared so that the plane
// at view depth `focus` projects as it did from the lens centre: a pinhole through one point of a thin lens.
void SceneNode::applyLens(scene::CameraState& state, glm::mat4& proj, glm::vec2 offset, float focus) {
    state.position += state.orientation * glm::vec3(offset, 0.0f);
    state.world = glm::translate(glm::mat4(1.0f), state.position) * glm::mat4_cast(state.orientation);
    state.view = glm::inverse(state.world);
    proj[2][0] -= proj[0][0] * offset.x / focus;
    proj[2][1] -= proj[1][1] * offset.y / focus;
}

void SceneNode::execute(ExecuteContext& ctx) {
    const scene::Scene& s = mScene->scene();
    const uint32_t frame = ctx.frameIndex();
    const double dt = mHold ? 0.0 : 1.0 / mFps;
    const double t = mStart + frame * dt;
    GpuScene& gpu = mScene->gpu(ctx.gpu(), ctx.shaders());
    CameraFrame& c = mCamera->current;
    const float aspect = static_cast<float>(c.width) / static_cast<float>(c.height);

    // Velocity is the motion over one frame interval, also on frame 0 (the clock is continuous).
    // Consecutive frames hand their pose and camera on instead of evaluating them again.
    const bool consecutive = mEvaluated && frame == mLastFrame + 1;
    mScene->previousPose = consecutive ? std::move(mScene->pose) : s.evaluate(t - dt);
    scene::CameraState before = consecutive ? mUnshiftedState : cameraAt(t - dt);
    mScene->time = t;
    mScene->pose = s.evaluate(t);
    c.state = cameraAt(t);
    mEvaluated = true;
    mLastFrame = frame;

    mUnshiftedState = c.state;
    c.projNoJitter = c.state.projection(aspect, true);
    glm::mat4 prevProj = before.projection(aspect, true);
    if (mThinLens) {
        // Velocity stays the scene's motion: last frame's camera is moved to this frame's lens sample too.
        float focus = 0.0f;
        const glm::vec2 offset = lensOffset(c.state.lens, frame, focus);
        applyLens(c.state, c.projNoJitter, offset, focus);
        applyLens(before, prevProj, offset, focus);
    }
    c.prevJitter = frame == 0 ? glm::vec2(0.0f) : scene::jitterOffset(mJitter, frame - 1, mJitterGrid);
    c.jitter = scene::jitterOffset(mJitter, frame, mJitterGrid);
    c.vertexJitterThreshold = mVertexJitterThreshold;
    glm::mat4 shift = glm::translate(glm::mat4(1.0f), glm::vec3(2.0f * c.jitter.x / c.width, 2.0f * c.jitter.y / c.height, 0.0f));
    c.proj = shift * c.projNoJitter;
    c.viewProj = c.proj * c.state.view;
    c.viewProjNoJitter = c.projNoJitter * c.state.view;
    c.prevViewProjNoJitter = prevProj * before.view;
    c.invViewProj = glm::inverse(c.viewProj);
    c.time = t;
    c.frame = frame;
    gpu.update(mScene->pose, mScene->previousPose, c);
    mScene->reposeBvh(mScene->pose);
}

} // namespace vitrine
