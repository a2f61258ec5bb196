// The ray-tracing acceleration structure (core/accel/), shared by C++ and GLSL: the flattened bottom
// levels (nodes, triangles, where each triangle came from) and the per-frame top level. Every struct is
// made of 16-byte members or of four 32-bit scalars, so std430 and C++ agree without padding rules.
//
// Two levels: entry 0 of the top level is the static level, every static instance pre-transformed into
// one world-space bottom level; each further entry is a dynamic (animated) or deforming instance: an object-space
// bottom level of its mesh (a deforming mesh's refit to this frame's vertices) and this frame's world-to-object
// transform. Traversal: shaders/accel/bvh.glsl.
#ifndef ACCEL_BVH_H
#define ACCEL_BVH_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

// Traversal keeps one stack entry per level; the builder keeps every tree at most this deep.
#define VITRINE_BVH_STACK_SIZE 64
// "No node / triangle / instance": an empty child link, a miss, a triangle whose instance the top level knows.
#define VITRINE_BVH_NONE 0xffffffffu

// A node of a binary BVH. It holds the boxes of both children, so one 64-byte fetch lets traversal test
// both and visit the nearer first. A child is a leaf when its count is non-zero (link: its first
// triangle), an inner node when the count is 0 (link: the node's index), and absent when the link is
// VITRINE_BVH_NONE (only the root of a bottom level that is a single leaf, or empty, has one).
// The links and counts are stored in the w components as uint bits (floatBitsToUint).
struct GpuBvhNode {
    vec4 aMin; // xyz: child A's box; w: child A's link
    vec4 aMax; // xyz; w: child A's triangle count
    vec4 bMin; // child B, the same
    vec4 bMax;
};

// A triangle as traversal reads it, in leaf order: world space in the static level, object space in a
// dynamic mesh's bottom level. w: 0.
struct GpuBvhTriangle {
    vec4 v0;
    vec4 v1;
    vec4 v2;
};

// Where a BVH triangle came from; parallel to the triangle array.
struct GpuBvhTriangleRef {
    uint instance;  // scene instance (Scene::instances); VITRINE_BVH_NONE in a dynamic bottom level, whose
                    // instance is the top-level entry's (one mesh's bottom level serves all its instances)
    uint primitive; // Scene::primitives and GpuBvhPrimitive
    uint triangle;  // within the primitive: its vertex k is index firstIndex + 3 * triangle + k
    uint material;  // the primitive's material (Scene::materials, the scene's material buffer)
};

// A scene primitive, so a tracer can fetch a hit's vertex attributes from the scene's vertex and index
// buffers: vertex k of triangle t = vertices[indices[firstIndex + 3t + k] + vertexOffset].
struct GpuBvhPrimitive {
    uint firstIndex;
    uint indexCount;
    uint vertexOffset;
    uint flags; // VITRINE_BVH_PRIMITIVE_* bits
};

// GpuBvhPrimitive::flags: its material bounds a KHR_materials_volume but its mesh's faces of that material are not
// closed (core/scene/closed_mesh.hpp), so the tracers take it for thin-walled glass, as the rasteriser draws it.
#define VITRINE_BVH_PRIMITIVE_OPEN_VOLUME 1u

// One entry of the top level, written every frame (GpuBvh::update).
struct GpuBvhInstance {
    vec4 worldToObject0; // rows of the inverse of the instance's world matrix (affine); identity for the static level
    vec4 worldToObject1;
    vec4 worldToObject2;
    vec4 boundsMin; // xyz: the instance's box in world space at this frame (slightly padded)
    vec4 boundsMax;
    uvec4 info; // x: root node of its bottom level, y: scene instance (VITRINE_BVH_NONE for the static
                // level: the triangle's GpuBvhTriangleRef knows), z, w: 0
};

#ifdef __cplusplus
static_assert(sizeof(GpuBvhNode) == 64);
static_assert(sizeof(GpuBvhTriangle) == 48);
static_assert(sizeof(GpuBvhTriangleRef) == 16);
static_assert(sizeof(GpuBvhPrimitive) == 16);
static_assert(sizeof(GpuBvhInstance) == 96);
}
#endif
#endif
