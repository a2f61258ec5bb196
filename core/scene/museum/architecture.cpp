// The building: the hall's shell (floor, walls with windows and doorways, ceiling with skylights, trims)
// and the three side galleries. The arcades live in arcade.cpp.

#include "core/scene/museum/context.hpp"
#include "core/scene/museum/shapes.hpp"

#include <array>
#include <cmath>

namespace vitrine::scene::museum {

void buildArcades(Museum& m); // arcade.cpp

namespace {

using namespace plan;

const glm::vec3 kX(1, 0, 0), kY(0, 1, 0), kZ(0, 0, 1);

// Floors darken towards the walls and the column plinths: a cheap, plausible vertex AO.
AoFunction floorAo(const Aabb& room, bool columns) {
    return [room, columns](const glm::vec3& p) {
        float d = std::min(std::min(p.x - room.min.x, room.max.x - p.x), std::min(p.z - room.min.z, room.max.z - p.z));
        float ao = 1.0f - 0.35f * std::exp(-std::max(d, 0.0f) / 0.45f);
        if (columns) {
            for (int i = 0; i < kColumns; ++i) {
                for (float z : {-kColumnZ, kColumnZ}) {
                    glm::vec2 q = glm::abs(glm::vec2(p.x - (kColumnX0 + i * kColumnStep), p.z - z)) - glm::vec2(0.45f);
                    float dist = glm::length(glm::max(q, glm::vec2(0.0f)));
                    ao *= 1.0f - 0.4f * std::exp(-dist / 0.3f);
                }
            }
        }
        return ao;
    };
}

// A floor covering [x0, x1] × [z0, z1] at height y, facing up, with texture coordinates from the world.
void floorRect(MeshBuilder& b, const Aabb& room, float y, float uvScale, const AoFunction& ao) {
    glm::vec3 lo = room.min, hi = room.max;
    Frame f{{lo.x, y, hi.z}, kX, -kZ, {lo.x, hi.z}};
    int sx = std::max(1, int((hi.x - lo.x) / 0.5f)), sz = std::max(1, int((hi.z - lo.z) / 0.5f));
    rect(b, f, hi.x - lo.x, hi.z - lo.z, glm::vec2(uvScale, -uvScale), sx, sz, ao);
}

// One wall of a room, described from inside: its interior face starts at a and runs along u (horizontal)
// for w metres; the room is on the side of cross(u, +y).
struct Wall {
    glm::vec3 a;
    glm::vec3 u;
    float w;

    Frame frame() const { return Frame{a, u, kY, {glm::dot(a, u), 0.0f}}; }
    // The point of the wall's face at floor level straight across from p.
    glm::vec3 facing(const glm::vec3& p) const {
        glm::vec3 n = glm::cross(u, kY);
        glm::vec3 q = p - n * glm::dot(p - a, n);
        return glm::vec3(q.x, 0.0f, q.z);
    }
    // An opening centred on the world point c (along the wall), width ow, from y0 to y1.
    Opening opening(const glm::vec3& c, float ow, float y0, float y1) const {
        float x = glm::dot(c - a, u);
        return {x - 0.5f * ow, x + 0.5f * ow, y0, y1};
    }
};

// The four walls of a room box, counter-clockwise from the south (z-min) side, extended by the wall
// thickness at both ends so that corners close.
std::array<Wall, 4> roomWalls(const Aabb& r, float t) {
    glm::vec3 lo = r.min, hi = r.max;
    float wx = hi.x - lo.x + 2 * t, wz = hi.z - lo.z + 2 * t;
    return {Wall{{lo.x - t, 0, lo.z}, kX, wx}, Wall{{hi.x, 0, lo.z - t}, kZ, wz}, Wall{{hi.x + t, 0, hi.z}, -kX, wx},
            Wall{{lo.x, 0, hi.z + t}, -kZ, wz}};
}

// A moulded frame around a doorway on a wall face (dark marble), outside the opening.
void architrave(MeshBuilder& b, const Frame& f, const Opening& o) {
    const glm::vec2 profile[] = {{0.0f, 0.0f},    {0.0f, 0.03f},  {-0.02f, 0.05f},
                                 {-0.15f, 0.06f}, {-0.2f, 0.04f}, {-0.2f, 0.0f}};
    const glm::vec3 path[] = {f.at(o.x0, o.y0), f.at(o.x0, o.y1), f.at(o.x1, o.y1), f.at(o.x1, o.y0)};
    sweep(b, path, false, f.normal(), profile, false, false, 1.0f);
}

// Skirting along a wall face, broken where openings reach the floor.
void baseboard(MeshBuilder& b, const Wall& wall, std::span<const Opening> openings, float inset) {
    std::vector<std::pair<float, float>> runs = {{inset, wall.w - inset}};
    for (const Opening& o : openings) {
        if (o.y0 > 0.01f) continue;
        std::vector<std::pair<float, float>> next;
        for (auto [s, e] : runs) {
            float cut0 = o.x0 - 0.2f, cut1 = o.x1 + 0.2f; // the architrave takes over
            if (cut0 > s) next.emplace_back(s, std::min(e, cut0));
            if (cut1 < e) next.emplace_back(std::max(s, cut1), e);
        }
        runs = next;
    }
    glm::vec3 n = glm::cross(wall.u, kY);
    for (auto [s, e] : runs) {
        if (e - s < 0.05f) continue;
        glm::vec3 p0 = wall.a + wall.u * s, p1 = wall.a + wall.u * e + n * 0.03f + kY * 0.2f;
        box(b, glm::min(p0, p1), glm::max(p0, p1), 1.0f);
    }
}

// A cornice moulding around the ceiling of a room (counter-clockwise from above, so it faces inwards).
void cornice(MeshBuilder& b, const Aabb& r, float y) {
    const glm::vec3 path[] = {
        {r.min.x, y, r.min.z}, {r.max.x, y, r.min.z}, {r.max.x, y, r.max.z}, {r.min.x, y, r.max.z}};
    const glm::vec2 profile[] = {{0.0f, -0.42f}, {0.05f, -0.40f}, {0.07f, -0.32f}, {0.12f, -0.3f},
                                 {0.2f, -0.2f},  {0.28f, -0.08f}, {0.32f, -0.05f}, {0.34f, 0.0f}};
    sweep(b, path, true, kY, profile, false, false, 1.0f);
}

// A marble sill under a window, projecting into the room.
void sill(MeshBuilder& b, const Wall& wall, const Opening& o) {
    glm::vec3 n = glm::cross(wall.u, kY);
    box(b, wall.a + wall.u * (o.x0 - 0.1f) + kY * (o.y0 - 0.08f),
        wall.a + wall.u * (o.x1 + 0.1f) + kY * o.y0 + n * 0.12f, 1.0f);
}

// Mullions and transoms in a window opening of a wall, at mid-depth.
void windowBars(MeshBuilder& b, const Wall& wall, const Opening& o, float thickness) {
    glm::vec3 n = glm::cross(wall.u, kY);
    glm::vec3 mid = wall.a - n * (0.5f * thickness);
    auto bar = [&](float x0, float x1, float y0, float y1) {
        glm::vec3 p0 = mid + wall.u * x0 + kY * y0 - n * 0.04f, p1 = mid + wall.u * x1 + kY * y1 + n * 0.04f;
        box(b, glm::min(p0, p1), glm::max(p0, p1), 1.0f);
    };
    float w = o.x1 - o.x0;
    for (float f : {1.0f / 3.0f, 2.0f / 3.0f})
        bar(o.x0 + f * w - 0.025f, o.x0 + f * w + 0.025f, o.y0, o.y1);
    for (float y = o.y0 + 0.9f; y < o.y1 - 0.3f; y += 0.9f)
        bar(o.x0, o.x1, y - 0.025f, y + 0.025f);
}

// Vertical fins across a skylight well: the sun comes through in stripes.
void louvres(MeshBuilder& b, float x0, float x1, float z0, float z1, float y) {
    for (float z = z0 + 0.15f; z < z1 - 0.05f; z += 0.35f)
        box(b, {x0, y + 0.2f, z - 0.012f}, {x1, y + 0.4f, z + 0.012f}, 1.0f);
}

void buildHall(Museum& m) {
    const Aabb room{{-kHallX, 0, -kHallZ}, {kHallX, kHallH, kHallZ}};
    const float t = kWall;
    MeshBuilder shell("hall_shell"), metal("hall_metalwork");
    shell.material(m.mat.floorMarble);
    floorRect(shell, room, 0.0f, 1.0f / 1.5f, floorAo(room, true));

    std::array<Wall, 4> walls = roomWalls(room, t);
    std::array<std::vector<Opening>, 4> openings;
    for (int k = 0; k < 7; ++k) {
        openings[0].push_back(walls[0].opening({-12.0f + 4.0f * k, 0, -kHallZ}, 2.0f, 2.0f, 6.5f));
    }
    openings[1].push_back(walls[1].opening({kHallX, 0, 0}, 2 * kDoorHalf, 0.0f, kDoorH));
    openings[2].push_back(walls[2].opening({0, 0, kHallZ}, 2 * kDoorHalf, 0.0f, kDoorH));
    openings[3].push_back(walls[3].opening({-kHallX, 0, 0}, 2 * kDoorHalf, 0.0f, kDoorH));
    shell.material(m.mat.hallStone);
    // Walls 1-3 open into a gallery whose lining stands kLiningGap in front of them (buildGallery): their doorways'
    // reveals reach it. (Without, the camera saw the hall's wall down that 1-cm slot, whose texels the bake finds
    // inside geometry, as a black line beside every doorway.)
    for (int i = 0; i < 4; ++i)
        slab(shell, walls[i].frame(), walls[i].w, kHallH + 0.6f, t, openings[i], glm::vec2(1.0f), true, true,
             i == 0 ? 0.0f : kLiningGap);

    // Ceiling and roof, with four skylight wells.
    shell.material(m.mat.ceiling);
    std::vector<Opening> skylights;
    for (float x : {-10.0f, -3.5f, 3.5f, 10.0f})
        skylights.push_back({x + kHallX - 1.5f, x + kHallX + 1.5f, 3.2f, 5.2f});
    slab(shell, Frame{{-kHallX, kHallH, -kHallZ}, kX, kZ}, 2 * kHallX, 2 * kHallZ, 0.6f, skylights, glm::vec2(0.5f));
    cornice(shell, room, kHallH);

    shell.material(m.mat.darkMarble);
    for (int i = 0; i < 4; ++i) {
        baseboard(shell, walls[i], openings[i], t);
        for (const Opening& o : openings[i]) {
            if (o.y0 == 0.0f) {
                architrave(shell, walls[i].frame(), o);
            } else {
                sill(shell, walls[i], o);
            }
        }
    }
    metal.material(m.mat.bronze);
    for (const Opening& o : openings[0])
        windowBars(metal, walls[0], o, t);
    for (const Opening& o : skylights)
        louvres(metal, o.x0 - kHallX, o.x1 - kHallX, o.y0 - kHallZ, o.y1 - kHallZ, kHallH);
    m.place(shell, "hall_shell");
    m.place(metal, "hall_metalwork");
}

enum class Side { Exterior, Lining };

struct GallerySpec {
    const char* name;
    Aabb room;
    uint32_t wallMaterial;
    uint32_t floorMaterial;
    Side sides[4];  // south, east, north, west
    int windowSide; // -1: none
    bool skylight;
};

void buildGallery(Museum& m, const GallerySpec& g) {
    const float t = kWall;
    MeshBuilder shell(std::string(g.name) + "_shell"), metal(std::string(g.name) + "_metalwork");
    shell.material(g.floorMaterial);
    floorRect(shell, g.room, 0.0f, g.floorMaterial == m.mat.floorMarble ? 1.0f / 1.5f : 1.0f, floorAo(g.room, false));
    std::array<Wall, 4> walls = roomWalls(g.room, t);
    glm::vec3 center = g.room.center();
    shell.material(g.wallMaterial);
    for (int i = 0; i < 4; ++i) {
        std::vector<Opening> openings;
        if (g.sides[i] == Side::Lining) {
            // In front of the hall's wall, which has the reveals already: a face with a doorway only.
            Wall lining = walls[i];
            glm::vec3 n = glm::cross(lining.u, kY);
            lining.a += lining.u * t + n * kLiningGap;
            lining.w -= 2 * t;
            openings.push_back(lining.opening(lining.facing(center), 2 * kDoorHalf, 0.0f, kDoorH));
            slab(shell, lining.frame(), lining.w, kRoomH + 0.01f, t, openings, glm::vec2(1.0f), false, false);
            shell.material(m.mat.darkMarble);
            architrave(shell, lining.frame(), openings[0]);
            baseboard(shell, lining, openings, 0.0f);
            shell.material(g.wallMaterial);
            continue;
        }
        if (i == g.windowSide) {
            openings.push_back(walls[i].opening(walls[i].facing(center), 2.4f, 1.2f, 4.2f));
            metal.material(m.mat.bronze);
            windowBars(metal, walls[i], openings[0], t);
        }
        slab(shell, walls[i].frame(), walls[i].w, kRoomH + 0.5f, t, openings, glm::vec2(1.0f));
        shell.material(m.mat.darkMarble);
        baseboard(shell, walls[i], openings, t);
        for (const Opening& o : openings)
            sill(shell, walls[i], o);
        shell.material(g.wallMaterial);
    }
    shell.material(m.mat.ceiling);
    glm::vec3 lo = g.room.min, hi = g.room.max;
    std::vector<Opening> skylights;
    if (g.skylight) {
        skylights.push_back({center.x - lo.x - 2.0f, center.x - lo.x + 2.0f, 2.1f, 4.1f});
        metal.material(m.mat.bronze);
        louvres(metal, center.x - 2.0f, center.x + 2.0f, lo.z + 2.1f, lo.z + 4.1f, hi.y);
    }
    slab(shell, Frame{{lo.x, hi.y, lo.z}, kX, kZ}, hi.x - lo.x, hi.z - lo.z, 0.5f, skylights, glm::vec2(0.5f));
    cornice(shell, g.room, hi.y);
    m.place(shell, std::string(g.name) + "_shell");
    if (!metal.empty()) m.place(metal, std::string(g.name) + "_metalwork");
}

} // namespace

void buildArchitecture(Museum& m) {
    buildHall(m);
    buildArcades(m);
    const Materials& mat = m.mat;
    buildGallery(m, {"west_gallery",
                     Aabb{{kWestX0, 0, -kSideZ}, {kWestX1, kRoomH, kSideZ}},
                     mat.plasterWhite,
                     mat.woodFloor,
                     {Side::Exterior, Side::Lining, Side::Exterior, Side::Exterior},
                     0,
                     false});
    buildGallery(m, {"east_gallery",
                     Aabb{{kEastX0, 0, -kSideZ}, {kEastX1, kRoomH, kSideZ}},
                     mat.plasterWhite,
                     mat.woodFloor,
                     {Side::Exterior, Side::Exterior, Side::Exterior, Side::Lining},
                     0,
                     false});
    buildGallery(m, {"north_gallery",
                     Aabb{{-kNorthX, 0, kNorthZ0}, {kNorthX, kRoomH, kNorthZ1}},
                     mat.plasterRed,
                     mat.floorMarble,
                     {Side::Lining, Side::Exterior, Side::Exterior, Side::Exterior},
                     -1,
                     true});
}

} // namespace vitrine::scene::museum
