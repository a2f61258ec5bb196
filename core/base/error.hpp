#pragma once

#include <stdexcept>
#include <string>

namespace vitrine {

// Thrown when something the user wrote (a graph, a parameter, a file path, a scene) is wrong.
// The CLI maps it to exit status 1 and prints what() on stderr, so the message must name the
// file, the JSON pointer or `node.port`, and what was expected.
class UserError : public std::runtime_error {
public:
    explicit UserError(const std::string& message) : std::runtime_error(message) {}
};

// Thrown when vitrine itself fails (a Vulkan call, a broken invariant). Exit status 2.
class InternalError : public std::runtime_error {
public:
    explicit InternalError(const std::string& message) : std::runtime_error(message) {}
};

} // namespace vitrine
