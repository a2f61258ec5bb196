#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace vitrine {

// Parses JSON text; a syntax error becomes UserError "file:line:column: JSON syntax error: ...".
nlohmann::json parseJson(const std::string& text, const std::string& file);
nlohmann::json readJsonFile(const std::filesystem::path& path);

// Escapes one reference token of a JSON pointer (RFC 6901: ~ -> ~0, / -> ~1).
std::string pointerToken(const std::string& key);

// Short, quoted rendering of a JSON value for error messages.
std::string brief(const nlohmann::json& value);

} // namespace vitrine
