#pragma once

// Helpers shared by the post-stack tests (motion_blur_test.cpp, lens_test.cpp): synthetic input images as EXR files
// for image.load, graphs as JSON, and the test-only node test.camera_state (a CameraState from params, standing in
// for camera.physical).
#include "tests/gpu/gpu_test.hpp"

#include "core/image/image.hpp"

#include <filesystem>
#include <string>

namespace vitrine::test::post {

// Writes img as <name>.exr (float) into a scratch folder of this process; returns the path.
std::filesystem::path writeInput(const Image& img, const std::string& name);

// An image.load node for a file written by writeInput.
nlohmann::json loadNode(const std::filesystem::path& path);

nlohmann::json graph(nlohmann::json nodes, nlohmann::json outputs, int w, int h, int frames = 1);

// Centroid of channel c of img over the disc of radius r around (x, y), and the channel's sum there (pixel centres
// at +0.5).
struct Blob {
    double x = 0.0, y = 0.0, sum = 0.0;
};
Blob centroid(const Image& img, double x, double y, double r, int c);

} // namespace vitrine::test::post
