#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <optional>
#include <string>

namespace vitrine {

// Where and why JSON text did not parse. `byte` counts from 0; line and column from 1.
struct JsonTextError {
    enum class Kind { Syntax, NumberTooLarge, TooDeep };
    Kind kind = Kind::Syntax;
    size_t byte = 0;
    size_t line = 1;
    size_t column = 1;
    std::string message; // e.g. "syntax error while parsing value - invalid literal; last read: 'x'"
    // "JSON syntax error: ..." or what else was wrong, for "file:line:column: " + describe().
    std::string describe() const;
};

// Arrays and objects nested deeper than this are refused: copying, merging and printing a JSON value
// recurse once per level, and a file of a million '[' must be an error, not a stack overflow.
inline constexpr size_t kMaxJsonDepth = 256;

// Parses JSON text without throwing. Besides syntax errors it refuses numbers a double cannot hold
// (1e309) and nesting deeper than kMaxJsonDepth, reporting the position of each. Used by the graph
// loader (files and --set values) and the glTF loader, so that every user-written JSON is read alike.
std::optional<nlohmann::json> parseJsonText(const std::string& text, JsonTextError& error);

} // namespace vitrine
