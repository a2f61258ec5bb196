#include "core/graph/json_util.hpp"

#include "core/base/error.hpp"

#include <fstream>
#include <sstream>

namespace vitrine {

nlohmann::json parseJson(const std::string& text, const std::string& file) {
    try {
        return nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error& e) {
        size_t line = 1, column = 1;
        size_t end = std::min<size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
        for (size_t i = 0; i < end; ++i) {
            if (text[i] == '\n') {
                ++line;
                column = 1;
            } else {
                ++column;
            }
        }
        std::string what = e.what();
        // nlohmann prefixes "[json.exception.parse_error.101] parse error at line 3, column 5: ".
        auto colon = what.find(": ", what.find("parse error"));
        std::string detail = colon == std::string::npos ? what : what.substr(colon + 2);
        throw UserError(file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": JSON syntax error: " + detail);
    }
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
    std::string s = value.dump();
    if (s.size() > 60) s = s.substr(0, 57) + "...";
    return s;
}

} // namespace vitrine
