#include "core/graph/node.hpp"

#include "core/base/error.hpp"
#include "core/graph/registry.hpp"

#include <mutex>
#include <utility>

namespace vitrine {

void detail::wrongObjectType(const std::string& port, const char* expected) {
    throw InternalError("port '" + port + "' carries no object of the expected type (" + expected + ")");
}

const nlohmann::json& Params::at(const std::string& name) const {
    auto it = mValues.find(name);
    if (it == mValues.end()) throw InternalError("node " + mSchema.type + " reads undeclared param '" + name + "'");
    return *it;
}

bool Params::getBool(const std::string& name) const { return at(name).get<bool>(); }
int Params::getInt(const std::string& name) const { return at(name).get<int>(); }
float Params::getFloat(const std::string& name) const { return at(name).get<float>(); }
std::string Params::getString(const std::string& name) const { return at(name).get<std::string>(); }

glm::vec2 Params::getVec2(const std::string& name) const {
    const auto& v = at(name);
    return {v[0].get<float>(), v[1].get<float>()};
}
glm::vec3 Params::getVec3(const std::string& name) const {
    const auto& v = at(name);
    return {v[0].get<float>(), v[1].get<float>(), v[2].get<float>()};
}
glm::vec4 Params::getVec4(const std::string& name) const {
    const auto& v = at(name);
    return {v[0].get<float>(), v[1].get<float>(), v[2].get<float>(), v[3].get<float>()};
}

int Params::getEnumIndex(const std::string& name) const {
    const ParamSpec* spec = mSchema.findParam(name);
    std::string value = getString(name);
    for (size_t i = 0; spec && i < spec->choices.size(); ++i)
        if (spec->choices[i] == value) return static_cast<int>(i);
    throw InternalError("node " + mSchema.type + ": param '" + name + "' is not an enum value");
}

namespace {
std::mutex gFiguresMutex;
std::map<std::string, std::vector<double>> gFigures;
} // namespace

void recordNodeFigure(const std::string& name, double value) {
    std::lock_guard lock(gFiguresMutex);
    gFigures[name].push_back(value);
}

std::map<std::string, std::vector<double>> takeNodeFigures() {
    std::lock_guard lock(gFiguresMutex);
    return std::exchange(gFigures, {});
}

} // namespace vitrine
