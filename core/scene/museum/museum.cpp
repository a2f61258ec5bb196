// buildMuseum(): materials, lenses, camera paths, the sun and rooms; the geometry comes from the parts
// in architecture.cpp, exhibits.cpp, decor.cpp and robot.cpp, the reflection probes from probes.cpp.

#include "core/scene/museum.hpp"

#include "core/scene/museum/context.hpp"
#include "core/scene/museum/geometry_store.hpp"

#include "core/base/error.hpp"
#include "core/scene/hash.hpp"
#include "core/shading/sky.hpp"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>

namespace vitrine::scene {

namespace museum {

uint32_t Museum::addNode(const std::string& name, const Transform& local, int32_t parent) {
    uint32_t index = static_cast<uint32_t>(scene.nodes.size());
    Node node;
    node.name = name;
    node.local = local;
    scene.nodes.push_back(node);
    scene.nodes[parent < 0 ? root : static_cast<uint32_t>(parent)].children.push_back(index);
    return index;
}

uint32_t Museum::place(MeshBuilder& b, const std::string& name, const Transform& local, bool lightmapped,
                       int32_t parent) {
    uint32_t mesh = b.commit(scene, lightmapped);
    uint32_t node = addNode(name, local, parent);
    scene.nodes[node].mesh = static_cast<int32_t>(mesh);
    return node;
}

namespace {

TextureRef ref(int32_t texture, glm::vec2 scale = glm::vec2(1.0f), glm::vec2 offset = glm::vec2(0.0f),
               float rotation = 0.0f) {
    TextureRef r;
    r.texture = texture;
    r.transform = {offset, scale, rotation};
    return r;
}

ScalarParam constant(float v) {
    return ScalarParam{v, 0.0f};
}

ScalarParam fromTexture(float factor, float atZero, int32_t texture, uint32_t channel,
                        glm::vec2 scale = glm::vec2(1.0f)) {
    return ScalarParam{factor, atZero, ref(texture, scale), channel};
}

MaterialLayer plain(const char* name, glm::vec3 albedo, float shininess, float metallic) {
    MaterialLayer l;
    l.name = name;
    l.albedo.factor = glm::vec4(albedo, 1.0f);
    l.shininess = constant(shininess);
    l.metallic = constant(metallic);
    return l;
}

uint32_t add(Scene& scene, const char* name, std::vector<MaterialLayer> layers) {
    Material m;
    m.name = name;
    m.layers = std::move(layers);
    scene.materials.push_back(m);
    return static_cast<uint32_t>(scene.materials.size() - 1);
}

Materials makeMaterials(Scene& scene, const MuseumTextures& t) {
    Materials m{};
    {
        MaterialLayer white = plain("white marble", glm::vec3(1.0f), 1.0f, 0.0f);
        white.albedo.texture = ref(t.marbleAlbedo);
        white.normal.texture = ref(t.marbleNormal);
        white.shininess = fromTexture(1.0f, 0.0f, t.marbleData, 0);
        white.cavity = fromTexture(1.0f, 0.0f, t.marbleData, 2);
        // The dark tiles: the same veins turned 90° and darkened, laid where the chequer mask says.
        MaterialLayer dark = plain("dark inlay", glm::vec3(0.075f, 0.075f, 0.085f), 0.95f, 0.0f);
        dark.albedo.texture = ref(t.marbleAlbedo, glm::vec2(1.0f), glm::vec2(0.0f), glm::half_pi<float>());
        dark.overrides = kLayerAlbedo | kLayerShininess;
        dark.mask = LayerMask{1.0f, ref(t.marbleData), 1};
        m.floorMarble = add(scene, "floor_marble", {white, dark});
    }
    {
        MaterialLayer wood = plain("walnut parquet", glm::vec3(1.1f), 0.75f, 0.0f);
        wood.albedo.texture = ref(t.woodAlbedo, glm::vec2(0.5f, 3.0f));
        wood.normal.texture = ref(t.woodNormal, glm::vec2(0.5f, 3.0f));
        wood.shininess = fromTexture(0.75f, 0.4f, t.woodData, 0, glm::vec2(0.5f, 3.0f));
        wood.cavity = fromTexture(1.0f, 0.0f, t.woodData, 2, glm::vec2(0.5f, 3.0f));
        m.woodFloor = add(scene, "floor_walnut", {wood});
    }
    {
        MaterialLayer stone = plain("limestone", glm::vec3(1.2f, 1.17f, 1.1f), 1.0f, 0.0f);
        stone.albedo.texture = ref(t.stoneAlbedo);
        stone.normal.texture = ref(t.stoneNormal);
        stone.shininess = fromTexture(1.0f, 0.0f, t.stoneData, 0);
        stone.cavity = fromTexture(1.0f, 0.0f, t.stoneData, 2);
        // Ashlar joints: the joint mask is laid out for 2.4 × 1.2 m of wall, independent of the stone.
        MaterialLayer mortar = plain("mortar", glm::vec3(0.42f, 0.40f, 0.36f), 0.08f, 0.0f);
        mortar.cavity = constant(0.55f);
        mortar.overrides = kLayerAlbedo | kLayerNormal | kLayerShininess | kLayerCavity;
        mortar.mask = LayerMask{1.0f, ref(t.stoneData, glm::vec2(1.0f / 2.4f, 1.0f / 1.2f)), 1};
        m.hallStone = add(scene, "wall_limestone", {stone, mortar});
    }
    auto plaster = [&](const char* name, glm::vec3 color, float shininess) {
        MaterialLayer l = plain(name, color, shininess, 0.0f);
        l.normal.texture = ref(t.plasterNormal, glm::vec2(0.5f));
        return add(scene, name, {l});
    };
    m.plasterWhite = plaster("plaster_white", glm::vec3(0.74f, 0.72f, 0.68f), 0.22f);
    m.plasterRed = plaster("plaster_red", glm::vec3(0.30f, 0.040f, 0.035f), 0.25f);
    m.ceiling = plaster("ceiling", glm::vec3(0.80f, 0.79f, 0.76f), 0.12f);
    {
        MaterialLayer l = plain("column marble", glm::vec3(1.05f), 0.8f, 0.0f);
        l.albedo.texture = ref(t.marbleAlbedo, glm::vec2(0.7f, 0.2f));
        m.columnMarble = add(scene, "column_marble", {l});
        MaterialLayer d = plain("dark marble", glm::vec3(0.09f, 0.09f, 0.1f), 0.85f, 0.0f);
        d.albedo.texture = ref(t.marbleAlbedo, glm::vec2(1.0f), glm::vec2(0.3f, 0.1f), 0.5f);
        m.darkMarble = add(scene, "trim_dark_marble", {d});
    }
    {
        MaterialLayer leaf = plain("gold leaf", glm::vec3(1.0f, 0.78f, 0.40f), 0.7f, 1.0f);
        leaf.normal.texture = ref(t.plasterNormal, glm::vec2(2.0f));
        leaf.normal.scale = 0.5f;
        MaterialLayer grime = plain("grime", glm::vec3(0.12f, 0.10f, 0.08f), 0.2f, 0.0f);
        grime.overrides = kLayerAlbedo | kLayerShininess | kLayerMetallic;
        grime.mask = LayerMask{0.6f, ref(t.dirt, glm::vec2(3.0f)), 0};
        m.gilded = add(scene, "gilded_frame", {leaf, grime});
    }
    m.chrome = add(scene, "chrome", {plain("chrome", glm::vec3(0.96f, 0.96f, 0.97f), 0.985f, 1.0f)});
    {
        MaterialLayer l = plain("brushed steel", glm::vec3(0.88f, 0.88f, 0.86f), 0.72f, 1.0f);
        l.normal.texture = ref(t.brushedNormal);
        m.brushedSteel = add(scene, "brushed_steel", {l});
    }
    {
        MaterialLayer gold = plain("gold", glm::vec3(1.0f, 0.766f, 0.336f), 0.88f, 1.0f);
        MaterialLayer dirt = plain("dirt", glm::vec3(0.16f, 0.13f, 0.09f), 0.18f, 0.0f);
        dirt.cavity = fromTexture(1.0f, 0.4f, t.dirt, 2, glm::vec2(2.0f));
        dirt.overrides = kLayerAlbedo | kLayerShininess | kLayerMetallic | kLayerCavity;
        dirt.mask = LayerMask{1.0f, ref(t.dirt, glm::vec2(2.0f)), 0};
        m.dirtyGold = add(scene, "dirty_gold", {gold, dirt});
    }
    {
        MaterialLayer l = plain("sandstone", glm::vec3(1.0f), 1.0f, 0.0f);
        l.albedo.texture = ref(t.stoneAlbedo, glm::vec2(2.0f));
        l.normal.texture = ref(t.stoneNormal, glm::vec2(2.0f));
        l.normal.scale = 1.5f;
        l.shininess = fromTexture(0.8f, 0.0f, t.stoneData, 0, glm::vec2(2.0f));
        l.cavity = fromTexture(1.0f, 0.0f, t.stoneData, 2, glm::vec2(2.0f));
        m.roughStone = add(scene, "rough_stone", {l});
    }
    {
        MaterialLayer l = plain("velvet", glm::vec3(1.0f), 0.3f, 0.0f);
        l.albedo.texture = ref(t.clothAlbedo, glm::vec2(4.0f));
        l.normal.texture = ref(t.clothNormal, glm::vec2(4.0f));
        m.velvet = add(scene, "velvet", {l});
        scene.materials.back().doubleSided = true; // a single sheet seen from both sides
    }
    {
        MaterialLayer wood = plain("walnut", glm::vec3(1.0f), 0.4f, 0.0f);
        wood.albedo.texture = ref(t.woodAlbedo);
        wood.normal.texture = ref(t.woodNormal);
        wood.cavity = fromTexture(1.0f, 0.0f, t.woodData, 2);
        MaterialLayer lacquer = plain("lacquer", glm::vec3(1.0f), 0.93f, 0.0f);
        lacquer.overrides = kLayerShininess | kLayerNormal; // a clear coat: colour shows through
        lacquer.mask = LayerMask{1.0f, ref(t.woodData), 0};
        m.lacqueredWood = add(scene, "lacquered_wood", {wood, lacquer});
        MaterialLayer bench = wood;
        bench.shininess = constant(0.55f);
        m.walnut = add(scene, "walnut", {bench});
    }
    {
        MaterialLayer l = plain("engraved silver", glm::vec3(0.97f, 0.96f, 0.92f), 0.9f, 1.0f);
        l.normal.texture = ref(t.fineNormal);
        m.engravedSilver = add(scene, "engraved_silver", {l});
    }
    m.brass = add(scene, "brass", {plain("brass", glm::vec3(0.91f, 0.74f, 0.42f), 0.82f, 1.0f)});
    m.bronze = add(scene, "bronze", {plain("bronze", glm::vec3(0.25f, 0.18f, 0.12f), 0.55f, 0.9f)});
    m.robotWhite = add(scene, "robot_white", {plain("paint", glm::vec3(0.82f, 0.82f, 0.80f), 0.75f, 0.0f)});
    m.robotDark = add(scene, "robot_dark", {plain("joints", glm::vec3(0.04f, 0.04f, 0.045f), 0.55f, 0.6f)});
    m.robotEye = add(scene, "robot_visor", {plain("visor", glm::vec3(0.02f), 0.9f, 0.0f)});
    scene.materials.back().emissiveFactor = glm::vec3(0.2f, 0.8f, 1.0f);
    scene.materials.back().emissiveStrength = 40.0f;
    for (int q = 0; q < 4; ++q) {
        MaterialLayer l = plain("oil on canvas", glm::vec3(1.0f), 0.35f, 0.0f);
        l.albedo.texture = ref(t.paintings, glm::vec2(0.5f), glm::vec2(0.5f * (q & 1), 0.5f * (q >> 1)));
        l.normal.texture = ref(t.clothNormal, glm::vec2(6.0f));
        l.normal.scale = 0.3f;
        std::string name = "painting_" + std::to_string(q);
        m.paintings[q] = add(scene, name.c_str(), {l});
    }
    // Vitrine glass: thin, clear with a faint green edge tint (KHR_materials_transmission, IOR 1.5), seen from both
    // sides; drawn by forward.transparent, left out of the G-buffer, the shadow map and the ray-tracing BVH.
    m.glass = add(scene, "vitrine_glass", {plain("glass", glm::vec3(0.93f, 0.97f, 0.95f), 0.97f, 0.0f)});
    scene.materials.back().transmission = 1.0f;
    scene.materials.back().doubleSided = true;
    return m;
}

glm::quat lookAt(const glm::vec3& eye, const glm::vec3& target) {
    glm::vec3 back = glm::normalize(eye - target);
    glm::vec3 right = glm::normalize(glm::cross(glm::vec3(0, 1, 0), back));
    glm::vec3 up = glm::cross(back, right);
    return glm::normalize(glm::quat_cast(glm::mat3(right, up, back)));
}

CameraKey key(float time, glm::vec3 eye, glm::vec3 target, float yfov) {
    return {time, eye, lookAt(eye, target), yfov};
}

void addCameras(Scene& scene) {
    Camera walk;
    walk.name = "walkthrough";
    walk.yfov = 0.9f; // ~25 mm on full frame
    walk.fNumber = 4.0f;
    walk.focusDistance = 4.0f;
    Camera dolly;
    dolly.name = "dolly";
    dolly.yfov = 0.45f; // ~52 mm, shallow depth of field on the sphere
    dolly.fNumber = 1.8f;
    dolly.focusDistance = 2.8f;
    Camera still;
    still.name = "static";
    still.yfov = 0.75f;
    still.fNumber = 5.6f;
    still.focusDistance = 10.0f;
    scene.cameras = {walk, dolly, still};

    const float eye = 1.62f, fov = 0.9f;
    CameraPath w;
    w.name = "walkthrough";
    w.camera = 0;
    w.keys = {key(0, {-19.2f, eye, 2.6f}, {-22.4f, 1.45f, 0.0f}, fov),
              key(5, {-18.8f, eye, -0.6f}, {-10.0f, 1.8f, 0.0f}, fov),
              key(10, {-13.0f, eye, 0.0f}, {-6.0f, 1.3f, 1.0f}, fov),
              key(15, {-5.0f, eye, -1.8f}, {0.0f, 1.45f, 1.0f}, fov),
              key(20, {3.0f, eye, -2.2f}, {6.0f, 1.3f, 1.0f}, fov),
              key(25, {0.0f, eye, 6.0f}, {0.0f, 2.0f, 12.0f}, fov),
              key(30, {0.0f, eye, 9.5f}, {0.0f, 2.3f, 17.4f}, fov),
              key(35, {-4.0f, eye, 12.5f}, {-7.0f, 2.1f, 12.5f}, fov),
              key(40, {2.0f, eye, 14.0f}, {7.0f, 2.1f, 12.0f}, fov),
              key(45, {0.0f, eye, 8.5f}, {0.0f, 3.0f, 0.0f}, fov),
              key(48, {1.5f, eye, 4.0f}, {10.0f, 2.0f, -3.0f}, fov),
              key(52, {10.0f, eye, -2.5f}, {16.4f, 1.8f, 0.0f}, fov),
              key(55, {16.2f, eye, -0.5f}, {22.4f, 1.2f, -2.0f}, fov),
              key(58, {20.0f, eye, 0.0f}, {22.4f, 1.1f, -2.0f}, fov),
              key(63, {24.5f, eye, 3.8f}, {22.4f, 1.3f, 2.0f}, fov)};
    CameraPath d;
    d.name = "dolly";
    d.camera = 1;
    d.smooth = false;
    const glm::vec3 sphere(0.0f, 1.49f, 1.0f);
    for (int i = 0; i <= 4; ++i) {
        float x = -2.2f + 1.1f * i;
        d.keys.push_back(key(2.5f * i, {x, 1.35f, -1.2f}, sphere, 0.45f));
    }
    CameraPath s;
    s.name = "static";
    s.camera = 2;
    s.keys = {key(0, {-15.2f, 1.7f, -1.6f}, {6.0f, 2.6f, 1.5f}, 0.75f)};
    scene.cameraPaths = {w, d, s};
}

void addRooms(Scene& scene) {
    using namespace plan;
    scene.rooms = {{"hall", Aabb{{-kHallX, 0, -kHallZ}, {kHallX, kHallH, kHallZ}}},
                   {"west_gallery", Aabb{{kWestX0, 0, -kSideZ}, {kWestX1, kRoomH, kSideZ}}},
                   {"east_gallery", Aabb{{kEastX0, 0, -kSideZ}, {kEastX1, kRoomH, kSideZ}}},
                   {"north_gallery", Aabb{{-kNorthX, 0, kNorthZ0}, {kNorthX, kRoomH, kNorthZ1}}}};
}

} // namespace

} // namespace museum

uint64_t museumGeometryKey(uint64_t seed) {
    Hasher h;
    h.string("museum geometry");
    h.value(museumGeometrySourceHash());
    h.value(seed);
    return h.result();
}

Scene buildMuseum(const MuseumOptions& options) {
    using namespace museum;
    uint32_t size = options.textureSize;
    if (size < 16 || size > 4096 || (size & (size - 1)) != 0) {
        throw UserError("scene.museum: textureSize " + std::to_string(size) + "; expected a power of two in 16..4096");
    }
    Scene scene;
    scene.name = "museum";
    scene.vertices.reserve(kMuseumVertexReserve);
    scene.indices.reserve(kMuseumIndexReserve);
    Museum m{scene, {}, {}, Rng(options.seed), 0};
    m.tex = makeTextures(scene, size, m.rng, options);
    m.mat = makeMaterials(scene, m.tex);
    scene.roots = {0};
    // The geometry depends on the seed and the code only (not the texture size): stored once per seed.
    const uint64_t geometryKey = museumGeometryKey(options.seed);
    std::optional<StoredBytes> stored;
    if (options.loadGeometry) stored = options.loadGeometry(geometryKey);
    if (!stored || !deserializeGeometry(stored->bytes, scene)) {
        scene.nodes.push_back(Node{"museum"});
        buildArchitecture(m);
        buildExhibits(m);
        buildDecor(m);
        buildRobot(m);
        if (options.storeGeometry)
            if (std::optional<std::vector<uint8_t>> bytes = serializeGeometry(scene))
                options.storeGeometry(geometryKey, *bytes);
    }
    addCameras(scene);
    addRooms(scene);
    placeProbes(scene);
    scene.hasSun = true;
    // From the south, a little east, 46° up: through the south windows onto the nave floor and through
    // the skylights' louvres onto the north aisle.
    scene.sun.toSun = glm::normalize(glm::vec3(0.3f, 0.72f, -0.63f));
    // The Preetham sun of the museum's sky for that direction (the ground albedo does not change it): color ×
    // illuminance is its RGB illuminance, colour normalised to a largest component of 1.
    glm::dvec3 e = shading::PreethamSky::sunIlluminance(kMuseumSkyTurbidity, glm::dvec3(scene.sun.toSun));
    double peak = std::max({e.x, e.y, e.z});
    scene.sun.color = glm::vec3(e / peak);
    scene.sun.illuminance = static_cast<float>(peak);
    scene.finalize();
    scene.validate();
    return scene;
}

} // namespace vitrine::scene
