#include "core/scene/scene.hpp"

#include "core/base/error.hpp"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace vitrine::scene {

Aabb Aabb::transformed(const glm::mat4& m) const {
    Aabb out;
    if (empty()) return out;
    for (int i = 0; i < 8; ++i) {
        glm::vec3 corner((i & 1) ? max.x : min.x, (i & 2) ? max.y : min.y, (i & 4) ? max.z : min.z);
        out.expand(glm::vec3(m * glm::vec4(corner, 1.0f)));
    }
    return out;
}

glm::mat4 Transform::matrix() const {
    glm::mat4 m = glm::mat4_cast(rotation);
    m[0] *= scale.x;
    m[1] *= scale.y;
    m[2] *= scale.z;
    m[3] = glm::vec4(translation, 1.0f);
    return m;
}

glm::mat3 UvTransform::matrix() const {
    float c = std::cos(rotation), s = std::sin(rotation);
    // T · R · S from the KHR_texture_transform specification, written out; glm is column-major.
    return glm::mat3(glm::vec3(c * scale.x, -s * scale.x, 0.0f), glm::vec3(s * scale.y, c * scale.y, 0.0f),
                     glm::vec3(offset, 1.0f));
}

float Camera::focalLengthMm() const {
    return 0.5f * sensorHeightMm / std::tan(0.5f * yfov);
}

glm::vec3 CameraPath::tangent(size_t key) const {
    if (!smooth || keys.size() < 2) return glm::vec3(0.0f);
    size_t prev = key == 0 ? 0 : key - 1;
    size_t next = std::min(key + 1, keys.size() - 1);
    float dt = keys[next].time - keys[prev].time;
    return dt > 0.0f ? (keys[next].position - keys[prev].position) / dt : glm::vec3(0.0f);
}

glm::mat4 CameraState::projection(float frameAspect, bool reverseZ) const {
    // The authored aspectRatio never stretches the image (the Khronos glTF Sample Viewer's rule): a perspective camera
    // keeps its vertical field of view and the frame's width decides the horizontal one; an orthographic camera keeps
    // ymag on a landscape frame (xmag = ymag × aspect) and xmag on a square or portrait one (ymag = xmag / aspect).
    float aspect = frameAspect;
    float n = lens.znear, f = lens.zfar;
    glm::mat4 m(0.0f);
    if (lens.projection == Projection::Orthographic) {
        float far = f > n ? f : n + 1000.0f;
        float xmag = aspect > 1.0f ? lens.ymag * aspect : lens.xmag;
        float ymag = aspect > 1.0f ? lens.ymag : lens.xmag / aspect;
        m[0][0] = 1.0f / xmag;
        m[1][1] = -1.0f / ymag; // Vulkan's y points down
        m[2][2] = -1.0f / (far - n);
        m[3][2] = -n / (far - n);
        m[3][3] = 1.0f;
    } else {
        float g = 1.0f / std::tan(0.5f * lens.yfov);
        m[0][0] = g / aspect;
        m[1][1] = -g;
        m[2][3] = -1.0f;
        if (f > 0.0f) {
            m[2][2] = f / (n - f);
            m[3][2] = n * f / (n - f);
        } else {
            m[2][2] = -1.0f;
            m[3][2] = -n;
        }
    }
    if (reverseZ) {
        // depth' = 1 - depth, i.e. clip z' = w - z.
        for (int c = 0; c < 4; ++c)
            m[c][2] = m[c][3] - m[c][2];
    }
    return m;
}

void Scene::finalize() {
    for (Node& node : nodes)
        node.parent = -1;
    for (size_t i = 0; i < nodes.size(); ++i) {
        for (uint32_t child : nodes[i].children) {
            if (child >= nodes.size() || nodes[child].parent >= 0 || child == i) {
                throw InternalError("scene '" + name + "': nodes[" + std::to_string(i) + "].children: node " +
                                    std::to_string(child) + " is out of range, its own child or has two parents");
            }
            nodes[child].parent = static_cast<int32_t>(i);
        }
    }
    if (roots.empty()) {
        for (size_t i = 0; i < nodes.size(); ++i) {
            if (nodes[i].parent < 0) roots.push_back(static_cast<uint32_t>(i));
        }
    }

    std::vector<bool> animated(nodes.size(), false);
    for (const Animation& animation : animations) {
        for (const AnimationChannel& channel : animation.channels) {
            if (channel.node < nodes.size()) animated[channel.node] = true;
        }
    }

    for (Primitive& p : primitives) {
        p.bounds = Aabb();
        for (uint32_t v = 0; v < p.vertexCount; ++v)
            p.bounds.expand(vertices[p.vertexOffset + v].position);
    }
    for (Mesh& mesh : meshes) {
        mesh.bounds = Aabb();
        for (uint32_t i = 0; i < mesh.primitiveCount; ++i)
            mesh.bounds.expand(primitives[mesh.firstPrimitive + i].bounds);
    }

    // Depth-first from the roots; a parent is always visited before its children.
    instances.clear();
    bounds = Aabb();
    struct Item {
        uint32_t node;
        glm::mat4 parentWorld;
        bool parentDynamic;
    };
    std::vector<Item> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it)
        stack.push_back({*it, glm::mat4(1.0f), false});
    while (!stack.empty()) {
        Item item = stack.back();
        stack.pop_back();
        Node& node = nodes[item.node];
        glm::mat4 world = item.parentWorld * node.local.matrix();
        node.dynamic = item.parentDynamic || animated[item.node];
        if (node.mesh >= 0) {
            MeshInstance instance;
            instance.node = item.node;
            instance.mesh = static_cast<uint32_t>(node.mesh);
            instance.world = world;
            instance.dynamic = node.dynamic;
            instance.worldBounds = meshes[instance.mesh].bounds.transformed(world);
            bounds.expand(instance.worldBounds);
            instances.push_back(instance);
        }
        for (auto it = node.children.rbegin(); it != node.children.rend(); ++it) {
            stack.push_back({*it, world, node.dynamic});
        }
    }
    // A skinned mesh moves with its joints: dynamic when one of them is.
    for (MeshInstance& instance : instances) {
        int32_t skin = nodes[instance.node].skin;
        if (skin < 0 || static_cast<size_t>(skin) >= skins.size()) continue;
        for (uint32_t j : skins[skin].joints)
            instance.dynamic = instance.dynamic || (j < nodes.size() && nodes[j].dynamic);
    }
    // Instances in node order, which is what both the loader and the builders think of as "the" order.
    std::stable_sort(instances.begin(), instances.end(),
                     [](const MeshInstance& a, const MeshInstance& b) { return a.node < b.node; });
}

void Scene::morphVertices(uint32_t primitive, const std::vector<float>& weights, std::span<Vertex> out) const {
    const Primitive& p = primitives[primitive];
    const Vertex* rest = vertices.data() + p.vertexOffset;
    std::copy(rest, rest + p.vertexCount, out.begin());
    const Mesh* mesh = nullptr;
    for (const Mesh& m : meshes) {
        if (primitive >= m.firstPrimitive && primitive < m.firstPrimitive + m.primitiveCount) mesh = &m;
    }
    if (!mesh || p.targetCount == 0) return;
    for (uint32_t t = 0; t < p.targetCount; ++t) {
        float restWeight = t < mesh->weights.size() ? mesh->weights[t] : 0.0f;
        float w = (t < weights.size() ? weights[t] : restWeight) - restWeight;
        if (w == 0.0f) continue;
        const MorphDelta* d = morphDeltas.data() + p.firstDelta + size_t(t) * p.vertexCount;
        for (uint32_t v = 0; v < p.vertexCount; ++v) {
            out[v].position += w * d[v].position;
            out[v].normal += w * d[v].normal;
            out[v].tangent += glm::vec4(w * d[v].tangent, 0.0f);
        }
    }
    for (Vertex& v : out) {
        float n = glm::length(v.normal), tl = glm::length(glm::vec3(v.tangent));
        if (n > 0.0f) v.normal /= n;
        if (tl > 0.0f) v.tangent = glm::vec4(glm::vec3(v.tangent) / tl, v.tangent.w);
    }
}

std::vector<glm::mat4> Scene::jointMatrices(uint32_t node, const ScenePose& pose) const {
    const Skin& skin = skins[nodes[node].skin];
    glm::mat4 toNode = glm::inverse(pose.nodeWorld[node]);
    std::vector<glm::mat4> out(skin.joints.size());
    for (size_t j = 0; j < skin.joints.size(); ++j) {
        glm::mat4 inverseBind = j < skin.inverseBind.size() ? skin.inverseBind[j] : glm::mat4(1.0f);
        out[j] = toNode * pose.nodeWorld[skin.joints[j]] * inverseBind;
    }
    return out;
}

void Scene::skinPrimitive(uint32_t primitive, const std::vector<glm::mat4>& joints, std::span<Vertex> out) const {
    const Primitive& p = primitives[primitive];
    const Vertex* rest = vertices.data() + p.vertexOffset;
    std::copy(rest, rest + p.vertexCount, out.begin());
    if (!p.skinned) return;
    for (uint32_t v = 0; v < p.vertexCount; ++v) {
        const SkinVertex& s = skinVertices[p.firstSkinVertex + v];
        glm::mat4 m(0.0f);
        for (int k = 0; k < 4; ++k) {
            size_t j = static_cast<size_t>(s.joints[k]);
            if (s.weights[k] != 0.0f && j < joints.size()) m += s.weights[k] * joints[j];
        }
        glm::mat3 n = glm::transpose(glm::inverse(glm::mat3(m)));
        out[v].position = glm::vec3(m * glm::vec4(s.position, 1.0f));
        glm::vec3 normal = n * s.normal, tangent = glm::mat3(m) * glm::vec3(s.tangent);
        float nl = glm::length(normal), tl = glm::length(tangent);
        out[v].normal = nl > 0.0f ? normal / nl : s.normal;
        out[v].tangent = glm::vec4(tl > 0.0f ? tangent / tl : glm::vec3(s.tangent), s.tangent.w);
    }
}

ScenePose Scene::restPose() const {
    ScenePose pose;
    pose.nodeWorld.assign(nodes.size(), glm::mat4(1.0f));
    std::vector<uint32_t> stack;
    for (size_t i = 0; i < nodes.size(); ++i) {
        if (nodes[i].parent < 0) stack.push_back(static_cast<uint32_t>(i));
    }
    while (!stack.empty()) {
        uint32_t n = stack.back();
        stack.pop_back();
        glm::mat4 parent = nodes[n].parent >= 0 ? pose.nodeWorld[nodes[n].parent] : glm::mat4(1.0f);
        pose.nodeWorld[n] = parent * nodes[n].local.matrix();
        for (uint32_t child : nodes[n].children)
            stack.push_back(child);
    }
    for (const MeshInstance& instance : instances)
        pose.instanceWorld.push_back(pose.nodeWorld[instance.node]);
    return pose;
}

ScenePose Scene::evaluate(double t) const {
    std::vector<Transform> local(nodes.size());
    for (size_t i = 0; i < nodes.size(); ++i)
        local[i] = nodes[i].local;
    ScenePose pose;
    for (const Animation& animation : animations) {
        float at = animation.localTime(t);
        for (const AnimationChannel& channel : animation.channels) {
            if (channel.path == AnimationPath::Weights) {
                int32_t mesh = nodes[channel.node].mesh;
                if (mesh < 0) continue;
                pose.meshWeights.resize(meshes.size());
                pose.meshWeights[mesh] = animation.samplers[channel.sampler].sampleWeights(at);
                pose.meshWeights[mesh].resize(meshes[mesh].weights.size(), 0.0f);
                continue;
            }
            glm::vec4 v = animation.samplers[channel.sampler].sample(at, channel.path);
            Transform& tr = local[channel.node];
            switch (channel.path) {
            case AnimationPath::Translation:
                tr.translation = glm::vec3(v);
                break;
            case AnimationPath::Rotation:
                tr.rotation = toQuat(v);
                break;
            case AnimationPath::Scale:
                tr.scale = glm::vec3(v);
                break;
            case AnimationPath::Weights:
                break;
            }
        }
    }

    pose.nodeWorld.assign(nodes.size(), glm::mat4(1.0f));
    std::vector<uint32_t> stack;
    for (size_t i = 0; i < nodes.size(); ++i) {
        if (nodes[i].parent < 0) stack.push_back(static_cast<uint32_t>(i));
    }
    while (!stack.empty()) {
        uint32_t n = stack.back();
        stack.pop_back();
        glm::mat4 parent = nodes[n].parent >= 0 ? pose.nodeWorld[nodes[n].parent] : glm::mat4(1.0f);
        pose.nodeWorld[n] = parent * local[n].matrix();
        for (uint32_t child : nodes[n].children)
            stack.push_back(child);
    }
    pose.instanceWorld.reserve(instances.size());
    for (const MeshInstance& instance : instances)
        pose.instanceWorld.push_back(pose.nodeWorld[instance.node]);
    return pose;
}

const CameraPath* Scene::findCameraPath(std::string_view path) const {
    for (const CameraPath& p : cameraPaths) {
        if (p.name == path) return &p;
    }
    return nullptr;
}

CameraState Scene::cameraAt(std::string_view pathName, double t) const {
    const CameraPath* path = findCameraPath(pathName);
    if (!path || path->keys.empty()) {
        std::string known;
        for (const CameraPath& p : cameraPaths)
            known += (known.empty() ? "" : ", ") + p.name;
        throw UserError("scene '" + name + "': camera path '" + std::string(pathName) + "' " +
                        (path ? "has no keys" : "not found") +
                        "; expected one of: " + (known.empty() ? "(none)" : known));
    }
    const std::vector<CameraKey>& keys = path->keys;
    float first = keys.front().time, last = keys.back().time;
    double time = t;
    if (path->loop && last > first) {
        time = std::fmod(t - first, static_cast<double>(last - first));
        if (time < 0.0) time += last - first;
        time += first;
    }
    float ft = std::clamp(static_cast<float>(time), first, last);

    size_t next = static_cast<size_t>(
        std::upper_bound(keys.begin(), keys.end(), ft, [](float v, const CameraKey& k) { return v < k.time; }) -
        keys.begin());
    size_t k = next == 0 ? 0 : next - 1;
    next = std::min(next, keys.size() - 1);
    const CameraKey& a = keys[k];
    const CameraKey& b = keys[next];
    float td = b.time - a.time;
    float s = td > 0.0f ? (ft - a.time) / td : 0.0f;

    CameraState state;
    if (path->smooth && td > 0.0f) {
        float s2 = s * s, s3 = s2 * s;
        state.position = (2 * s3 - 3 * s2 + 1) * a.position + td * (s3 - 2 * s2 + s) * path->tangent(k) +
                         (-2 * s3 + 3 * s2) * b.position + td * (s3 - s2) * path->tangent(next);
    } else {
        state.position = glm::mix(a.position, b.position, s);
    }
    state.orientation = glm::normalize(glm::slerp(a.orientation, b.orientation, s));
    state.lens = path->camera < cameras.size() ? cameras[path->camera] : Camera();
    state.lens.yfov = glm::mix(a.yfov, b.yfov, s);
    state.world = glm::translate(glm::mat4(1.0f), state.position) * glm::mat4_cast(state.orientation);
    state.view = glm::inverse(state.world);
    return state;
}

size_t Scene::memoryBytes() const {
    size_t bytes = vertices.size() * sizeof(Vertex) + indices.size() * sizeof(uint32_t);
    for (const TextureImage& image : images)
        bytes += image.pixels.size();
    return bytes;
}

} // namespace vitrine::scene
