#pragma once

// Parametric shapes for the museum, written into a MeshBuilder with texture coordinates in metres
// (times a scale) and one lightmap chart per flat face or unrolled surface. Front faces are
// counter-clockwise, normals point out.

#include "core/scene/museum/mesh_builder.hpp"

#include <functional>
#include <span>

namespace vitrine::scene::museum {

// A plane patch: points origin + u·x + v·y; the front normal is cross(u, v). u and v are orthonormal.
struct Frame {
    glm::vec3 origin{0.0f};
    glm::vec3 u{1, 0, 0};
    glm::vec3 v{0, 1, 0};
    glm::vec2 uvOffset{0.0f}; // added to the texture coordinates, in metres

    glm::vec3 normal() const { return glm::cross(u, v); }
    glm::vec3 at(float x, float y) const { return origin + u * x + v * y; }
};

// A hole through a slab, in the front face's (x, y) coordinates.
struct Opening {
    float x0, x1, y0, y1;
};

// Vertex ambient occlusion as a function of the world position (floors darken near walls).
using AoFunction = std::function<float(const glm::vec3&)>;

// The rectangle [0,w] × [0,h] of a frame, split into segX × segY quads. uv0 = (x, -y) · uvScale.
void rect(MeshBuilder& b, const Frame& f, float w, float h, glm::vec2 uvScale, int segX = 1, int segY = 1,
          const AoFunction& ao = {});

// A wall or ceiling slab: the front face in the frame's plane, a back face thickness behind it, and
// openings cut through both with their reveals (jambs, sill, head). back = false leaves out the back,
// reveals = false the reveals (a lining in front of a wall that has them already). The jambs and the head
// reach revealBeyond past the back face: to a lining standing that far in front of it, so that no slot
// between the two shows in the opening (the sill does not: the floor beyond carries on under the lining).
void slab(MeshBuilder& b, const Frame& f, float w, float h, float thickness, std::span<const Opening> openings,
          glm::vec2 uvScale, bool back = true, bool reveals = true, float revealBeyond = 0.0f);

void box(MeshBuilder& b, const glm::vec3& min, const glm::vec3& max, float uvScale);

// Surface of revolution about +Y of a profile of (radius, height) points, bottom to top. Profile corners
// sharper than ~35° keep hard edges.
void lathe(MeshBuilder& b, std::span<const glm::vec2> profile, int segments, glm::vec2 uvScale);

void sphere(MeshBuilder& b, float radius, int rings, int segments, float uvScale);

// A 2D profile (x along the path's side, y along up) swept along a 3D path that turns about up, with
// mitred corners. smooth: normals blend across path vertices (curves), else stay per segment (corners).
void sweep(MeshBuilder& b, std::span<const glm::vec3> path, bool closedPath, const glm::vec3& up,
           std::span<const glm::vec2> profile, bool closedProfile, bool smooth, float uvScale);

// A parametric patch p(s, t) over [0,1]², ns × nt quads, normals by finite differences pointing along
// cross(dp/ds, dp/dt). size: the patch's extent in metres along s and t (texture and chart scale).
void surface(MeshBuilder& b, const std::function<glm::vec3(float, float)>& p, int ns, int nt, glm::vec2 size,
             glm::vec2 uvScale);

// Catmull-Rom resampling of a coarse profile into a smooth one with `samples` points.
std::vector<glm::vec2> smoothProfile(std::span<const glm::vec2> control, int samples);

// Points of a circle (or arc) of radius r about center in the plane spanned by a and b.
std::vector<glm::vec3> arc(const glm::vec3& center, const glm::vec3& a, const glm::vec3& b, float r, float angle0,
                           float angle1, int segments);
std::vector<glm::vec2> circleProfile(float r, int segments);

} // namespace vitrine::scene::museum
