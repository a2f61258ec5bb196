#pragma once
// Colour grading through OpenColorIO for color.grade: exposure/contrast in the input's (linear) space, then in a
// working space (display-encoded sRGB by default) an ASC CDL and a LUT file (OCIO FileTransform: .cube and every
// other format OCIO reads), then back to the input's space. One OCIO processor gives both halves: the CPU apply()
// is the reference the GPU shader (OCIO's generated GLSL plus its 3D LUT textures) is tested against.

#include "core/image/image.hpp"

#include <glm/glm.hpp>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace vitrine {

class ColorConfig;

struct GradeSettings {
    std::string source = "scene_linear";    // colour space of the input and the output
    std::string working = "sRGB - Texture"; // colour space the CDL and the LUT apply in
    float exposure = 0.0f;                  // stops, in the source space
    float contrast = 1.0f;                  // around `pivot`, in the source space
    float pivot = 0.18f;
    glm::vec3 slope{1.0f}, offset{0.0f}, power{1.0f};
    float saturation = 1.0f;
    bool cdlClamp = true;          // ASC CDL v1.2 clamps to [0, 1]; false: OCIO's CDL_NO_CLAMP
    std::filesystem::path lut;     // empty: none
    bool lutTetrahedral = true;    // 3D LUT interpolation: tetrahedral, else trilinear
};

// A 3D LUT texture the generated shader samples: edge³ RGB values, red fastest.
struct GradeLut3d {
    std::string samplerName;
    unsigned edge = 0;
    bool linear = true; // sample with linear filtering
    std::vector<float> rgb;
};

struct GradeShader {
    std::string glsl; // defines `vec4 <functionName>(vec4)` and declares `uniform sampler3D <samplerName>;` per LUT
    std::vector<GradeLut3d> luts;
};

class Grade {
public:
    // UserError naming the setting (source, working, lut) for an unknown colour space or a LUT file OCIO cannot
    // read.
    Grade(const ColorConfig& config, const GradeSettings& settings);
    ~Grade();
    Grade(Grade&&) noexcept;
    Grade& operator=(Grade&&) noexcept;

    // OCIO's CPU processor on every pixel; alpha passes through.
    void apply(Image& image) const;
    // OCIO's GLSL (4.0 dialect) for the same processor. UserError when it needs 1D LUT textures or uniforms,
    // which color.grade does not bind (a .cube holding a 1D LUT).
    GradeShader shader(const std::string& functionName) const;

private:
    struct Impl;
    std::unique_ptr<Impl> mImpl;
};

} // namespace vitrine
