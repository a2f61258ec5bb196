// camera.physical: a DSLR's exposure and lens for the post stack. Meters the HDR image (a centre-weighted
// histogram of log2 luminance), adapts to it over time, picks aperture, shutter and ISO along a program line (or
// takes them from params in manual mode) and describes the lens at that setting from a data/lenses/ file. Its
// `state` port carries the result (nodes/camera/camera_state.hpp). By default all of the exposure runs on the GPU
// (shaders/camera/expose.comp) and stays there for the post nodes' shaders; `readback` same_frame / next_frame
// read the histogram back and do it on the CPU instead (debugging; same_frame stalls the frame).
#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/base/paths.hpp"
#include "core/gpu/buffer_set.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/vk_check.hpp"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "nodes/camera/camera_state.hpp"
#include "nodes/camera/lens.hpp"
#include "nodes/camera/metering.hpp"
#include "nodes/camera/program.hpp"
#include "shaders/camera/exposure.h"
#include "shaders/camera/meter.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>

namespace vitrine {
namespace {

using gpu_types::ExposePush;
using gpu_types::MeterPush;

NodeSchema schema() {
    NodeSchema s;
    s.type = "camera.physical";
    s.doc = "Physical camera: meters the HDR image (centre-weighted log-luminance histogram, eye adaptation), picks "
            "aperture, shutter and ISO on a program line (or manual settings) for a lens from data/lenses/, and "
            "hands the post stack its state (EV, exposure, f-number, shutter, ISO, focal length, aperture shape, "
            "residual aberrations).";
    s.inputs = {{"color", PortKind::Texture, {}, true, Usage::Sampled,
                 "HDR colour to meter (cd/m²), e.g. the previous frame's `fog_composite.color@prev`; unconnected: "
                 "the scene is taken to meter at `initial_ev100`"}};
    OutputPort state;
    state.name = "state";
    state.kind = PortKind::Buffer;
    state.doc = "The camera's state this frame (nodes/camera/camera_state.hpp) for the post nodes' camera_state";
    s.outputs = {state};
    s.params = {
        {"lens", ParamType::Path, "canon_ef_50mm_f1.8_stm", {}, {}, {},
         "A lens of data/lenses/ by name (file stem), or a lens .json file relative to the graph"},
        {"focal_length", ParamType::Float, 0.0, 0.0, 2000.0, {}, "Focal length (mm) within the lens's range; 0: its shortest"},
        {"focus_distance", ParamType::Float, 5.0, 0.01, 100000.0, {}, "Focus distance (m); closer than the lens's closest focus clamps"},
        {"sensor_width", ParamType::Float, 0.0, 0.0, 100.0, {}, "Sensor width (mm); 0: the lens's format"},
        {"sensor_height", ParamType::Float, 0.0, 0.0, 100.0, {}, "Sensor height (mm); 0: the lens's format"},
        {"blade_rotation", ParamType::Float, 0.0, -180.0, 180.0, {}, "Rotation of the aperture's first blade (degrees)"},
        {"mode", ParamType::Enum, "program", {}, {}, {"program", "manual"},
         "program: the metered EV picks aperture and shutter (and auto ISO); manual: f_number, shutter, iso"},
        {"program_shift", ParamType::Float, 0.0, -10.0, 10.0, {},
         "Program shift (stops): positive stops down and lengthens the shutter at equal exposure"},
        {"exposure_compensation", ParamType::Float, 0.0, -10.0, 10.0, {}, "Stops added to the metered exposure (program mode)"},
        {"iso", ParamType::Float, 100.0, 25.0, 409600.0, {}, "ISO (manual and program), or the base ISO with auto_iso"},
        {"auto_iso", ParamType::Bool, false, {}, {}, {},
         "Program mode: raise the ISO (up to max_iso) before the shutter drops below 1/max(60, focal) s"},
        {"max_iso", ParamType::Float, 6400.0, 25.0, 409600.0, {}, "Auto ISO's ceiling"},
        {"f_number", ParamType::Float, 8.0, 0.7, 128.0, {}, "Manual mode: aperture (f-number), within the lens's range"},
        {"shutter", ParamType::Float, 1.0 / 125.0, 1e-5, 3600.0, {}, "Manual mode: shutter (s)"},
        {"shortest_shutter", ParamType::Float, 1.0 / 8000.0, 1e-5, 1.0, {}, "The body's fastest shutter (s)"},
        {"longest_shutter", ParamType::Float, 30.0, 1e-3, 3600.0, {}, "The program's slowest shutter (s)"},
        {"centre_weight", ParamType::Float, 0.75, 0.0, 1.0, {},
         "Metering weight: (1 − c) + c·exp(−r²/2σ²), r from the centre in half image heights; 0: average"},
        {"centre_sigma", ParamType::Float, 0.5, 0.05, 10.0, {}, "σ of the centre weight, in half image heights"},
        {"meter_low", ParamType::Float, 0.1, 0.0, 0.99, {}, "Fraction of the (weighted) histogram ignored at the dark end"},
        {"meter_high", ParamType::Float, 0.95, 0.01, 1.0, {}, "Fraction of the histogram below which the metering stops (the brightest 1 − this is ignored)"},
        {"adaptation_time", ParamType::Float, 0.5, 0.0, 60.0, {},
         "Eye adaptation time constant τ (s): the EV moves by 1 − exp(−dt/τ) of the way each frame; 0: instant"},
        {"fps", ParamType::Float, 24.0, 1.0, 1000.0, {}, "Frames per second, for the adaptation (the scene's fps)"},
        {"initial_ev100", ParamType::Float, 12.0, -10.0, 30.0, {},
         "Scene EV100 assumed until the first metering arrives (frame 0 of an @prev input), or always without `color`"},
        {"log_settings", ParamType::Bool, false, {}, {}, {},
         "Print the metered EV and the chosen settings every frame (info log)"},
        {"readback", ParamType::Enum, "none", {}, {}, {"none", "same_frame", "next_frame"},
         "none: metering, eye adaptation and the program run on the GPU and the post nodes read the result there (no "
         "wait); for debugging, the same on the CPU from the histogram read back: same_frame waits for the GPU in the "
         "middle of the frame, next_frame uses it one frame later"},
    };
    return s;
}

class Physical final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const Params& p = ctx.params();
        try {
            mLens = camera::loadLens(camera::findLens(p.getString("lens"), ctx.resolvePath(".").parent_path(),
                                                      dataDir()));
        } catch (const UserError& e) {
            ctx.failParam("lens", e.what());
        }
        mFocal = p.getFloat("focal_length") > 0.0f ? p.getFloat("focal_length") : mLens.focalMinMm;
        if (mFocal < mLens.focalMinMm - 1e-3f || mFocal > mLens.focalMaxMm + 1e-3f)
            ctx.failParam("focal_length", "expected 0 or a focal length within " + mLens.name + "'s range " +
                                              range(mLens.focalMinMm, mLens.focalMaxMm) + " mm");
        mSensorW = p.getFloat("sensor_width") > 0.0f ? p.getFloat("sensor_width") : mLens.sensorWidthMm;
        mSensorH = p.getFloat("sensor_height") > 0.0f ? p.getFloat("sensor_height") : mLens.sensorHeightMm;
        mManual = p.getString("mode") == "manual";
        const float open = camera::interpolate(mLens.maxAperture, mFocal);
        const float closed = camera::interpolate(mLens.minAperture, mFocal);
        if (mManual && (p.getFloat("f_number") < open - 1e-3f || p.getFloat("f_number") > closed + 1e-3f))
            ctx.failParam("f_number", "expected an f-number within " + mLens.name + "'s range at " + fmt(mFocal) +
                                          " mm: f/" + range(open, closed));
        if (p.getFloat("shortest_shutter") >= p.getFloat("longest_shutter"))
            ctx.failParam("shortest_shutter", "must be shorter than longest_shutter");
        if (p.getFloat("meter_low") >= p.getFloat("meter_high"))
            ctx.failParam("meter_low", "must be below meter_high");
        if (p.getBool("auto_iso") && p.getFloat("max_iso") < p.getFloat("iso"))
            ctx.failParam("max_iso", "must be at least the base iso");

        // The input's size is read at the first frame: an `@prev` input's producer may be set up after this node.
        mMeter = ctx.hasInput("color");
        mReadback = p.getString("readback") != "none";
        if (mMeter) {
            mTilesPipeline = ctx.computePipeline("camera/meter_tiles.comp", {}, 1);
            mReducePipeline = ctx.computePipeline("camera/meter_reduce.comp", {}, 1);
        }
        if (!mReadback) mExposePipeline = ctx.computePipeline("camera/expose.comp", {}, 1);
        mOut = std::make_shared<CameraStateObject>();
        mOut->cpuExposure = mReadback;
        ctx.setObject("state", mOut);
    }

    void execute(ExecuteContext& ctx) override {
        const Params& p = ctx.params();
        mOut->ensureGpu(ctx.gpu());
        ensureBuffers(ctx.gpu(), mMeter ? &ctx.input("color").desc() : nullptr);
        if (!mReadback) return executeOnGpu(ctx, p);
        if (ctx.frameIndex() == 0) {
            mAdapted.reset();
            mPending = false;
        }
        const bool sameFrame = p.getString("readback") == "same_frame";
        std::optional<float> metered;
        if (mMeter) {
            if (!sameFrame && mPending) metered = readMeter(p);
            mPending = false;
            if (ctx.inputValid("color")) {
                recordMeter(ctx, p);
                if (sameFrame) {
                    ctx.splitSubmission();
                    metered = readMeter(p);
                } else {
                    mPending = true;
                }
            }
        }
        if (metered) mLastMetered = *metered;
        const float dt = 1.0f / p.getFloat("fps");
        const float tau = p.getFloat("adaptation_time");
        if (!mAdapted) {
            // Converged at once: the first metering (or the initial EV) is taken as it is.
            mAdapted = metered ? *metered : p.getFloat("initial_ev100");
            if (!metered) mLastMetered = *mAdapted;
        } else {
            mAdapted = gpu_types::cameraAdapt(*mAdapted, mLastMetered, dt, tau);
        }
        fillState(p, *mAdapted);
        mOut->frame = ctx.frameIndex();
        mOut->writeExposureFromCpu();
        if (p.getBool("log_settings")) logSettings(ctx.frameIndex(), mOut->state, "");
    }

    void releaseGpu() override {
        mSet = StorageBufferSet();
        mTiles = GpuBuffer();
        mResult = GpuBuffer();
        mPending = false;
    }

private:
    static void logSettings(uint32_t frame, const CameraState& st, const char* note) {
        char line[320];
        std::snprintf(line, sizeof line,
                      "camera.physical frame %u%s: metered EV100 %.2f, exposed EV100 %.2f (%.2f stops): f/%.1f, "
                      "shutter %.4g s, ISO %.0f, %.1f mm",
                      frame, note, st.meteredEv100, st.ev100, std::log2(st.exposure), st.fNumber, st.shutterSeconds,
                      st.iso, st.focalLengthMm);
        logInfo(line);
    }

    // The default path: meter, adapt and expose on the GPU; the CPU fills only the metering-independent fields.
    void executeOnGpu(ExecuteContext& ctx, const Params& p) {
        // Last frame's result, which the GPU has finished (one frame in flight): logged before it is overwritten.
        if (p.getBool("log_settings") && ctx.frameIndex() > 0)
            logSettings(ctx.frameIndex() - 1, mOut->resolved(), " (GPU, logged a frame late)");
        const bool metered = mMeter && ctx.inputValid("color");
        if (metered) {
            recordMeter(ctx, p);
        } else {
            // Orders this frame's write of the exposure after last frame's reads of it.
            ctx.computeBarrier();
        }
        ExposePush push{};
        push.flags = (metered ? EXPOSE_METERED : 0u) | (ctx.frameIndex() == 0 ? EXPOSE_RESET : 0u) |
                     (mManual ? EXPOSE_MANUAL : 0u) | (p.getBool("auto_iso") ? EXPOSE_AUTO_ISO : 0u);
        push.meterLow = p.getFloat("meter_low");
        push.meterHigh = p.getFloat("meter_high");
        push.dt = 1.0f / p.getFloat("fps");
        push.tau = p.getFloat("adaptation_time");
        push.initialEv100 = p.getFloat("initial_ev100");
        push.compensation = p.getFloat("exposure_compensation");
        push.shift = p.getFloat("program_shift");
        push.wideOpenFNumber = camera::interpolate(mLens.maxAperture, mFocal);
        push.minFNumber = camera::interpolate(mLens.minAperture, mFocal);
        push.shortestShutter = p.getFloat("shortest_shutter");
        push.longestShutter = p.getFloat("longest_shutter");
        push.focalLengthMm = mFocal;
        push.iso = p.getFloat("iso");
        push.maxIso = p.getFloat("max_iso");
        push.manualFNumber = p.getFloat("f_number");
        push.manualShutter = p.getFloat("shutter");
        // The metering-independent fields (lens, sensor, blades); the metering-dependent ones it fills are
        // placeholders (cpuExposure is false: consumers read them from the GPU buffer).
        fillState(p, p.getFloat("initial_ev100"));
        const CameraState& st = mOut->state;
        push.blades = static_cast<uint32_t>(std::max(0, st.bladeCount));
        push.bladeRoundness = st.bladeRoundness;
        push.bladeRotation = st.bladeRotation;
        push.mechanicalWideOpen = mMechanicalWideOpen;
        ctx.dispatchWithSets(mExposePipeline, &push, sizeof(push), EXPOSE_GROUP, 1, layouts(), sets());
        // The post nodes read the exposure in their shaders, later in this command buffer.
        ctx.computeBarrier();
        mOut->frame = ctx.frameIndex();
    }

    std::array<VkDescriptorSetLayout, 1> layouts() const { return {mSet.layout()}; }
    std::array<VkDescriptorSet, 1> sets() const { return {mSet.set()}; }

    static std::string fmt(float v) {
        char b[32];
        std::snprintf(b, sizeof b, "%g", v);
        return b;
    }
    static std::string range(float a, float b) { return a == b ? fmt(a) : fmt(a) + "-" + fmt(b); }

    // in: the metered image (null without `color`: the buffers only complete the set expose.comp binds).
    void ensureBuffers(Context& gpu, const ImageDesc* in) {
        if (mSet) return;
        mTilesX = in ? (in->width + METER_TILE - 1) / METER_TILE : 1;
        mTileCount = in ? mTilesX * ((in->height + METER_TILE - 1) / METER_TILE) : 1;
        mTiles = GpuBuffer(gpu, VkDeviceSize(mTileCount) * METER_BINS * sizeof(glm::vec2), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                           false, "camera.physical.tiles");
        mResult = GpuBuffer(gpu, METER_BINS * sizeof(glm::vec2), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true,
                            "camera.physical.histogram");
        const std::array<VkBuffer, 3> buffers = {mTiles.buffer(), mResult.buffer(), mOut->buffer()};
        mSet = StorageBufferSet(gpu, buffers, VK_SHADER_STAGE_COMPUTE_BIT, "camera.physical.meter");
    }

    void recordMeter(ExecuteContext& ctx, const Params& p) {
        MeterPush push{};
        push.centreWeight = p.getFloat("centre_weight");
        push.centreSigma = p.getFloat("centre_sigma");
        push.tilesX = mTilesX;
        push.tileCount = mTileCount;
        const std::array<VkDescriptorSetLayout, 1> layouts = {mSet.layout()};
        const std::array<VkDescriptorSet, 1> sets = {mSet.set()};
        const ImageDesc& in = ctx.input("color").desc();
        // The tiles are rewritten every frame: order this frame's writes after last frame's reads of them.
        ctx.computeBarrier();
        ctx.dispatchWithSets(mTilesPipeline, &push, sizeof(push), in.width, in.height, layouts, sets);
        ctx.computeBarrier();
        ctx.dispatchWithSets(mReducePipeline, &push, sizeof(push), METER_BINS * METER_REDUCE_GROUP, 1, layouts, sets);
        if (!mReadback) return ctx.computeBarrier(); // expose.comp reads the histogram next
        VkMemoryBarrier2 b{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
        b.srcStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
        b.srcAccessMask = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
        b.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
        b.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
        VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
        dep.memoryBarrierCount = 1;
        dep.pMemoryBarriers = &b;
        vkCmdPipelineBarrier2(ctx.cmd(), &dep);
    }

    std::optional<float> readMeter(const Params& p) const {
        const auto* bins = static_cast<const glm::vec2*>(mResult.mapped());
        std::array<glm::vec2, METER_BINS> h;
        for (int i = 0; i < METER_BINS; ++i) h[i] = bins[i];
        const float meanLog2 = camera::histogramMeanLog2(h, p.getFloat("meter_low"), p.getFloat("meter_high"));
        if (std::isnan(meanLog2)) return std::nullopt;
        return camera::meteredEv100(std::exp2(meanLog2));
    }

    void fillState(const Params& p, float meteredEv) {
        camera::ExposureSettings e;
        camera::ProgramLimits limits;
        limits.wideOpenFNumber = camera::interpolate(mLens.maxAperture, mFocal);
        limits.minFNumber = camera::interpolate(mLens.minAperture, mFocal);
        if (mManual) {
            e.fNumber = p.getFloat("f_number");
            e.shutterSeconds = p.getFloat("shutter");
            e.iso = p.getFloat("iso");
            e.ev100 = camera::ev100Of(e.fNumber, e.shutterSeconds, e.iso);
        } else {
            limits.shortestShutter = p.getFloat("shortest_shutter");
            limits.longestShutter = p.getFloat("longest_shutter");
            limits.focalLengthMm = mFocal;
            limits.iso = p.getFloat("iso");
            limits.autoIso = p.getBool("auto_iso");
            limits.maxIso = p.getFloat("max_iso");
            e = camera::programExposure(meteredEv - p.getFloat("exposure_compensation"), p.getFloat("program_shift"), limits);
        }
        const camera::LensState lens = camera::evaluateLens(mLens, mFocal, p.getFloat("focus_distance"), e.fNumber);
        mMechanicalWideOpen = lens.mechanicalWideOpen;
        CameraState& s = mOut->state;
        s.ev100 = e.ev100;
        s.exposure = camera::exposureScale(e.ev100);
        s.fNumber = e.fNumber;
        s.shutterSeconds = e.shutterSeconds;
        s.iso = e.iso;
        s.focalLengthMm = lens.focalLengthMm;
        s.focusDistanceM = p.getFloat("focus_distance");
        s.sensorWidthMm = mSensorW;
        s.sensorHeightMm = mSensorH;
        s.bladeCount = mLens.blades;
        s.bladeRoundness = mLens.bladeRoundness;
        s.bladeRotation = p.getFloat("blade_rotation") * std::numbers::pi_v<float> / 180.0f;
        s.wideOpenFNumber = lens.wideOpenFNumber;
        s.minFNumber = lens.minFNumber;
        s.distortionK1 = lens.k1;
        s.distortionK2 = lens.k2;
        s.caRedScale = lens.caRed;
        s.caBlueScale = lens.caBlue;
        s.mechanicalVignetting = lens.mechanicalVignetting;
        s.meteredEv100 = meteredEv;
    }

    camera::LensData mLens;
    float mFocal = 50.0f, mSensorW = 36.0f, mSensorH = 24.0f;
    bool mManual = false, mMeter = false, mReadback = false;
    float mMechanicalWideOpen = 0.0f;
    uint32_t mTilesX = 0, mTileCount = 0;
    PipelineId mTilesPipeline = 0, mReducePipeline = 0, mExposePipeline = 0;
    GpuBuffer mTiles, mResult;
    StorageBufferSet mSet;
    bool mPending = false;
    std::optional<float> mAdapted;
    float mLastMetered = 0.0f;
    std::shared_ptr<CameraStateObject> mOut;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Physical>(); });

} // namespace
} // namespace vitrine
