#include "tests/gpu/gpu_test.hpp"

#include "core/graph/compiler.hpp"
#include "core/graph/executor.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gltf.hpp"
#include "core/scene/scene.hpp"
#include "core/shader/compiler.hpp"

#include <cmath>
#include <memory>
#include <unistd.h>

namespace vitrine::test {

Context& gpu() {
    static std::unique_ptr<Context> ctx = [] {
        ContextOptions o;
        o.validation = true;
        return std::make_unique<Context>(o);
    }();
    return *ctx;
}

void GpuTest::SetUp() { mMessagesBefore = gpu().validationMessageCount(); }

void GpuTest::TearDown() {
    gpu().waitIdle();
    auto messages = gpu().validationMessages();
    EXPECT_EQ(messages.size(), mMessagesBefore) << "Vulkan validation reported: "
                                                 << (messages.empty() ? "" : messages.back());
}

namespace {

std::map<std::string, Image> runCompiled(CompiledGraph graph) {
    ShaderCompiler shaders;
    Executor executor(gpu(), graph, shaders);
    std::map<std::string, Image> out;
    RunOptions options;
    options.progress = false;
    options.write = {graph.desc.frame.frames - 1};
    options.onOutput = [&](uint32_t, const std::string& name, const Image& image) { out[name] = image; };
    executor.run(options);
    return out;
}

} // namespace

std::map<std::string, Image> runGraph(const nlohmann::json& doc) {
    GraphDesc desc = validateGraph(doc, "test-graph.json", NodeRegistry::global());
    return runCompiled(compileGraph(std::move(desc)));
}

std::map<std::string, Image> runGraphFile(const std::string& path, const std::vector<std::string>& sets) {
    return runCompiled(compileGraph(loadGraph(path, sets)));
}

double rmse(const Image& a, const Image& b) {
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    double sum = 0.0;
    size_t n = static_cast<size_t>(a.width) * a.height;
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            double d = a.pixels[i * 4 + c] - b.pixels[i * 4 + c];
            sum += d * d;
        }
    return std::sqrt(sum / (3.0 * n));
}

double maxAbsDiff(const Image& a, const Image& b) {
    double m = 0.0;
    for (size_t i = 0; i < a.pixels.size() && i < b.pixels.size(); ++i)
        m = std::max(m, static_cast<double>(std::fabs(a.pixels[i] - b.pixels[i])));
    return m;
}

namespace {

std::filesystem::path scratchDir() {
    return std::filesystem::temp_directory_path() / ("vitrine_gpu_test_" + std::to_string(::getpid()));
}

class ScratchCleanup : public ::testing::Environment {
public:
    void TearDown() override { std::filesystem::remove_all(scratchDir()); }
};
const auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

} // namespace

std::filesystem::path writeSceneGlb(scene::Scene& s, const std::string& name) {
    s.finalize();
    s.validate();
    std::filesystem::create_directories(scratchDir());
    auto file = scratchDir() / (name + ".glb");
    scene::exportGlb(s, file);
    return file;
}

glm::quat lookRotation(glm::vec3 eye, glm::vec3 target) {
    glm::vec3 back = glm::normalize(eye - target);
    glm::vec3 right = glm::normalize(glm::cross(glm::vec3(0, 1, 0), back));
    glm::vec3 up = glm::cross(back, right);
    return glm::normalize(glm::quat_cast(glm::mat3(right, up, back)));
}

} // namespace vitrine::test
