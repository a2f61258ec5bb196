// glTF meshes → the scene's flat vertex/index arrays and primitive ranges.

#include "core/scene/closed_mesh.hpp"
#include "core/scene/gltf_detail.hpp"
#include "core/scene/tangents.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <tiny_gltf.h>

namespace vitrine::scene::gltf {

namespace {

uint32_t defaultMaterial(LoadContext& ctx) {
    if (ctx.defaultMaterial < 0) {
        // glTF's default material: every property at its default, i.e. white, metallic 1, roughness 1.
        Material m;
        m.name = "default";
        MaterialLayer layer;
        layer.name = "base";
        layer.shininess = ScalarParam{0.0f, 1.0f};
        layer.metallic = ScalarParam{1.0f, 0.0f};
        m.layers.push_back(layer);
        ctx.defaultMaterial = static_cast<int32_t>(ctx.scene->materials.size());
        ctx.scene->materials.push_back(m);
    }
    return static_cast<uint32_t>(ctx.defaultMaterial);
}

// Triangle strips and fans as lists (glTF's winding rules).
std::vector<uint32_t> toTriangleList(const LoadContext& ctx, std::vector<uint32_t> in, int mode, const std::string& e) {
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (in.size() % 3 != 0) { // legal (the Khronos validator warns): the trailing vertices make no triangle
            ctx.warn(e, std::to_string(in.size()) + " vertices or indices are not a multiple of 3; the last " +
                            std::to_string(in.size() % 3) + " are not drawn");
            in.resize(in.size() - in.size() % 3);
        }
        return in;
    }
    std::vector<uint32_t> out;
    for (size_t k = 0; k + 2 < in.size(); ++k) {
        if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
            bool even = k % 2 == 0;
            out.insert(out.end(), {in[k + (even ? 0 : 1)], in[k + (even ? 1 : 0)], in[k + 2]});
        } else {
            out.insert(out.end(), {in[0], in[k + 1], in[k + 2]});
        }
    }
    return out;
}

// indexAccessor: the primitive's `indices` as the file has it (tinygltf's copy may lack it, see tinygltfInput).
// weights: the mesh's rest weights, one per morph target (every primitive of a glTF mesh has as many targets).
// material: the primitive's material index (its own, or its KHR_materials_variants mapping), -1 for glTF's default.
void loadPrimitive(LoadContext& ctx, const tinygltf::Primitive& p, int indexAccessor, const std::vector<float>& weights,
                   int material, const std::string& e) {
    int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
    if (mode <= TINYGLTF_MODE_LINE_STRIP) {
        ctx.warn(e, "points and lines are not drawn; primitive skipped");
        return;
    }
    if (mode > TINYGLTF_MODE_TRIANGLE_FAN) ctx.fail(e + ".mode", std::to_string(mode) + "; expected 0..6");

    auto find = [&](const char* name) {
        auto it = p.attributes.find(name);
        return it == p.attributes.end() ? -1 : it->second;
    };
    int positionAccessor = find("POSITION");
    if (positionAccessor < 0) { // legal: an extension may supply positions; vitrine reads none that does
        ctx.warn(e + ".attributes", "no POSITION; primitive skipped");
        return;
    }
    AccessorValues positions = readAccessor(ctx, positionAccessor, e + ".attributes.POSITION", {3});
    size_t n = positions.count;
    auto read = [&](const char* name, std::initializer_list<int> comps) {
        AccessorValues v;
        int accessor = find(name);
        if (accessor < 0) return v;
        v = readAccessor(ctx, accessor, e + ".attributes." + name, comps);
        if (v.count != n) {
            ctx.fail(e + ".attributes." + name,
                     std::to_string(v.count) + " elements; expected " + std::to_string(n) + " like POSITION");
        }
        return v;
    };
    AccessorValues normals = read("NORMAL", {3});
    AccessorValues tangents = read("TANGENT", {4});
    AccessorValues uv0 = read("TEXCOORD_0", {2});
    AccessorValues uv1 = read("TEXCOORD_1", {2});
    AccessorValues colors = read("COLOR_0", {3, 4});
    AccessorValues ao = read("_AO", {1});
    AccessorValues joints = read("JOINTS_0", {4});
    AccessorValues jointWeights = read("WEIGHTS_0", {4});
    if ((joints.count > 0) != (jointWeights.count > 0))
        ctx.fail(e + ".attributes", joints.count ? "JOINTS_0 without WEIGHTS_0; expected both for skinning"
                                                 : "WEIGHTS_0 without JOINTS_0; expected both for skinning");
    for (const auto& [name, accessor] : p.attributes) {
        static const char* kKnown[] = {"POSITION", "NORMAL",     "TANGENT", "TEXCOORD_0", "TEXCOORD_1",
                                       "COLOR_0",  "_AO",        "JOINTS_0", "WEIGHTS_0"};
        if (std::find(std::begin(kKnown), std::end(kKnown), name) == std::end(kKnown)) {
            ctx.warn(e + ".attributes." + name, "not used by vitrine; ignored");
        }
    }
    // Morph targets: POSITION, NORMAL and TANGENT displacements, target-major (Primitive::firstDelta).
    if (p.targets.size() != weights.size()) {
        ctx.fail(e + ".targets", std::to_string(p.targets.size()) + " morph targets; expected " +
                                     std::to_string(weights.size()) +
                                     " (the mesh's weights, and every primitive of a mesh has as many targets)");
    }
    std::vector<MorphDelta> deltas(p.targets.size() * n);
    for (size_t t = 0; t < p.targets.size(); ++t) {
        std::string te = e + ".targets[" + std::to_string(t) + "]";
        for (const auto& [name, accessor] : p.targets[t]) {
            glm::vec3 MorphDelta::*field = name == "POSITION" ? &MorphDelta::position
                                           : name == "NORMAL" ? &MorphDelta::normal
                                           : name == "TANGENT" ? &MorphDelta::tangent
                                                              : nullptr;
            if (!field) {
                ctx.warn(te + "." + name, "morph displacements of this attribute are not used by vitrine; ignored");
                continue;
            }
            AccessorValues v = readAccessor(ctx, accessor, te + "." + name, {3});
            if (v.count != n) {
                ctx.fail(te + "." + name,
                         std::to_string(v.count) + " elements; expected " + std::to_string(n) + " like POSITION");
            }
            for (size_t i = 0; i < n; ++i)
                deltas[t * n + i].*field = glm::vec3(v.get(i));
        }
    }

    std::vector<uint32_t> indices(n);
    if (indexAccessor >= 0) {
        indices = readIndices(ctx, indexAccessor, e + ".indices");
    } else {
        std::iota(indices.begin(), indices.end(), 0u);
    }
    for (size_t k = 0; k < indices.size(); ++k) {
        if (indices[k] >= n) {
            ctx.fail(e + ".indices", "index " + std::to_string(indices[k]) + " at position " + std::to_string(k) +
                                         " is out of range; expected < " + std::to_string(n) + " (the POSITION count)");
        }
    }
    indices = toTriangleList(ctx, std::move(indices), mode, e);
    if (indices.empty()) {
        ctx.warn(e, "has no triangles; skipped");
        return;
    }

    std::vector<Vertex> vertices(n);
    for (size_t i = 0; i < n; ++i) {
        Vertex& v = vertices[i];
        v.position = glm::vec3(positions.get(i));
        if (normals.count) {
            glm::vec3 nrm = glm::vec3(normals.get(i));
            float len = glm::length(nrm);
            // Only visibly wrong lengths are fixed, so that unit normals come back bit-exact.
            v.normal = std::abs(len - 1.0f) <= 1e-5f ? nrm : len > 0.0f ? nrm / len : glm::vec3(0, 1, 0);
        }
        if (tangents.count) v.tangent = tangents.get(i);
        if (uv0.count) v.uv0 = glm::vec2(uv0.get(i));
        if (uv1.count) v.uv1 = glm::vec2(uv1.get(i));
        if (colors.count) v.color = glm::vec4(glm::vec3(colors.get(i)), 1.0f);
        if (ao.count) v.color.a = ao.get(i).x;
    }
    if (!normals.count) {
        // glTF: "When normals are not specified, client implementations MUST calculate flat normals",
        // which needs a vertex per triangle corner; the file's tangents are then meaningless too.
        std::vector<Vertex> flat;
        flat.reserve(indices.size());
        for (size_t t = 0; t < indices.size(); t += 3) {
            Vertex a = vertices[indices[t]], b = vertices[indices[t + 1]], c = vertices[indices[t + 2]];
            glm::vec3 fn = glm::cross(b.position - a.position, c.position - a.position);
            float len = glm::length(fn);
            fn = len > 0.0f ? fn / len : glm::vec3(0, 1, 0);
            a.normal = b.normal = c.normal = fn;
            flat.insert(flat.end(), {a, b, c});
        }
        if (!deltas.empty()) { // the targets follow the vertices; flat normals stay flat (their deltas go)
            std::vector<MorphDelta> flatDeltas(weights.size() * indices.size());
            for (size_t t = 0; t < weights.size(); ++t)
                for (size_t k = 0; k < indices.size(); ++k)
                    flatDeltas[t * indices.size() + k] = {deltas[t * n + indices[k]].position, glm::vec3(0.0f),
                                                          glm::vec3(0.0f)};
            deltas = std::move(flatDeltas);
        }
        vertices = std::move(flat);
        if (joints.count) { // the skin attributes follow the vertices
            AccessorValues flatJoints = joints, flatWeights = jointWeights;
            flatJoints.count = flatWeights.count = indices.size();
            flatJoints.data.resize(indices.size() * 4);
            flatWeights.data.resize(indices.size() * 4);
            for (size_t k = 0; k < indices.size(); ++k) {
                for (int c = 0; c < 4; ++c) {
                    flatJoints.data[k * 4 + c] = joints.data[indices[k] * 4 + c];
                    flatWeights.data[k * 4 + c] = jointWeights.data[indices[k] * 4 + c];
                }
            }
            joints = std::move(flatJoints);
            jointWeights = std::move(flatWeights);
        }
        std::iota(indices.begin(), indices.end(), 0u);
    }
    // The rest pose: the mesh's weights applied (normals and tangents renormalised).
    for (size_t t = 0; t < weights.size(); ++t) {
        if (weights[t] == 0.0f) continue;
        for (size_t i = 0; i < vertices.size(); ++i) {
            const MorphDelta& d = deltas[t * vertices.size() + i];
            vertices[i].position += weights[t] * d.position;
            vertices[i].normal += weights[t] * d.normal;
            vertices[i].tangent += glm::vec4(weights[t] * d.tangent, 0.0f);
        }
    }
    if (!weights.empty()) {
        for (Vertex& v : vertices) {
            float len = glm::length(v.normal), tl = glm::length(glm::vec3(v.tangent));
            if (len > 0.0f) v.normal /= len;
            if (tl > 0.0f) v.tangent = glm::vec4(glm::vec3(v.tangent) / tl, v.tangent.w);
        }
    }
    if (!tangents.count || !normals.count) generateTangents(vertices, indices);

    Scene& scene = *ctx.scene;
    if (material >= 0 && static_cast<size_t>(material) < scene.materials.size()) {
        if (!uv0.count && usesUvSet(scene.materials[material], 0))
            ctx.warn(e, "its material samples TEXCOORD_0, which it lacks; (0, 0) used");
        if (!uv1.count && usesUvSet(scene.materials[material], 1))
            ctx.warn(e, "its material samples TEXCOORD_1, which it lacks; (0, 0) used");
    }
    Primitive prim;
    prim.firstIndex = static_cast<uint32_t>(scene.indices.size());
    prim.indexCount = static_cast<uint32_t>(indices.size());
    prim.vertexOffset = static_cast<uint32_t>(scene.vertices.size());
    prim.vertexCount = static_cast<uint32_t>(vertices.size());
    prim.material = material >= 0 ? static_cast<uint32_t>(material) : defaultMaterial(ctx);
    prim.lightmapUvs = uv1.count > 0;
    size_t unweighted = 0; // vertices whose weights do not add up to anything
    for (size_t i = 0; joints.count && i < vertices.size(); ++i) {
        const glm::vec4 w = jointWeights.get(i);
        unweighted += !(w.x + w.y + w.z + w.w > 0.0f);
    }
    if (unweighted) { // the Khronos validator does not check the sums; skinning would collapse such vertices
        ctx.warn(e + ".attributes.WEIGHTS_0", std::to_string(unweighted) + " of " + std::to_string(vertices.size()) +
                                                  " vertices have weights summing to 0 (glTF: they sum to 1); the "
                                                  "primitive is drawn unskinned, with its node");
    }
    if (joints.count && !unweighted) {
        // Bind space as loaded (rest morph weights applied); the loader skins the rest pose once the nodes are known.
        prim.skinned = true;
        prim.firstSkinVertex = static_cast<uint32_t>(scene.skinVertices.size());
        for (size_t i = 0; i < vertices.size(); ++i) {
            glm::vec4 w = jointWeights.get(i);
            float sum = w.x + w.y + w.z + w.w;
            scene.skinVertices.push_back({vertices[i].position, vertices[i].normal, vertices[i].tangent,
                                          joints.get(i), w / sum}); // glTF: weights sum to 1 (normalised here)
        }
    }
    prim.firstDelta = static_cast<uint32_t>(scene.morphDeltas.size());
    prim.targetCount = static_cast<uint32_t>(weights.size());
    scene.morphDeltas.insert(scene.morphDeltas.end(), deltas.begin(), deltas.end());
    scene.indices.insert(scene.indices.end(), indices.begin(), indices.end());
    scene.vertices.insert(scene.vertices.end(), vertices.begin(), vertices.end());
    scene.primitives.push_back(prim);
}

// KHR_materials_volume on faces that bound nothing (core/scene/closed_mesh.hpp): one warning per material of the mesh.
void warnOpenVolumes(LoadContext& ctx, const Mesh& mesh, const std::vector<std::string>& elements) {
    const Scene& scene = *ctx.scene;
    const std::vector<uint8_t> open = openVolumePrimitives(scene, mesh);
    std::vector<uint32_t> warned;
    for (uint32_t k = 0; k < mesh.primitiveCount; ++k) {
        const uint32_t material = scene.primitives[mesh.firstPrimitive + k].material;
        if (!open[k] || std::find(warned.begin(), warned.end(), material) != warned.end()) continue;
        warned.push_back(material);
        const std::string& name = scene.materials[material].name;
        ctx.warn(elements[k], "materials[" + std::to_string(material) + "]" +
                                  (name.empty() ? "" : " ('" + name + "')") +
                                  " has KHR_materials_volume (thicknessFactor > 0), which needs a closed mesh, but "
                                  "this mesh's faces of that material leave edges open; render.pathtrace traces them "
                                  "as thin-walled glass tinted over the thickness, as the rasteriser draws them");
    }
}

} // namespace

void loadMeshes(LoadContext& ctx) {
    const tinygltf::Model& model = *ctx.model;
    for (size_t i = 0; i < model.meshes.size(); ++i) {
        Mesh mesh;
        mesh.name = model.meshes[i].name;
        mesh.firstPrimitive = static_cast<uint32_t>(ctx.scene->primitives.size());
        const Json& primsJson = ctx.doc["meshes"][i]["primitives"];
        // Morph weights: the mesh's `weights`, else zeros, one per target of its first primitive.
        size_t targets = model.meshes[i].primitives.empty() ? 0 : model.meshes[i].primitives[0].targets.size();
        const std::vector<double>& w = model.meshes[i].weights;
        if (!w.empty() && w.size() != targets) {
            ctx.fail("meshes[" + std::to_string(i) + "].weights",
                     std::to_string(w.size()) + " weights; expected " + std::to_string(targets) +
                         " (one per morph target)");
        }
        // extras.vitrine.lightmapChartGap: the gap between its lightmap charts in uv units (vitrine's own export).
        const std::string element = "meshes[" + std::to_string(i) + "]";
        if (const Json* extras = object(ctx, ctx.doc["meshes"][i], "extras", element)) {
            const std::string e = element + ".extras";
            if (const Json* ours = object(ctx, *extras, kExtrasKey, e)) {
                const double gap = number(ctx, *ours, "lightmapChartGap", 0.0, e + "." + kExtrasKey);
                if (!(gap >= 0.0 && gap < 1.0))
                    ctx.fail(e + "." + kExtrasKey + ".lightmapChartGap",
                             "expected a gap in uv units in [0, 1), got " + std::to_string(gap));
                mesh.lightmapChartGap = static_cast<float>(gap);
            }
        }
        mesh.weights.assign(targets, 0.0f);
        for (size_t k = 0; k < w.size(); ++k)
            mesh.weights[k] = static_cast<float>(w[k]);
        std::vector<std::string> elements; // of the primitives loaded (points and lines are skipped)
        for (size_t j = 0; j < model.meshes[i].primitives.size(); ++j) {
            std::string e = "meshes[" + std::to_string(i) + "].primitives[" + std::to_string(j) + "]";
            int indexAccessor = static_cast<int>(integer(ctx, primsJson[j], "indices", -1, e));
            int material = variantMaterial(ctx, primsJson[j], model.meshes[i].primitives[j].material, e);
            const size_t before = ctx.scene->primitives.size();
            loadPrimitive(ctx, model.meshes[i].primitives[j], indexAccessor, mesh.weights, material, e);
            if (ctx.scene->primitives.size() > before) elements.push_back(e);
        }
        mesh.primitiveCount = static_cast<uint32_t>(ctx.scene->primitives.size()) - mesh.firstPrimitive;
        ctx.scene->meshes.push_back(mesh);
        warnOpenVolumes(ctx, ctx.scene->meshes.back(), elements);
    }
}

} // namespace vitrine::scene::gltf
