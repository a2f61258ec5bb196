#pragma once

#include <httplib.h>
#include <nlohmann/json.hpp>

#include <stdexcept>
#include <string>

// Small pieces every route of `vitrine serve` uses: JSON replies and errors with a status.
namespace vitrine::serve {

// A request the server refuses with `status`; `detail` is merged into the JSON error body (e.g. the pointer into the
// request body, or line and column of a syntax error).
class HttpError : public std::runtime_error {
public:
    HttpError(int status, const std::string& message, nlohmann::json detail = nlohmann::json::object())
        : std::runtime_error(message), mStatus(status), mDetail(std::move(detail)) {}
    int status() const { return mStatus; }
    const nlohmann::json& detail() const { return mDetail; }

private:
    int mStatus;
    nlohmann::json mDetail;
};

inline void replyJson(httplib::Response& res, int status, const nlohmann::json& body) {
    res.status = status;
    res.set_content(body.dump(2) + "\n", "application/json");
}

// {"error": message, "status": status, ...detail}.
inline void replyError(httplib::Response& res, int status, const std::string& message,
                       const nlohmann::json& detail = nlohmann::json::object()) {
    nlohmann::json body = {{"error", message}, {"status", status}};
    for (const auto& [key, value] : detail.items())
        body[key] = value;
    replyJson(res, status, body);
}

// The JSON object of a request body: 400 with line, column and byte offset when it does not parse, 400 with the
// pointer "" when it is not an object.
nlohmann::json parseRequestBody(const std::string& body);

// Fields of a request object, with 400 and the JSON pointer of the field when it has the wrong type or range.
std::string optionalString(const nlohmann::json& request, const std::string& key, const std::string& pointer = "");
uint32_t optionalUint(const nlohmann::json& request, const std::string& key, uint32_t min, uint32_t max,
                      uint32_t fallback, const std::string& pointer = "");
bool optionalBool(const nlohmann::json& request, const std::string& key, bool fallback,
                  const std::string& pointer = "");

} // namespace vitrine::serve
