// The museum's reflection probes, placed the way the demo placed its cube maps: every room split into a few
// boxes that follow its walls, every aisle bay of the hall (the alcoves between the columns) a box of its own that
// outranks the hall's, every doorway a small box that outranks both rooms and the bay it opens into. Axis-aligned
// boxes only; priorities 0 (rooms), 1 (bays), 2 (doorways). Each probe's projection box (the parallax proxy) is
// the room it sees: the hall for the nave slices and the bays, the gallery for its quarters, both rooms for a doorway.
//
// Boxes reach kWall past a room's walls, so the reveals of windows and doors and the wall faces themselves lie
// inside; where two boxes of one room meet, each reaches half its fade past the shared plane, so their weights
// cross-fade over one fade width. Capture points sit at eye height at the centre of each box's floor area, away
// from the exhibits (tests/unit/scene/test_museum_probes.cpp checks they are clear of all geometry).

#include "core/scene/museum/context.hpp"

#include <algorithm>
#include <string>
#include <vector>

namespace vitrine::scene::museum {

namespace {

using namespace plan;

constexpr float kEye = 1.7f;        // capture height, metres above the floor
constexpr float kRoomFade = 1.0f;   // between the cells of a room
constexpr float kBayFade = 0.5f;    // aisle bays
constexpr float kDoorFade = 0.3f;   // doorways
constexpr int32_t kBayPriority = 1;  // over the nave (and, inside the wall, the galleries)
constexpr int32_t kDoorPriority = 2; // over both rooms and the aisle bay a doorway opens into

ReflectionProbe box(const std::string& name, glm::vec3 lo, glm::vec3 hi, glm::vec3 capture, float fade,
                    int32_t priority, const Aabb& proxy) {
    ReflectionProbe p;
    p.projectionCenter = proxy.center();
    p.projectionHalfExtents = 0.5f * (proxy.max - proxy.min);
    p.name = name;
    p.position = capture;
    p.shape = ProbeShape::Box;
    p.center = 0.5f * (lo + hi);
    p.halfExtents = 0.5f * (hi - lo);
    p.fade = fade;
    p.priority = priority;
    return p;
}

// The interval [a, b] split into n cells; cell i grown by `outer` at the ends of [a, b] and by `inner` at the
// planes it shares with its neighbours.
glm::vec2 cell(float a, float b, int n, int i, float outer, float inner) {
    float w = (b - a) / n;
    return {a + i * w - (i == 0 ? outer : inner), a + (i + 1) * w + (i == n - 1 ? outer : inner)};
}

// A gallery as 2 × 2 boxes named by compass quarter (south is −z), captured at their centres.
void gallery(Scene& s, const std::string& name, const Aabb& room, float top) {
    const char* quarter[2][2] = {{"sw", "se"}, {"nw", "ne"}}; // [z][x]
    for (int k = 0; k < 2; ++k) {
        for (int i = 0; i < 2; ++i) {
            glm::vec2 x = cell(room.min.x, room.max.x, 2, i, kWall, 0.5f * kRoomFade);
            glm::vec2 z = cell(room.min.z, room.max.z, 2, k, kWall, 0.5f * kRoomFade);
            glm::vec2 cx = cell(room.min.x, room.max.x, 2, i, 0.0f, 0.0f), cz = cell(room.min.z, room.max.z, 2, k, 0.0f, 0.0f);
            glm::vec3 capture(0.5f * (cx.x + cx.y), kEye, 0.5f * (cz.x + cz.y));
            s.probes.push_back(
                box(name + "_" + quarter[k][i], {x.x, -kWall, z.x}, {x.y, top, z.y}, capture, kRoomFade, 0, room));
        }
    }
}

} // namespace

void placeProbes(Scene& s) {
    // Parallax proxies: what each probe sees is its room, so the room is its projection box (the hall for the
    // nave and the bays, the two rooms a doorway joins for it), apart from the smaller volumes they apply in (which
    // reach into the walls' reveals and the skylight wells: ibl.localized starts those points on the box's border).
    const float hallTop = kHallH + 0.7f, galleryTop = kRoomH + 0.6f;
    const Aabb hall{{-kHallX, 0.0f, -kHallZ}, {kHallX, kHallH, kHallZ}};
    const Aabb west{{kWestX0, 0, -kSideZ}, {kWestX1, kRoomH, kSideZ}};
    const Aabb east{{kEastX0, 0, -kSideZ}, {kEastX1, kRoomH, kSideZ}};
    const Aabb north{{-kNorthX, 0, kNorthZ0}, {kNorthX, kRoomH, kNorthZ1}};
    auto join = [](const Aabb& a, const Aabb& b) { return Aabb{glm::min(a.min, b.min), glm::max(a.max, b.max)}; };
    // The nave: eight 4 m slices of the hall between the arcades, up into the skylight wells (0.6 m of roof).
    const int slices = 8;
    const float naveZ = kColumnZ + kWall;
    for (int i = 0; i < slices; ++i) {
        glm::vec2 x = cell(-kHallX, kHallX, slices, i, kWall, 0.5f * kRoomFade);
        float cx = -kHallX + (i + 0.5f) * (2 * kHallX / slices);
        // Off the axis towards the south: the exhibits stand at z = +1 and the robot walks at z ≈ 3.3.
        s.probes.push_back(box("hall_nave_" + std::to_string(i), {x.x, -kWall, -naveZ}, {x.y, hallTop, naveZ},
                               {cx, kEye, -0.5f}, kRoomFade, 0, hall));
    }
    // The aisles: one bay between each pair of columns plus the two short ends, from just inside the arcade's
    // centre plane to the outer wall; they outrank the nave where both apply.
    const float bayInner = kColumnZ - 0.2f, bayOuter = kHallZ + kWall, bayCapture = 5.8f;
    std::vector<float> edges = {-kHallX};
    for (int c = 0; c < kColumns; ++c)
        edges.push_back(kColumnX0 + c * kColumnStep);
    edges.push_back(kHallX);
    for (int side = 0; side < 2; ++side) {
        float sign = side == 0 ? 1.0f : -1.0f;
        std::string prefix = side == 0 ? "hall_aisle_north_" : "hall_aisle_south_";
        for (size_t b = 0; b + 1 < edges.size(); ++b) {
            float x0 = edges[b] - (b == 0 ? kWall : 0.5f * kBayFade);
            float x1 = edges[b + 1] + (b + 2 == edges.size() ? kWall : 0.5f * kBayFade);
            float z0 = sign * bayInner, z1 = sign * bayOuter;
            glm::vec3 capture(0.5f * (edges[b] + edges[b + 1]), kEye, sign * bayCapture);
            s.probes.push_back(box(prefix + std::to_string(b), {x0, -kWall, std::min(z0, z1)},
                                   {x1, kHallH + 0.1f, std::max(z0, z1)}, capture, kBayFade, kBayPriority, hall));
        }
    }
    // Doorways: the hall's wall (kWall) plus the gallery's lining in front of it, and the architraves (0.2 m) around.
    const float depth = kWall + 0.01f, reach = 0.4f, frame = 0.2f, doorTop = kDoorH + 0.3f;
    s.probes.push_back(box("door_west", {-kHallX - depth - reach, -kWall, -kDoorHalf - frame},
                           {-kHallX + reach, doorTop, kDoorHalf + frame}, {-kHallX - 0.5f * depth, kEye, 0.0f},
                           kDoorFade, kDoorPriority, join(hall, west)));
    s.probes.push_back(box("door_east", {kHallX - reach, -kWall, -kDoorHalf - frame},
                           {kHallX + depth + reach, doorTop, kDoorHalf + frame}, {kHallX + 0.5f * depth, kEye, 0.0f},
                           kDoorFade, kDoorPriority, join(hall, east)));
    s.probes.push_back(box("door_north", {-kDoorHalf - frame, -kWall, kHallZ - reach},
                           {kDoorHalf + frame, doorTop, kHallZ + depth + reach}, {0.0f, kEye, kHallZ + 0.5f * depth},
                           kDoorFade, kDoorPriority, join(hall, north)));
    // The galleries: 2 × 2 boxes each, up into the north gallery's skylight well (0.5 m of roof).
    gallery(s, "west_gallery", west, galleryTop);
    gallery(s, "east_gallery", east, galleryTop);
    gallery(s, "north_gallery", north, galleryTop);
}

} // namespace vitrine::scene::museum
