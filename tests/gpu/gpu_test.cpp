#include "tests/gpu/gpu_test.hpp"

#include "core/graph/compiler.hpp"
#include "core/graph/executor.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gltf.hpp"
#include "core/scene/scene.hpp"
#include "core/shader/compiler.hpp"

#include <cmath>
#include <limits>
#include <memory>
#include <unistd.h>

namespace vitrine::test {

namespace {

// The shared context lives until the test environment tears down; its log outlives it, so messages the layer
// raises while the device and instance are destroyed (leaked objects, say) still fail the run.
std::shared_ptr<ValidationLog>& sharedLog() {
    static std::shared_ptr<ValidationLog> log = std::make_shared<ValidationLog>();
    return log;
}

std::unique_ptr<Context>& sharedContext() {
    static std::unique_ptr<Context> ctx;
    return ctx;
}

class ContextTeardown : public ::testing::Environment {
public:
    void TearDown() override {
        if (!sharedContext()) return;
        const size_t before = sharedLog()->count();
        sharedContext().reset();
        const auto messages = sharedLog()->messages();
        if (messages.size() > before)
            ADD_FAILURE() << "Vulkan validation reported " << messages.size() - before
                          << " message(s) while the shared test context was destroyed; the last: " << messages.back();
    }
};
const auto* const kContextTeardown = ::testing::AddGlobalTestEnvironment(new ContextTeardown);

} // namespace

Context& gpu() {
    auto& ctx = sharedContext();
    if (!ctx) {
        ContextOptions o;
        o.validation = true;
        o.synchronizationValidation = true;
        o.log = sharedLog();
        ctx = std::make_unique<Context>(o);
    }
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

std::map<std::string, Image> runCompiled(CompiledGraph graph, std::function<bool()> stop = {}) {
    ShaderCompiler shaders;
    Executor executor(gpu(), graph, shaders);
    std::map<std::string, Image> out;
    RunOptions options;
    options.progress = false;
    options.write = {graph.desc.frame.frames - 1};
    options.onOutput = [&](uint32_t, const std::string& name, const Image& image) { out[name] = image; };
    options.stop = std::move(stop);
    executor.run(options);
    return out;
}

} // namespace

std::map<std::string, Image> runGraph(const nlohmann::json& doc, std::function<bool()> stop) {
    GraphDesc desc = validateGraph(doc, "test-graph.json", NodeRegistry::global());
    return runCompiled(compileGraph(std::move(desc)), std::move(stop));
}

std::map<std::string, Image> runGraphFile(const std::string& path, const std::vector<std::string>& sets) {
    return runCompiled(compileGraph(loadGraph(path, sets)));
}

namespace {

// Image comparisons refuse what they cannot measure: an empty image or two sizes make the test fail, and the
// result is infinite so that no "error below bound" assertion can pass by accident.
bool comparable(const Image& a, const Image& b) {
    if (a.width <= 0 || a.height <= 0 || a.pixels.empty()) {
        ADD_FAILURE() << "image comparison of an empty image (" << a.width << "x" << a.height << ")";
        return false;
    }
    if (a.width != b.width || a.height != b.height || a.pixels.size() != b.pixels.size()) {
        ADD_FAILURE() << "image comparison of different sizes: " << a.width << "x" << a.height << " vs " << b.width
                      << "x" << b.height;
        return false;
    }
    return true;
}

} // namespace

double rmse(const Image& a, const Image& b) {
    if (!comparable(a, b)) return std::numeric_limits<double>::infinity();
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
    if (!comparable(a, b)) return std::numeric_limits<double>::infinity();
    double m = 0.0;
    for (size_t i = 0; i < a.pixels.size(); ++i) {
        const double d = std::fabs(static_cast<double>(a.pixels[i]) - static_cast<double>(b.pixels[i]));
        // A NaN on either side is as far as can be (std::max would skip it: a NaN output must not pass).
        if (std::isnan(d)) return std::numeric_limits<double>::infinity();
        m = std::max(m, d);
    }
    return m;
}

std::filesystem::path scratchDir() {
    return std::filesystem::temp_directory_path() / ("vitrine_gpu_test_" + std::to_string(::getpid()));
}

namespace {

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
