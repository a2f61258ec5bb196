// reference.fog: single scattering with exact shadow rays, the twin of fog.volumetric (issue #26).
#include "core/base/log.hpp"
#include "core/gpu/transfer.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"
#include "core/shading/sh.hpp"
#include "nodes/reference/twin_tracer.hpp"
#include "shaders/fog/volumetric.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace vitrine {
namespace {

constexpr float kPi = 3.14159265358979f;
// The sky nodes' `sh` texels (shaders/sky/sky.h): SH9 radiance 0-8, sun illuminance 9, sun direction 10.
constexpr int kSkyTexelSunIlluminance = 9, kSkyTexelSunDirection = 10;

NodeSchema schema() {
    NodeSchema s;
    s.type = "reference.fog";
    s.doc = "Ray-traced twin of fog.volumetric: the single-scattering integral along each camera ray (through the "
            "pixel centre, at full resolution) up to its primary surface, or max_distance where it hits nothing, "
            "through the same medium (extinction sigma(y) = density exp(-height_falloff (y - height_reference)), "
            "albedo 1): L = integral of T(t) sigma(t) [E_sun p_HG(l.v) V(x(t)) + A(v)] dt with T the transmittance "
            "(closed form for the exponential height profile), V the sun's visibility by an exact shadow ray through "
            "the scene's BVH (not a shadow map), A fog.volumetric's ambient term (the sky SH convolved with the HG "
            "lobe, times ambient_scale, unshadowed as there; its integral is A (1 - T(d)) exactly). The sun term is "
            "estimated by `steps` distances per sample, stratified and jittered in optical depth (importance "
            "sampling T sigma), so it converges to the integral rather than to a fixed step pattern. Outputs what "
            "fog.volumetric outputs, at full resolution, for fog.composite. Runs on the CPU (Embree) whatever the "
            "Vulkan device; converges and caches like render.pathtrace with target_noise > 0.";
    s.inputs = {
        {"scene", PortKind::Scene, {}, false, Usage::Sampled, "The scene to trace (the G-buffer's scene)"},
        {"camera", PortKind::Camera, {}, false, Usage::Sampled, "The frame's camera (its unjittered view)"},
        {"sky_sh", PortKind::Texture, {}, false, Usage::Sampled,
         "A sky node's `sh`: SH9 radiance (ambient in-scattering), sun illuminance and direction"},
    };
    s.inputs.back().readBack = true;
    OutputPort color;
    color.name = "color";
    color.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    color.size = SizeRule::frame();
    color.usage = Usage::StorageReadWrite;
    color.doc = "fog.volumetric's `scatter` at full resolution: in-scattered radiance towards the camera (rgb, cd/m²) "
                "and transmittance to the surface (a, exact)";
    OutputPort stats = color;
    stats.name = "stats";
    stats.doc = "x: samples per pixel; y: mean luminance; z: sum of squared deviations of the samples' luminance; "
                "w: standard error of the mean luminance (cd/m²)";
    OutputPort distance;
    distance.name = "distance";
    distance.format = VK_FORMAT_R32_SFLOAT;
    distance.size = SizeRule::frame();
    distance.usage = Usage::TransferDst;
    distance.doc = "fog.volumetric's `distance`: metres from the camera to the surface (1e6 where nothing was hit), "
                   "for fog.composite";
    s.outputs = {color, stats, distance};
    s.params = {
        {"density", ParamType::Float, 0.01, 0.0, 10.0, {},
         "Extinction coefficient sigma (1/m) at height_reference; scattering albedo 1 (fog.volumetric's density)"},
        {"anisotropy", ParamType::Float, 0.5, -0.95, 0.95, {}, "Henyey-Greenstein g (fog.volumetric's anisotropy)"},
        {"height_falloff", ParamType::Float, 0.0, 0.0, 10.0, {},
         "Density falls off as exp(-falloff (y - height_reference)) (1/m); 0: homogeneous"},
        {"height_reference", ParamType::Float, 0.0, -1e4, 1e4, {}, "Height (world y, m) where the density is `density`"},
        {"steps", ParamType::Int, 8, 1.0, 256.0, {},
         "Distances per sample along the ray (strata of optical depth, one jittered point and shadow ray each)"},
        {"sun_scale", ParamType::Float, 1.0, 0.0, 100.0, {}, "Multiplier of the sky model's sun illuminance"},
        {"ambient_scale", ParamType::Float, 0.15, 0.0, 10.0, {},
         "Multiplier of the sky's ambient in-scattering (fog.volumetric's ambient_scale)"},
        {"shadows", ParamType::Bool, true, {}, {}, {}, "Sun visibility by shadow rays (off: the sun lights all air)"},
        {"max_distance", ParamType::Float, 50.0, 0.1, 1e4, {}, "Distance (m) marched where the camera ray hits nothing"},
    };
    appendTwinParams(s.params, 4);
    return s;
}

float phaseHg(float cosTheta, float g) {
    const float d = 1.0f + g * g - 2.0f * g * cosTheta;
    return (1.0f - g * g) / (4.0f * kPi * d * std::sqrt(d));
}

// Optical depth along o + t d through sigma(y) = sigma0 exp(-f (y - y0)): tau(t) = s0 (1 - exp(-k t)) / k with
// s0 = sigma(o.y), k = f d.y (s0 t where k is ~0), and its inverse.
struct Medium {
    double s0 = 0.0, k = 0.0;
    double tau(double t) const { return std::abs(k * t) < 1e-7 ? s0 * t : s0 * -std::expm1(-k * t) / k; }
    double distanceAt(double tau) const {
        if (s0 <= 0.0) return 0.0;
        const double x = tau * k / s0;
        return std::abs(x) < 1e-7 ? tau / s0 : -std::log1p(-x) / k;
    }
};

class ReferenceFog final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mScene = ctx.objectAs<SceneObject>("scene");
        mCamera = ctx.objectAs<CameraObject>("camera");
        mStorePipeline = ctx.computePipeline("render/pathtrace_store.comp", {}, 1);
    }

    void execute(ExecuteContext& ctx) override {
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        const ImageDesc& out = ctx.output("color").desc();
        const int w = static_cast<int>(out.width), h = static_cast<int>(out.height);

        ctx.splitSubmission(); // the sky of this frame is computed before it is read back
        const Image sh = readImage(ctx.gpu(), ctx.input("sky_sh"), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        auto texel = [&](int i) { return glm::vec3(sh.at(i, 0)[0], sh.at(i, 0)[1], sh.at(i, 0)[2]); };
        CpuSky sky;
        sky.sunIlluminance = texel(kSkyTexelSunIlluminance);
        sky.sunDirection = texel(kSkyTexelSunDirection);
        std::array<glm::vec3, 9> shc;
        for (int i = 0; i < 9; ++i) shc[i] = texel(i);

        const float density = p.getFloat("density"), g = p.getFloat("anisotropy");
        const float falloff = p.getFloat("height_falloff"), reference = p.getFloat("height_reference");
        const float sunScale = p.getFloat("sun_scale"), ambientScale = p.getFloat("ambient_scale");
        const float maxDistance = p.getFloat("max_distance");
        const bool shadows = p.getBool("shadows");
        const int steps = p.getInt("steps");

        CpuTraceSettings settings = TwinTracer::settings(cam, w, h);
        settings.sunScale = sunScale;
        scene::Hasher key;
        key.string("reference.fog v1");
        hashTraceInputs(key, *mScene, cam, sky, w, h);
        key.value(shc);
        for (float v : {density, g, falloff, reference, sunScale, ambientScale, maxDistance}) key.value(v);
        key.value(shadows);
        key.value(steps);

        auto medium = [=](glm::vec3 o, glm::vec3 d) {
            Medium m;
            m.s0 = density * std::exp(-double(falloff) * (double(o.y) - reference));
            m.k = double(falloff) * d.y;
            return m;
        };
        // The primary surfaces' distances (one ray per pixel): where each march ends, its transmittance (exact) and the
        // `distance` output, also when the estimate comes from the bake cache.
        mDistance.assign(static_cast<size_t>(w) * h, 0.0f);
        mTransmittance.assign(static_cast<size_t>(w) * h, 1.0f);
        mHit.assign(static_cast<size_t>(w) * h, 0);
        {
            CpuTraceSettings one = settings;
            one.spp = 1;
            CpuAccumulation scratch;
            mTwin.tracer(*mScene).estimate(one, sky, scratch, [&](const CpuRays& rays, int x, int y, uint32_t&) {
                glm::vec3 o, d;
                rays.cameraRay(x, y, glm::vec2(0.5f), o, d);
                CpuSurface s;
                const size_t i = static_cast<size_t>(y) * w + x;
                mHit[i] = rays.intersect(o, d, 3.4e38f, s) ? 1 : 0;
                mDistance[i] = mHit[i] ? s.t : maxDistance;
                mTransmittance[i] = static_cast<float>(std::exp(-medium(o, d).tau(mDistance[i])));
                return glm::vec3(0.0f);
            });
        }

        const CpuSampleFn sample = [&, steps, shadows, g](const CpuRays& rays, int x, int y, uint32_t& rng) {
            glm::vec3 o, d;
            rays.cameraRay(x, y, glm::vec2(0.5f), o, d);
            const double dist = mDistance[static_cast<size_t>(y) * w + x];
            const Medium m = medium(o, d);
            const double scattered = -std::expm1(-m.tau(dist)); // 1 - T(d) = integral of T sigma dt
            // fog.volumetric's ambient: sum_lm g^l L_lm Y_lm(v), clamped at 0, times ambient_scale.
            const std::array<double, 9> b = shading::shBasis9(glm::dvec3(d));
            glm::vec3 ambient = shc[0] * float(b[0]);
            for (int i = 1; i < 4; ++i) ambient += g * shc[i] * float(b[i]);
            for (int i = 4; i < 9; ++i) ambient += g * g * shc[i] * float(b[i]);
            ambient = glm::max(ambient, glm::vec3(0.0f)) * ambientScale;
            if (scattered <= 0.0) return glm::vec3(0.0f);
            const glm::vec3 l = rays.sunDirection();
            const glm::vec3 sunSource = rays.sunIlluminance() * phaseHg(glm::dot(l, d), g);
            // The sun term: integral of T sigma V dt = (1 - T(d)) E[V] over tau uniform in [0, tau(d)] mapped as
            // 1 - T: stratified in that fraction, one jittered point per stratum.
            int lit = 0;
            for (int i = 0; i < steps; ++i) {
                if (!shadows) {
                    ++lit;
                    continue;
                }
                const double u = (i + CpuRays::next(rng)) / steps;
                const double tau = -std::log1p(-u * scattered);
                const double t = std::min(m.distanceAt(tau), dist);
                const glm::vec3 x = o + d * static_cast<float>(t);
                lit += rays.occluded(x, l, 3.4e38f) ? 0 : 1;
            }
            return static_cast<float>(scattered) * (sunSource * (float(lit) / float(steps)) + ambient);
        };
        const CpuAccumulation& acc =
            mTwin.run(ctx, "reference.fog", *mScene, settings, sky, key, sample);
        mResult = acc;
        Image distance(w, h);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const size_t i = static_cast<size_t>(y) * w + x;
                mResult.color[i].a = mTransmittance[i];
                distance.at(x, y)[0] = mHit[i] ? mDistance[i] : static_cast<float>(FOG_SKY_DISTANCE);
            }
        mUpload.upload(ctx, mStorePipeline, mResult);
        ctx.upload("distance", distance);
    }

private:
    std::shared_ptr<SceneObject> mScene;
    std::shared_ptr<CameraObject> mCamera;
    PipelineId mStorePipeline = 0;
    TwinTracer mTwin;
    CpuAccumulation mResult;
    CpuResultUpload mUpload;
    std::vector<float> mDistance, mTransmittance;
    std::vector<uint8_t> mHit;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<ReferenceFog>(); });

} // namespace
} // namespace vitrine
