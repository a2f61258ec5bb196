#include "core/graph/json_util.hpp"

#include "core/base/error.hpp"
#include "core/base/json_text.hpp"

#include <fstream>
#include <sstream>

namespace vitrine {

nlohmann::json parseJson(const std::string& text, const std::string& file) {
    JsonTextError error;
    std::optional<nlohmann::json> json = parseJsonText(text, error);
    if (!json)
        throw UserError(file + ":" + std::to_string(error.line) + ":" + std::to_string(error.column) + ": " +
                        error.describe());
    return std::move(*json);
}

nlohmann::json readJsonFile(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw UserError(path.string() + ": no such file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw UserError(path.string() + ": cannot be read");
    std::stringstream ss;
    ss << in.rdbuf();
    return parseJson(ss.str(), path.string());
}

std::string pointerToken(const std::string& key) {
    std::string out;
    for (char c : key) {
        if (c == '~') out += "~0";
        else if (c == '/') out += "~1";
        else out += c;
    }
    return out;
}

std::string brief(const nlohmann::json& value) {
    // Strings from --set may hold bytes that are not UTF-8; an error message must not throw.
    std::string s = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    if (s.size() > 60) s = s.substr(0, 57) + "...";
    return s;
}

} // namespace vitrine
