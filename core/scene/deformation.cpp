#include "core/scene/deformation.hpp"

namespace vitrine::scene {

Deformation::Deformation(const Scene& scene) : mScene(scene) {
    bool morphAnimated = false;
    for (const Animation& a : scene.animations) {
        for (const AnimationChannel& c : a.channels)
            morphAnimated = morphAnimated || c.path == AnimationPath::Weights;
    }
    mDeformed.assign(scene.meshes.size(), false);
    mSkinnedNode.assign(scene.meshes.size(), -1);
    for (const MeshInstance& instance : scene.instances) {
        const Node& node = scene.nodes[instance.node];
        if (node.skin < 0 || !instance.dynamic) continue; // a still skin stays in its rest pose
        if (mSkinnedNode[instance.mesh] >= 0) continue;   // posed by the first node that draws it with a skin
        const Mesh& mesh = scene.meshes[instance.mesh];
        for (uint32_t k = 0; k < mesh.primitiveCount; ++k) {
            if (scene.primitives[mesh.firstPrimitive + k].skinned) {
                mSkinnedNode[instance.mesh] = static_cast<int32_t>(instance.node);
                mDeformed[instance.mesh] = true;
                break;
            }
        }
    }
    for (size_t m = 0; m < scene.meshes.size() && morphAnimated; ++m) {
        const Mesh& mesh = scene.meshes[m];
        for (uint32_t k = 0; k < mesh.primitiveCount; ++k)
            mDeformed[m] = mDeformed[m] || scene.primitives[mesh.firstPrimitive + k].targetCount > 0;
    }
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        if (!mDeformed[m]) continue;
        mAny = true;
        const Mesh& mesh = scene.meshes[m];
        for (uint32_t k = 0; k < mesh.primitiveCount; ++k) {
            const Primitive& p = scene.primitives[mesh.firstPrimitive + k];
            mRanges.push_back({p.vertexOffset, p.vertexCount});
        }
    }
}

void Deformation::pose(const ScenePose& pose, std::span<Vertex> out) const {
    if (!mAny) return;
    const bool nodesPosed = pose.nodeWorld.size() == mScene.nodes.size();
    for (size_t m = 0; m < mScene.meshes.size(); ++m) {
        if (!mDeformed[m]) continue;
        const Mesh& mesh = mScene.meshes[m];
        const bool skinned = mSkinnedNode[m] >= 0;
        std::vector<glm::mat4> joints;
        if (skinned && nodesPosed) joints = mScene.jointMatrices(static_cast<uint32_t>(mSkinnedNode[m]), pose);
        const std::vector<float>& weights =
            m < pose.meshWeights.size() && !pose.meshWeights[m].empty() ? pose.meshWeights[m] : mesh.weights;
        for (uint32_t k = 0; k < mesh.primitiveCount; ++k) {
            const uint32_t primitive = mesh.firstPrimitive + k;
            const Primitive& p = mScene.primitives[primitive];
            const std::span<Vertex> range = out.subspan(p.vertexOffset, p.vertexCount);
            if (skinned && p.skinned) {
                if (nodesPosed) mScene.skinPrimitive(primitive, joints, range);
            } else if (p.targetCount > 0) {
                mScene.morphVertices(primitive, weights, range);
            }
        }
    }
}

std::vector<Vertex> Deformation::posedVertices(const ScenePose& pose) const {
    std::vector<Vertex> v = mScene.vertices;
    this->pose(pose, v);
    return v;
}

} // namespace vitrine::scene
