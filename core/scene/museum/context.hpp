#pragma once

// What the parts of the museum builder share: the scene under construction, its textures and
// materials, the random stream, and the floor plan (metres, +Y up, hall centred on the origin).

#include "core/scene/museum/mesh_builder.hpp"
#include "core/scene/museum/noise.hpp"
#include "core/scene/museum/textures.hpp"

#include <string>

namespace vitrine::scene::museum {

namespace plan {
constexpr float kWall = 0.4f; // wall thickness
// A gallery's lining stands this far in front of the hall's wall (no shared plane to fight over); the hall's
// doorways' jambs and heads reach across the gap to it.
constexpr float kLiningGap = 0.01f;
// Interior of the hall: x ∈ [-kHallX, kHallX], z ∈ [-kHallZ, kHallZ], y ∈ [0, kHallH].
constexpr float kHallX = 16.0f, kHallZ = 7.0f, kHallH = 9.0f;
constexpr float kRoomH = 5.5f;   // side galleries' ceiling
constexpr float kColumnZ = 4.6f; // the two arcades
constexpr float kColumnX0 = -14.0f, kColumnStep = 4.0f;
constexpr int kColumns = 8;
constexpr float kSpring = 6.0f; // top of the capitals, where the arches spring
constexpr float kDoorHalf = 1.5f, kDoorH = 3.8f;
// Side galleries (interiors).
constexpr float kWestX0 = -28.4f, kWestX1 = -16.4f, kEastX0 = 16.4f, kEastX1 = 28.4f, kSideZ = 6.0f;
constexpr float kNorthX = 7.0f, kNorthZ0 = 7.4f, kNorthZ1 = 17.4f;
} // namespace plan

struct Materials {
    uint32_t floorMarble, woodFloor, hallStone, plasterWhite, plasterRed, ceiling, columnMarble, darkMarble;
    uint32_t gilded, chrome, brushedSteel, dirtyGold, roughStone, velvet, lacqueredWood, engravedSilver;
    uint32_t brass, bronze, walnut, robotWhite, robotDark, robotEye;
    uint32_t paintings[4];
    uint32_t glass;
};

struct Museum {
    Scene& scene;
    MuseumTextures tex;
    Materials mat{};
    Rng rng;
    uint32_t root = 0; // the node every part hangs under

    // Commits b as a mesh and adds a node for it under parent (the root by default). Returns the node.
    uint32_t place(MeshBuilder& b, const std::string& name, const Transform& local = {}, bool lightmapped = true,
                   int32_t parent = -1);
    uint32_t addNode(const std::string& name, const Transform& local, int32_t parent = -1);
};

// The parts, in the order buildMuseum() calls them.
void buildArchitecture(Museum& m);
void buildExhibits(Museum& m);
void buildDecor(Museum& m); // paintings, frames, benches, stanchions
void buildRobot(Museum& m);
void placeProbes(Scene& scene); // probes.cpp: reflection probes per room, aisle bay and doorway

} // namespace vitrine::scene::museum
