#pragma once

#include "core/gpu/context.hpp"
#include "core/image/image.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <map>
#include <string>

namespace vitrine::test {

// One Vulkan context (validation on) for the whole GPU test binary; every test fails if the
// validation layer reported anything while it ran.
Context& gpu();

class GpuTest : public ::testing::Test {
protected:
    void SetUp() override;
    void TearDown() override;

private:
    size_t mMessagesBefore = 0;
};

// Validates, compiles and runs a graph given as JSON; returns every graph output of the last frame.
std::map<std::string, Image> runGraph(const nlohmann::json& graph);
std::map<std::string, Image> runGraphFile(const std::string& path, const std::vector<std::string>& sets = {});

double rmse(const Image& a, const Image& b); // over RGB
double maxAbsDiff(const Image& a, const Image& b);

} // namespace vitrine::test
