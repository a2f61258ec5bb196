// loadGltf(): the order of the steps, plus nodes, cameras, animations, camera paths, lights and extras.

#include "core/scene/gltf.hpp"
#include "core/scene/gltf_detail.hpp"
#include "core/scene/probe_json.hpp"

#include "core/base/error.hpp"
#include "core/base/log.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

#include <tiny_gltf.h>

namespace vitrine::scene::gltf {

namespace {

constexpr float kCameraSampleRate = 30.0f; // Hz, for camera nodes moved by arbitrary animations
// At most this many samples per camera path (9 h 15 min at 30 Hz): a longer animation is a broken file, not a shot.
constexpr float kMaxCameraSamples = 1.0e6f;

std::string role(const LoadContext& ctx, const Json& obj, const std::string& e) {
    const Json* extras = member(obj, "extras");
    const Json* ours = extras ? member(*extras, kExtrasKey) : nullptr;
    return ours && ours->is_object() ? string(ctx, *ours, "role", "", e + ".extras.vitrine") : std::string();
}

Transform readTransform(const LoadContext& ctx, const tinygltf::Node& n, const std::string& e) {
    Transform t;
    auto checkSize = [&](const std::vector<double>& v, size_t size, const char* name) {
        if (!v.empty() && v.size() != size) {
            ctx.fail(e + "." + name, std::to_string(v.size()) + " numbers; expected " + std::to_string(size));
        }
    };
    checkSize(n.translation, 3, "translation");
    checkSize(n.rotation, 4, "rotation");
    checkSize(n.scale, 3, "scale");
    checkSize(n.matrix, 16, "matrix");
    if (!n.matrix.empty()) {
        glm::mat4 m;
        for (int i = 0; i < 16; ++i)
            m[i / 4][i % 4] = static_cast<float>(n.matrix[i]);
        t.translation = glm::vec3(m[3]);
        glm::vec3 c[3] = {glm::vec3(m[0]), glm::vec3(m[1]), glm::vec3(m[2])};
        t.scale = glm::vec3(glm::length(c[0]), glm::length(c[1]), glm::length(c[2]));
        if (glm::dot(glm::cross(c[0], c[1]), c[2]) < 0.0f) t.scale.x = -t.scale.x;
        if (t.scale.x != 0.0f && t.scale.y != 0.0f && t.scale.z != 0.0f) {
            t.rotation =
                glm::normalize(glm::quat_cast(glm::mat3(c[0] / t.scale.x, c[1] / t.scale.y, c[2] / t.scale.z)));
        }
        return t;
    }
    if (!n.translation.empty()) t.translation = glm::vec3(n.translation[0], n.translation[1], n.translation[2]);
    if (!n.scale.empty()) t.scale = glm::vec3(n.scale[0], n.scale[1], n.scale[2]);
    if (!n.rotation.empty()) {
        glm::quat q(static_cast<float>(n.rotation[3]), static_cast<float>(n.rotation[0]),
                    static_cast<float>(n.rotation[1]), static_cast<float>(n.rotation[2]));
        float len = glm::length(q);
        if (!(len > 1e-6f) || !std::isfinite(len)) ctx.fail(e + ".rotation", "expected a unit quaternion [x, y, z, w]");
        // Unit quaternions written with float precision come back unchanged; only fix visible errors.
        t.rotation = std::abs(len - 1.0f) > 1e-6f ? q / len : q;
    }
    return t;
}

Camera readCamera(const LoadContext& ctx, const tinygltf::Camera& c, const Json& json, const std::string& e) {
    Camera cam;
    cam.name = c.name;
    if (c.type == "perspective") {
        cam.yfov = static_cast<float>(c.perspective.yfov);
        cam.znear = static_cast<float>(c.perspective.znear);
        cam.zfar = static_cast<float>(c.perspective.zfar);
        cam.aspectRatio = static_cast<float>(c.perspective.aspectRatio);
        if (!(cam.yfov > 0.0f)) ctx.fail(e + ".perspective.yfov", "expected a field of view > 0 (radians)");
        if (cam.yfov >= 3.14f) { // legal (glTF: it SHOULD be below π), but no projection reaches it
            ctx.warn(e + ".perspective.yfov", std::to_string(cam.yfov) + " rad is not below π; drawn at 3.14 rad");
            cam.yfov = 3.14f;
        }
        if (!(cam.znear > 0.0f)) ctx.fail(e + ".perspective.znear", "expected > 0");
        if (cam.zfar != 0.0f && cam.zfar <= cam.znear) ctx.fail(e + ".perspective.zfar", "expected > znear");
    } else if (c.type == "orthographic") {
        cam.projection = Projection::Orthographic;
        cam.xmag = static_cast<float>(c.orthographic.xmag);
        cam.ymag = static_cast<float>(c.orthographic.ymag);
        cam.znear = static_cast<float>(c.orthographic.znear);
        cam.zfar = static_cast<float>(c.orthographic.zfar);
        if (cam.xmag == 0.0f || cam.ymag == 0.0f) ctx.fail(e + ".orthographic", "expected non-zero xmag and ymag");
        if (!(cam.zfar > cam.znear)) ctx.fail(e + ".orthographic.zfar", "expected > znear");
    } else {
        ctx.fail(e + ".type", "'" + c.type + "'; expected perspective or orthographic");
    }
    const Json* extras = member(json, "extras");
    if (const Json* p = extras ? object(ctx, *extras, kExtrasKey, e + ".extras") : nullptr) {
        std::string pe = e + ".extras.vitrine";
        auto f = [&](const char* key, float def) { return static_cast<float>(number(ctx, *p, key, def, pe)); };
        cam.sensorWidthMm = f("sensorWidthMm", cam.sensorWidthMm);
        cam.sensorHeightMm = f("sensorHeightMm", cam.sensorHeightMm);
        cam.fNumber = f("fNumber", cam.fNumber);
        cam.focusDistance = f("focusDistance", cam.focusDistance);
        cam.shutterTime = f("shutterTime", cam.shutterTime);
        cam.iso = f("iso", cam.iso);
        cam.apertureBlades = static_cast<uint32_t>(integer(ctx, *p, "apertureBlades", cam.apertureBlades, pe));
    }
    return cam;
}

// width: values per key (the morph target count for weights, else 1).
AnimationSampler readSampler(const LoadContext& ctx, const tinygltf::AnimationSampler& s, AnimationPath path,
                             const std::string& e, uint32_t width = 1) {
    AnimationSampler out;
    if (s.interpolation == "LINEAR")
        out.interpolation = Interpolation::Linear;
    else if (s.interpolation == "STEP")
        out.interpolation = Interpolation::Step;
    else if (s.interpolation == "CUBICSPLINE")
        out.interpolation = Interpolation::CubicSpline;
    else
        ctx.fail(e + ".interpolation", "'" + s.interpolation + "'; expected LINEAR, STEP or CUBICSPLINE");
    AccessorValues input = readAccessor(ctx, s.input, e + ".input", {1}, true);
    int comps = path == AnimationPath::Rotation ? 4 : path == AnimationPath::Weights ? 1 : 3;
    AccessorValues output = readAccessor(ctx, s.output, e + ".output", {comps});
    size_t per = (out.interpolation == Interpolation::CubicSpline ? 3 : 1) * size_t(width);
    out.width = width;
    if (output.count != input.count * per) {
        ctx.fail(e + ".output", std::to_string(output.count) + " elements; expected " +
                                    std::to_string(input.count * per) + " (input count" +
                                    (out.interpolation == Interpolation::CubicSpline ? " × 3" : "") +
                                    (width != 1 ? " × " + std::to_string(width) + " morph targets)" : ")"));
    }
    out.times = input.data; // finite: readAccessor refuses NaN and infinities
    for (size_t i = 1; i < out.times.size(); ++i) {
        if (out.times[i] < out.times[i - 1]) ctx.fail(e + ".input", "times decrease at key " + std::to_string(i));
    }
    for (size_t i = 0; i < output.count; ++i)
        out.values.push_back(output.get(i));
    return out;
}

AnimationPath toPath(const LoadContext& ctx, const std::string& path, const std::string& e) {
    if (path == "translation") return AnimationPath::Translation;
    if (path == "rotation") return AnimationPath::Rotation;
    if (path == "scale") return AnimationPath::Scale;
    if (path == "weights") return AnimationPath::Weights;
    ctx.fail(e, "'" + path + "'; expected translation, rotation, scale or weights");
}

// A camera path written by exportGlb(): translation and rotation samplers on the path's node, yfov in extras.
CameraPath readExportedPath(const LoadContext& ctx, const tinygltf::Animation& a, const Json& ours,
                            const std::string& e) {
    std::string pe = e + ".extras.vitrine.cameraPath";
    CameraPath path;
    path.name = a.name;
    int64_t camera = integer(ctx, ours, "camera", 0, pe);
    if (camera < 0 || static_cast<size_t>(camera) >= ctx.scene->cameras.size())
        ctx.fail(pe + ".camera", "out of range");
    path.camera = static_cast<uint32_t>(camera);
    path.smooth = boolean(ctx, ours, "smooth", true, pe);
    path.loop = boolean(ctx, ours, "loop", false, pe);
    AnimationSampler translation, rotation;
    for (size_t c = 0; c < a.channels.size(); ++c) {
        const tinygltf::AnimationChannel& ch = a.channels[c];
        AnimationPath p = toPath(ctx, ch.target_path, e + ".channels[" + std::to_string(c) + "].target.path");
        std::string se = e + ".samplers[" + std::to_string(ch.sampler) + "]";
        (p == AnimationPath::Rotation ? rotation : translation) = readSampler(ctx, a.samplers[ch.sampler], p, se);
    }
    const Json* fov = member(ours, "yfov");
    size_t keys = translation.times.size();
    if (keys == 0 || rotation.times.size() != keys || !fov || !fov->is_array() || fov->size() != keys) {
        ctx.fail(pe, "expected translation and rotation channels and a yfov list with one value per key");
    }
    size_t mid = translation.interpolation == Interpolation::CubicSpline ? 3 : 1;
    size_t off = mid == 3 ? 1 : 0;
    for (size_t k = 0; k < keys; ++k) {
        CameraKey key;
        key.time = translation.times[k];
        key.position = glm::vec3(translation.values[k * mid + off]);
        size_t rmid = rotation.interpolation == Interpolation::CubicSpline ? 3 : 1;
        key.orientation = toQuat(rotation.values[k * rmid + (rmid == 3 ? 1 : 0)]);
        if (!(*fov)[k].is_number()) ctx.fail(pe + ".yfov", "expected numbers");
        key.yfov = (*fov)[k].get<float>();
        path.keys.push_back(key);
    }
    return path;
}

void splitWorld(const glm::mat4& world, glm::vec3& position, glm::quat& orientation) {
    position = glm::vec3(world[3]);
    glm::mat3 r(glm::normalize(glm::vec3(world[0])), glm::normalize(glm::vec3(world[1])),
                glm::normalize(glm::vec3(world[2])));
    orientation = glm::normalize(glm::quat_cast(r));
}

// A path for a camera node of any file: one key when still, 30 Hz samples while animations move it.
CameraPath pathForCameraNode(const LoadContext& ctx, const Scene& scene, uint32_t node) {
    CameraPath path;
    path.name = scene.nodes[node].name.empty() ? "camera" + std::to_string(node) : scene.nodes[node].name;
    path.camera = static_cast<uint32_t>(scene.nodes[node].camera);
    path.smooth = false;
    float start = 0.0f, end = 0.0f;
    bool moving = false;
    for (const Animation& a : scene.animations) {
        bool affects = false;
        for (const AnimationChannel& c : a.channels) {
            for (int32_t n = static_cast<int32_t>(node); n >= 0 && !affects; n = scene.nodes[n].parent) {
                affects = c.node == static_cast<uint32_t>(n);
            }
        }
        if (!affects) continue;
        start = moving ? std::min(start, a.startTime()) : a.startTime();
        end = moving ? std::max(end, a.endTime()) : a.endTime();
        path.loop = path.loop || a.loop;
        moving = true;
    }
    // Checked before the cast: a float beyond size_t is undefined behaviour, and a huge count exhausts memory.
    const float samples = std::ceil((end - start) * kCameraSampleRate);
    if (moving && !(samples <= kMaxCameraSamples)) {
        char span[32];
        std::snprintf(span, sizeof span, "%g", static_cast<double>(end - start));
        ctx.fail("camera node '" + path.name + "'",
                 std::string("its animations span ") + span + " s; a camera path is sampled at 30 Hz, at most " +
                     std::to_string(static_cast<int>(kMaxCameraSamples)) + " samples (expected times in seconds)");
    }
    size_t count = moving ? static_cast<size_t>(samples) + 1 : 1;
    float yfov = scene.cameras[path.camera].yfov;
    for (size_t k = 0; k < count; ++k) {
        CameraKey key;
        key.time = moving ? std::min(end, start + k / kCameraSampleRate) : 0.0f;
        key.yfov = yfov;
        // Sampling with loop wrapping would fold the last key back onto the first; clamp instead.
        ScenePose pose = scene.evaluate(key.time >= end && moving ? end - 1e-4f : key.time);
        splitWorld(pose.nodeWorld[node], key.position, key.orientation);
        path.keys.push_back(key);
    }
    return path;
}

void readSceneExtras(LoadContext& ctx, const Json& sceneJson, const std::string& e) {
    const Json* extras = member(sceneJson, "extras");
    const Json* ours = extras ? object(ctx, *extras, kExtrasKey, e + ".extras") : nullptr;
    if (!ours) return;
    std::string oe = e + ".extras.vitrine";
    Scene& scene = *ctx.scene;
    if (const Json* sun = object(ctx, *ours, "sun", oe)) {
        scene.hasSun = true;
        scene.sun.toSun = glm::vec3(numbers(ctx, *sun, "toSun", 3, glm::vec4(0, 1, 0, 0), oe + ".sun"));
        scene.sun.color = glm::vec3(numbers(ctx, *sun, "color", 3, glm::vec4(1.0f), oe + ".sun"));
        scene.sun.illuminance = static_cast<float>(number(ctx, *sun, "illuminance", 100000.0, oe + ".sun"));
        scene.sun.angularDiameter = static_cast<float>(number(ctx, *sun, "angularDiameter", 0.00931, oe + ".sun"));
    }
    if (const Json* rooms = member(*ours, "rooms")) {
        if (!rooms->is_array()) ctx.fail(oe + ".rooms", "expected an array");
        for (size_t i = 0; i < rooms->size(); ++i) {
            std::string re = oe + ".rooms[" + std::to_string(i) + "]";
            Room room;
            room.name = string(ctx, (*rooms)[i], "name", "", re);
            room.bounds.min = glm::vec3(numbers(ctx, (*rooms)[i], "min", 3, glm::vec4(0.0f), re));
            room.bounds.max = glm::vec3(numbers(ctx, (*rooms)[i], "max", 3, glm::vec4(0.0f), re));
            scene.rooms.push_back(room);
        }
    }
}

// VITRINE_reflection_probes on the scene (VITRINE_reflection_probes.md).
void readProbes(LoadContext& ctx, const Json& sceneJson, const std::string& e) {
    const Json* ext = object(ctx, sceneJson, "extensions", e);
    const Json* ours = ext ? object(ctx, *ext, kProbesExtension, e + ".extensions") : nullptr;
    if (!ours) return;
    std::string pe = e + ".extensions." + kProbesExtension;
    for (const auto& item : ours->items()) {
        if (item.key() != "probes" && item.key() != "extensions" && item.key() != "extras")
            ctx.fail(pe + "." + item.key(), "unknown key; expected probes");
    }
    const Json* list = member(*ours, "probes");
    if (!list) ctx.fail(pe + ".probes", "missing; expected an array of probes");
    ctx.scene->probes = probejson::read(*list, probejson::Where{ctx.file, false}, pe + ".probes");
}

// KHR_lights_punctual: the first directional light becomes the sun (when the file has no exact sun in our
// extras), point and spot lights are kept with their nodes; other directional lights are ignored with a warning.
void readLights(LoadContext& ctx, const std::vector<int32_t>& remap) {
    const Json* ext = member(ctx.doc, "extensions");
    const Json* lights = ext ? member(*ext, kLightsPunctual) : nullptr;
    const Json* list = lights ? member(*lights, "lights") : nullptr;
    const Json* nodes = member(ctx.doc, "nodes");
    if (!list || !nodes) return;
    Scene& scene = *ctx.scene;
    for (size_t i = 0; i < nodes->size(); ++i) {
        const Json* next = member((*nodes)[i], "extensions");
        const Json* light = next ? member(*next, kLightsPunctual) : nullptr;
        if (!light || remap[i] < 0) continue;
        const Json& l = (*list)[(*light)["light"].get<size_t>()];
        std::string le = "extensions.KHR_lights_punctual.lights[" + (*light)["light"].dump() + "]";
        if (!l.is_object()) ctx.fail(le, "expected a JSON object");
        std::string type = string(ctx, l, "type", "", le);
        glm::vec3 color = glm::vec3(numbers(ctx, l, "color", 3, glm::vec4(1.0f), le));
        float intensity = static_cast<float>(number(ctx, l, "intensity", 1.0, le));
        if (!(intensity >= 0.0f)) ctx.fail(le + ".intensity", "expected a number >= 0");
        if (type == "directional") {
            if (scene.hasSun) {
                ctx.warn(le, "only one directional light is used (the sun); ignored");
                continue;
            }
            glm::mat4 world = scene.evaluate(0.0).nodeWorld[remap[i]];
            scene.hasSun = true;
            scene.sun.toSun = glm::normalize(glm::vec3(world * glm::vec4(0, 0, 1, 0))); // lights shine down -Z
            scene.sun.color = color;
            scene.sun.illuminance = intensity;
            continue;
        }
        if (type != "point" && type != "spot") ctx.fail(le + ".type", "'" + type + "'; expected directional, point or spot");
        PunctualLight p;
        p.name = string(ctx, l, "name", "", le);
        p.type = type == "spot" ? LightType::Spot : LightType::Point;
        p.color = color;
        p.intensity = intensity;
        p.range = static_cast<float>(number(ctx, l, "range", 0.0, le));
        if (!(p.range >= 0.0f)) ctx.fail(le + ".range", "expected a number > 0");
        if (p.type == LightType::Spot) {
            const Json* spot = object(ctx, l, "spot", le);
            std::string se = le + ".spot";
            p.innerConeAngle = spot ? static_cast<float>(number(ctx, *spot, "innerConeAngle", 0.0, se)) : 0.0f;
            p.outerConeAngle = spot ? static_cast<float>(number(ctx, *spot, "outerConeAngle", 0.7853981634, se))
                                    : 0.7853981634f;
            if (!(p.innerConeAngle >= 0.0f && p.innerConeAngle < p.outerConeAngle && p.outerConeAngle <= 1.5707964f))
                ctx.fail(se, "expected 0 <= innerConeAngle < outerConeAngle <= pi/2");
        }
        p.node = static_cast<uint32_t>(remap[i]);
        scene.lights.push_back(p);
    }
}

} // namespace

void loadNodesAndScene(LoadContext& ctx) {
    const tinygltf::Model& model = *ctx.model;
    Scene& scene = *ctx.scene;
    const Json* nodesJson = member(ctx.doc, "nodes");

    // exportGlb()'s helper nodes (camera-path carriers, the sun) are dropped: the scene keeps those
    // things exactly in camera paths and extras.
    std::vector<int32_t> parentOf(model.nodes.size(), -1);
    for (size_t i = 0; i < model.nodes.size(); ++i) {
        for (int child : model.nodes[i].children) {
            if (parentOf[child] >= 0) {
                ctx.fail("nodes[" + std::to_string(i) + "].children",
                         "node " + std::to_string(child) + " is already a child of nodes[" +
                             std::to_string(parentOf[child]) + "]; expected a tree");
            }
            parentOf[child] = static_cast<int32_t>(i);
        }
    }
    for (size_t i = 0; i < model.nodes.size(); ++i) {
        size_t steps = 0;
        for (int32_t n = parentOf[i]; n >= 0; n = parentOf[n]) {
            if (++steps > model.nodes.size() || n == static_cast<int32_t>(i)) {
                ctx.fail("nodes[" + std::to_string(i) + "]", "is its own ancestor; expected a tree");
            }
        }
    }
    std::vector<int32_t> remap(model.nodes.size(), -1);
    for (size_t i = 0; i < model.nodes.size(); ++i) {
        const tinygltf::Node& n = model.nodes[i];
        std::string r = role(ctx, (*nodesJson)[i], "nodes[" + std::to_string(i) + "]");
        bool helper = (r == "cameraPath" || r == "sun") && n.children.empty() && n.mesh < 0 && parentOf[i] < 0;
        if (!helper) remap[i] = static_cast<int32_t>(scene.nodes.size()), scene.nodes.emplace_back();
    }
    for (size_t i = 0; i < model.nodes.size(); ++i) {
        if (remap[i] < 0) continue;
        const tinygltf::Node& n = model.nodes[i];
        std::string e = "nodes[" + std::to_string(i) + "]";
        Node& node = scene.nodes[remap[i]];
        node.name = n.name;
        node.local = readTransform(ctx, n, e);
        node.mesh = n.mesh;
        node.camera = n.camera;
        node.skin = n.skin;
        for (int child : n.children)
            node.children.push_back(static_cast<uint32_t>(remap[child]));
    }
    // Skins: joints as scene nodes, inverse bind matrices (identity without an accessor).
    for (size_t i = 0; i < model.skins.size(); ++i) {
        const tinygltf::Skin& sk = model.skins[i];
        std::string e = "skins[" + std::to_string(i) + "]";
        Skin skin;
        skin.name = sk.name;
        for (size_t j = 0; j < sk.joints.size(); ++j) {
            int joint = sk.joints[j];
            if (joint < 0 || static_cast<size_t>(joint) >= model.nodes.size() || remap[joint] < 0)
                ctx.fail(e + ".joints[" + std::to_string(j) + "]", "expected the index of a node");
            skin.joints.push_back(static_cast<uint32_t>(remap[joint]));
        }
        skin.inverseBind.assign(skin.joints.size(), glm::mat4(1.0f));
        if (sk.inverseBindMatrices >= 0) {
            AccessorValues m = readAccessor(ctx, sk.inverseBindMatrices, e + ".inverseBindMatrices", {16}, true);
            if (m.count != skin.joints.size()) {
                ctx.fail(e + ".inverseBindMatrices", std::to_string(m.count) + " matrices; expected " +
                                                         std::to_string(skin.joints.size()) + " (one per joint)");
            }
            for (size_t j = 0; j < m.count; ++j)
                for (int c = 0; c < 16; ++c)
                    skin.inverseBind[j][c / 4][c % 4] = m.data[j * 16 + c]; // column-major, as glTF
        }
        scene.skins.push_back(std::move(skin));
    }
    for (size_t i = 0; i < model.nodes.size(); ++i) {
        const tinygltf::Node& n = model.nodes[i];
        if (remap[i] < 0 || n.skin < 0) continue;
        std::string e = "nodes[" + std::to_string(i) + "].skin";
        if (static_cast<size_t>(n.skin) >= scene.skins.size()) ctx.fail(e, "expected the index of a skin");
        if (n.mesh < 0) continue;
        const Mesh& mesh = scene.meshes[n.mesh];
        for (uint32_t k = 0; k < mesh.primitiveCount; ++k) {
            const Primitive& p = scene.primitives[mesh.firstPrimitive + k];
            if (!p.skinned) continue;
            for (uint32_t v = 0; v < p.vertexCount; ++v) {
                glm::vec4 j = scene.skinVertices[p.firstSkinVertex + v].joints;
                if (std::max({j.x, j.y, j.z, j.w}) >= float(scene.skins[n.skin].joints.size())) {
                    ctx.fail("meshes[" + std::to_string(n.mesh) + "].primitives[" + std::to_string(k) +
                                 "].attributes.JOINTS_0",
                             "vertex " + std::to_string(v) + " names joint " +
                                 std::to_string(int(std::max({j.x, j.y, j.z, j.w}))) + "; " + e + " has " +
                                 std::to_string(scene.skins[n.skin].joints.size()) + " joints");
                }
            }
        }
    }
    // A node's morph `weights` override its mesh's: the first node that draws a mesh sets its rest pose.
    std::vector<int> weightsFrom(scene.meshes.size(), -1);
    for (size_t i = 0; i < model.nodes.size(); ++i) {
        const tinygltf::Node& n = model.nodes[i];
        if (remap[i] < 0 || n.mesh < 0 || static_cast<size_t>(n.mesh) >= scene.meshes.size()) continue;
        std::string e = "nodes[" + std::to_string(i) + "].weights";
        Mesh& mesh = scene.meshes[n.mesh];
        std::vector<float> w(n.weights.begin(), n.weights.end());
        if (w.empty()) w = mesh.weights;
        if (w.size() != mesh.weights.size()) {
            ctx.fail(e, std::to_string(w.size()) + " weights; expected " + std::to_string(mesh.weights.size()) +
                            " (one per morph target of meshes[" + std::to_string(n.mesh) + "])");
        }
        if (weightsFrom[n.mesh] >= 0) {
            if (w != mesh.weights) {
                ctx.warn(e, "differ from those of nodes[" + std::to_string(weightsFrom[n.mesh]) +
                                "], which draws the same mesh; vitrine morphs a mesh once, with the first node's weights");
            }
            continue;
        }
        weightsFrom[n.mesh] = static_cast<int>(i);
        if (w == mesh.weights) continue;
        for (uint32_t k = 0; k < mesh.primitiveCount; ++k) {
            const Primitive& p = scene.primitives[mesh.firstPrimitive + k];
            std::vector<Vertex> morphed(p.vertexCount);
            scene.morphVertices(mesh.firstPrimitive + k, w, morphed);
            std::copy(morphed.begin(), morphed.end(), scene.vertices.begin() + p.vertexOffset);
        }
        mesh.weights = w;
    }

    for (size_t i = 0; i < model.cameras.size(); ++i) {
        scene.cameras.push_back(
            readCamera(ctx, model.cameras[i], ctx.doc["cameras"][i], "cameras[" + std::to_string(i) + "]"));
    }

    std::vector<std::pair<size_t, const Json*>> exportedPaths;
    for (size_t i = 0; i < model.animations.size(); ++i) {
        const tinygltf::Animation& a = model.animations[i];
        std::string e = "animations[" + std::to_string(i) + "]";
        const Json& json = ctx.doc["animations"][i];
        const Json* extras = member(json, "extras");
        const Json* ours = extras ? object(ctx, *extras, kExtrasKey, e + ".extras") : nullptr;
        if (const Json* path = ours ? object(ctx, *ours, "cameraPath", e + ".extras.vitrine") : nullptr) {
            exportedPaths.emplace_back(i, path);
            continue;
        }
        Animation out;
        out.name = a.name;
        out.loop = ours ? boolean(ctx, *ours, "loop", false, e + ".extras.vitrine") : false;
        // Samplers that a kept channel uses, in file order (samplers only for morph weights go).
        // Morph weights of a node without a morphed mesh have nothing to drive.
        auto morphTargets = [&](const tinygltf::AnimationChannel& ch) -> size_t {
            int mesh = ch.target_node >= 0 ? model.nodes[ch.target_node].mesh : -1;
            return mesh >= 0 && static_cast<size_t>(mesh) < scene.meshes.size() ? scene.meshes[mesh].weights.size() : 0;
        };
        auto kept = [&](const tinygltf::AnimationChannel& ch) {
            return ch.target_node >= 0 && remap[ch.target_node] >= 0 &&
                   (ch.target_path != "weights" || morphTargets(ch) > 0);
        };
        std::vector<int> samplerRemap(a.samplers.size(), -1);
        for (const tinygltf::AnimationChannel& ch : a.channels)
            samplerRemap[ch.sampler] = kept(ch) ? 0 : samplerRemap[ch.sampler];
        int used = 0;
        for (int& s : samplerRemap)
            s = s < 0 ? -1 : used++;
        out.samplers.resize(used);
        std::vector<int> samplerPath(used, -1);
        for (size_t c = 0; c < a.channels.size(); ++c) {
            const tinygltf::AnimationChannel& ch = a.channels[c];
            std::string ce = e + ".channels[" + std::to_string(c) + "]";
            if (!kept(ch)) {
                ctx.warn(ce, ch.target_path == "weights" && ch.target_node >= 0
                                 ? "drives morph weights of a node without a mesh with morph targets; ignored"
                                 : "targets no node; ignored");
                continue;
            }
            AnimationPath path = toPath(ctx, ch.target_path, ce + ".target.path");
            int s = samplerRemap[ch.sampler];
            std::string se = e + ".samplers[" + std::to_string(ch.sampler) + "]";
            uint32_t width = path == AnimationPath::Weights ? static_cast<uint32_t>(morphTargets(ch)) : 1;
            if (samplerPath[s] < 0) {
                out.samplers[s] = readSampler(ctx, a.samplers[ch.sampler], path, se, width);
                samplerPath[s] = static_cast<int>(path);
            } else if ((samplerPath[s] == int(AnimationPath::Rotation)) != (path == AnimationPath::Rotation) ||
                       (samplerPath[s] == int(AnimationPath::Weights)) != (path == AnimationPath::Weights) ||
                       out.samplers[s].width != width) {
                ctx.fail(se, "drives values of different kinds (rotation, translation/scale, weights of another "
                             "count); expected one kind of value");
            }
            out.channels.push_back({static_cast<uint32_t>(remap[ch.target_node]), path, static_cast<uint32_t>(s)});
        }
        scene.animations.push_back(std::move(out));
    }

    const Json* scenes = member(ctx.doc, "scenes");
    if (scenes && scenes->is_array() && !scenes->empty()) {
        size_t s = static_cast<size_t>(integer(ctx, ctx.doc, "scene", 0, ""));
        std::string e = "scenes[" + std::to_string(s) + "]";
        const Json& sceneJson = (*scenes)[s];
        scene.name = string(ctx, sceneJson, "name", "", e);
        if (const Json* roots = member(sceneJson, "nodes")) {
            for (size_t k = 0; k < roots->size(); ++k) {
                size_t n = (*roots)[k].get<size_t>();
                if (parentOf[n] >= 0) {
                    ctx.fail(e + ".nodes[" + std::to_string(k) + "]",
                             "node " + std::to_string(n) + " has a parent; expected root nodes only");
                }
                if (remap[n] >= 0) scene.roots.push_back(static_cast<uint32_t>(remap[n]));
            }
        }
        readSceneExtras(ctx, sceneJson, e);
        readProbes(ctx, sceneJson, e);
    }
    scene.finalize();
    // The rest pose of skinned meshes: skinned by the first node that draws each with a skin, joints at rest.
    if (!scene.skins.empty()) {
        ScenePose rest = scene.restPose();
        std::vector<int> skinnedBy(scene.meshes.size(), -1);
        for (size_t i = 0; i < scene.nodes.size(); ++i) {
            const Node& n = scene.nodes[i];
            if (n.skin < 0 || n.mesh < 0) continue;
            if (skinnedBy[n.mesh] >= 0) {
                if (scene.nodes[skinnedBy[n.mesh]].skin != n.skin)
                    ctx.warn("nodes[" + std::to_string(i) + "].skin",
                             "its mesh is skinned by another node's skin too; vitrine poses a mesh once, by the first");
                continue;
            }
            skinnedBy[n.mesh] = static_cast<int>(i);
            std::vector<glm::mat4> joints = scene.jointMatrices(static_cast<uint32_t>(i), rest);
            const Mesh& mesh = scene.meshes[n.mesh];
            for (uint32_t k = 0; k < mesh.primitiveCount; ++k) {
                const Primitive& p = scene.primitives[mesh.firstPrimitive + k];
                std::vector<Vertex> posed(p.vertexCount);
                scene.skinPrimitive(mesh.firstPrimitive + k, joints, posed);
                std::copy(posed.begin(), posed.end(), scene.vertices.begin() + p.vertexOffset);
            }
        }
        scene.finalize(); // bounds of the posed vertices
    }
    readLights(ctx, remap);

    for (const auto& [index, path] : exportedPaths) {
        scene.cameraPaths.push_back(
            readExportedPath(ctx, model.animations[index], *path, "animations[" + std::to_string(index) + "]"));
    }
    size_t exported = scene.cameraPaths.size();
    for (size_t n = 0; n < scene.nodes.size(); ++n) {
        if (scene.nodes[n].camera < 0) continue;
        CameraPath path = pathForCameraNode(ctx, scene, static_cast<uint32_t>(n));
        // A path exportGlb() wrote under this node's name already is this camera's (a re-import).
        auto end = scene.cameraPaths.begin() + static_cast<std::ptrdiff_t>(exported);
        if (std::any_of(scene.cameraPaths.begin(), end, [&](const CameraPath& p) { return p.name == path.name; }))
            continue;
        std::string base = path.name;
        for (int k = 2; scene.findCameraPath(path.name); ++k)
            path.name = base + "#" + std::to_string(k);
        scene.cameraPaths.push_back(std::move(path));
    }
}

// tinygltf's image decoder (stb_image), except that an image it cannot decode (WebP, KTX2, damaged data) is left empty
// instead of failing the whole file: loadImagesAndTextures() warns and draws the textures using it without it.
bool decodeOrLeaveEmpty(tinygltf::Image* image, int index, std::string*, std::string* warn, int width, int height,
                        const unsigned char* bytes, int size, void*) {
    std::string ignored;
    if (tinygltf::LoadImageData(image, index, &ignored, warn, width, height, bytes, size, nullptr)) return true;
    image->image.clear();
    image->width = image->height = 0;
    return true;
}

} // namespace vitrine::scene::gltf

namespace vitrine::scene {

Scene loadGltfFromMemory(const std::vector<uint8_t>& bytes, const std::filesystem::path& file,
                         std::vector<std::string>& warnings, const std::string& materialVariant) {
    using namespace gltf;
    LoadContext ctx;
    ctx.file = file.string();
    ctx.baseDir = file.parent_path();
    ctx.warnings = &warnings;
    ctx.materialVariant = materialVariant;
    preflight(ctx, file, bytes);

    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(decodeOrLeaveEmpty, nullptr);
    std::string err, warn;
    const std::vector<uint8_t>& input = ctx.tinygltfInput.empty() ? bytes : ctx.tinygltfInput;
    bool ok = ctx.glb ? loader.LoadBinaryFromMemory(&model, &err, &warn, input.data(),
                                                    static_cast<unsigned>(input.size()), ctx.baseDir.string())
                      : loader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(input.data()),
                                                   static_cast<unsigned>(input.size()), ctx.baseDir.string());
    std::istringstream lines(warn);
    for (std::string line; std::getline(lines, line);) {
        if (!line.empty()) ctx.warn("tinygltf", line);
    }
    if (!ok) {
        // preflight() checks what glTF requires, so this is rare; tinygltf's parsers may give no reason at all.
        while (!err.empty() && (err.back() == '\n' || err.back() == ' '))
            err.pop_back();
        std::replace(err.begin(), err.end(), '\n', ';');
        ctx.fail("glTF", err.empty() ? "tinygltf refused the file without saying why (a property of the wrong type "
                                       "or one its parser requires?); check it with the Khronos glTF-Validator"
                                     : "tinygltf could not load it: " + err);
    }

    Scene scene;
    ctx.model = &model;
    ctx.scene = &scene;
    loadImagesAndTextures(ctx);
    loadMaterials(ctx);
    loadMeshes(ctx);
    loadNodesAndScene(ctx);
    scene.validate();
    return scene;
}

Scene loadGltf(const std::filesystem::path& file, std::vector<std::string>& warnings,
               const std::string& materialVariant) {
    gltf::LoadContext ctx;
    ctx.file = file.string();
    return loadGltfFromMemory(gltf::readGltfFile(ctx, file), file, warnings, materialVariant);
}

Scene loadGltfReporting(const std::filesystem::path& file, bool strict, const std::string& materialVariant) {
    std::vector<std::string> warnings; // distinct already (LoadContext::warn)
    Scene scene = loadGltf(file, warnings, materialVariant);
    if (strict && !warnings.empty()) {
        std::string list;
        for (const std::string& w : warnings)
            list += "\n  " + w;
        throw UserError(file.string() + ": " + std::to_string(warnings.size()) +
                        (warnings.size() == 1 ? " warning" : " warnings") +
                        ", which strict loading (--strict, or the scene.gltf param strict) makes errors:" + list);
    }
    for (const std::string& w : warnings)
        logWarning(w);
    return scene;
}

Scene loadGltf(const std::filesystem::path& file) {
    std::vector<std::string> warnings;
    return loadGltf(file, warnings);
}

} // namespace vitrine::scene
