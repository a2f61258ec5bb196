#include "tools/vitrine/serve/http_util.hpp"

#include "core/base/json_text.hpp"
#include "core/graph/json_util.hpp"

namespace vitrine::serve {

nlohmann::json parseRequestBody(const std::string& body) {
    JsonTextError error;
    std::optional<nlohmann::json> parsed = parseJsonText(body, error);
    if (!parsed)
        throw HttpError(400,
                        "request body:" + std::to_string(error.line) + ":" + std::to_string(error.column) + ": " +
                            error.describe(),
                        {{"line", error.line}, {"column", error.column}, {"byte", error.byte}, {"pointer", ""}});
    if (!parsed->is_object())
        throw HttpError(400, "request body: /: expected a JSON object, got " + brief(*parsed), {{"pointer", ""}});
    return std::move(*parsed);
}

std::string optionalString(const nlohmann::json& request, const std::string& key, const std::string& pointer) {
    if (!request.contains(key) || request[key].is_null()) return {};
    const std::string at = pointer + "/" + pointerToken(key);
    if (!request[key].is_string())
        throw HttpError(400, "request body: " + at + ": expected a string, got " + brief(request[key]),
                        {{"pointer", at}});
    return request[key].get<std::string>();
}

uint32_t optionalUint(const nlohmann::json& request, const std::string& key, uint32_t min, uint32_t max,
                      uint32_t fallback, const std::string& pointer) {
    if (!request.contains(key) || request[key].is_null()) return fallback;
    const nlohmann::json& v = request[key];
    const std::string at = pointer + "/" + pointerToken(key);
    const bool integral = v.is_number_unsigned() || (v.is_number_integer() && v.get<int64_t>() >= 0);
    if (!integral || v.get<uint64_t>() < min || v.get<uint64_t>() > max)
        throw HttpError(400,
                        "request body: " + at + ": expected an integer in [" + std::to_string(min) + ", " +
                            std::to_string(max) + "], got " + brief(v),
                        {{"pointer", at}});
    return static_cast<uint32_t>(v.get<uint64_t>());
}

bool optionalBool(const nlohmann::json& request, const std::string& key, bool fallback, const std::string& pointer) {
    if (!request.contains(key) || request[key].is_null()) return fallback;
    const std::string at = pointer + "/" + pointerToken(key);
    if (!request[key].is_boolean())
        throw HttpError(400, "request body: " + at + ": expected true or false, got " + brief(request[key]),
                        {{"pointer", at}});
    return request[key].get<bool>();
}

} // namespace vitrine::serve
