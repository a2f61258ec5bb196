#pragma once
// The bright pass that post.flare and post.streaks start from: the colour's light above `threshold` after exposure,
// at 1/`downsample` of its size. Both nodes declare the same three params and `bright` output with these helpers,
// size their bright-pass-sized outputs alike and fill the same three push-constant fields.
#include "core/graph/node.hpp"
#include "nodes/camera/camera_state.hpp"

#include <cmath>
#include <initializer_list>
#include <string>
#include <vector>

namespace vitrine {

// Puts exposure, threshold and downsample, in this order, before the node's own params. `verb` ends threshold's doc:
// "... above which light <verb>".
inline void prependBrightPassParams(std::vector<ParamSpec>& params, const std::string& verb) {
    const std::vector<ParamSpec> brightPass = {
        {"exposure",
         ParamType::Float,
         0.0,
         -24.0,
         24.0,
         {},
         "Exposure in stops (as post.tonemap's) that makes the threshold display-referred; camera_state replaces it"},
        {"threshold", ParamType::Float, 1.0, 0.0, 1e4, {}, "Exposed luminance above which light " + verb},
        {"downsample", ParamType::Int, 4, 1.0, 16.0, {}, "Bright-pass downsampling factor"},
    };
    params.insert(params.begin(), brightPass.begin(), brightPass.end());
}

inline OutputPort brightPassOutput() {
    OutputPort bright;
    bright.name = "bright";
    bright.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    bright.usage = Usage::StorageReadWrite;
    bright.doc = "The bright pass (HDR), downsampled";
    return bright;
}

// Called from setup: sizes `ports` to the `color` input's size / downsample, rounded up; returns the factor.
inline uint32_t sizeBrightPass(SetupContext& ctx, std::initializer_list<const char*> ports) {
    const ImageDesc& color = ctx.input("color");
    const auto factor = static_cast<uint32_t>(ctx.params().getInt("downsample"));
    for (const char* port : ports) {
        ImageDesc& d = ctx.output(port);
        d.width = (color.width + factor - 1) / factor;
        d.height = (color.height + factor - 1) / factor;
    }
    return factor;
}

// Called from execute: the push constants' exposure (1 when camera_state is connected: the bright pass's shader,
// made with cameraExposureDefines, multiplies by the camera's on the GPU; else 2^exposure), threshold and factor,
// fields that shaders/post/flare.h and streaks.h share.
template <class Push> void fillBrightPass(ExecuteContext& ctx, uint32_t factor, Push& push) {
    push.exposure = ctx.hasInput("camera_state") ? 1.0f : std::exp2(ctx.params().getFloat("exposure"));
    push.threshold = ctx.params().getFloat("threshold");
    push.factor = static_cast<int>(factor);
}

} // namespace vitrine
