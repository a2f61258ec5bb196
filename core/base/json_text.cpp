#include "core/base/json_text.hpp"

namespace vitrine {

namespace {

// nlohmann's own DOM builder, plus the position of the first error (its exceptions for number overflow
// carry none) and a depth limit.
class PositionedDomParser : public nlohmann::detail::json_sax_dom_parser<nlohmann::json> {
public:
    using Base = nlohmann::detail::json_sax_dom_parser<nlohmann::json>;
    explicit PositionedDomParser(nlohmann::json& result) : Base(result, false) {}

    bool start_object(std::size_t elements) { return deeper() && Base::start_object(elements); }
    bool end_object() { return --mDepth, Base::end_object(); }
    bool start_array(std::size_t elements) { return deeper() && Base::start_array(elements); }
    bool end_array() { return --mDepth, Base::end_array(); }

    template <class Exception> bool parse_error(std::size_t position, const std::string& token, const Exception& ex) {
        if (mMessage.empty()) {
            mPosition = position;
            mToken = token;
            mMessage = ex.what();
        }
        return false;
    }

    // Set by a failed parse: where the parser stood and what it said.
    std::size_t mPosition = 0;
    std::string mToken;
    std::string mMessage;
    bool mTooDeep = false;

private:
    bool deeper() {
        if (++mDepth <= kMaxJsonDepth) return true;
        if (mMessage.empty()) {
            mMessage = "nesting deeper than " + std::to_string(kMaxJsonDepth) + " levels of arrays and objects";
            mTooDeep = true;
        }
        return false;
    }
    std::size_t mDepth = 0;
};

// nlohmann prefixes "[json.exception.parse_error.101] parse error at line 3, column 5: ": keep what follows.
std::string stripPrefix(const std::string& what) {
    std::string s = what;
    if (s.rfind("[json.exception.", 0) == 0) {
        auto close = s.find("] ");
        if (close != std::string::npos) s = s.substr(close + 2);
    }
    if (s.rfind("parse error", 0) == 0) {
        auto colon = s.find(": ");
        if (colon != std::string::npos) s = s.substr(colon + 2);
    }
    return s;
}

// One past the bracket that opens level kMaxJsonDepth + 1 (the SAX callbacks get no position). The text parsed up to
// there, so strings and escapes are well formed.
size_t tooDeepPosition(const std::string& text) {
    size_t depth = 0;
    bool inString = false;
    for (size_t i = 0; i < text.size(); ++i) {
        char c = text[i];
        if (inString) {
            if (c == '\\')
                ++i;
            else if (c == '"')
                inString = false;
        } else if (c == '"') {
            inString = true;
        } else if ((c == '[' || c == '{') && ++depth > kMaxJsonDepth) {
            return i + 1;
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return text.size();
}

} // namespace

std::optional<nlohmann::json> parseJsonText(const std::string& text, JsonTextError& error) {
    nlohmann::json result;
    PositionedDomParser sax(result);
    bool ok = false;
    try {
        ok = nlohmann::json::sax_parse(text, &sax);
    } catch (const nlohmann::json::exception& e) {
        // sax_parse reports through parse_error(); this is a safety net for what it throws itself.
        if (sax.mMessage.empty()) sax.mMessage = e.what();
    }
    if (ok && sax.mMessage.empty()) return result;

    error = JsonTextError{};
    // Positions are one past the offending character, like nlohmann's own "byte" of a parse_error.
    if (sax.mTooDeep) sax.mPosition = tooDeepPosition(text);
    const std::string overflow = "number overflow parsing ";
    const bool tooLarge = !sax.mTooDeep && stripPrefix(sax.mMessage).rfind(overflow, 0) == 0;
    // A number is reported where it starts, not after its last digit.
    if (tooLarge && sax.mPosition >= sax.mToken.size()) sax.mPosition -= sax.mToken.size() - 1;
    size_t end = std::min(sax.mPosition > 0 ? sax.mPosition - 1 : 0, text.size());
    error.byte = end;
    for (size_t i = 0; i < end; ++i) {
        if (text[i] == '\n') {
            ++error.line;
            error.column = 1;
        } else {
            ++error.column;
        }
    }
    error.message = sax.mMessage.empty() ? "not valid JSON" : stripPrefix(sax.mMessage);
    if (sax.mTooDeep) {
        error.kind = JsonTextError::Kind::TooDeep;
    } else if (tooLarge) {
        error.kind = JsonTextError::Kind::NumberTooLarge;
        error.message = "the number " + error.message.substr(overflow.size()) +
                        " is too large (a double holds at most about 1.8e308)";
    }
    return std::nullopt;
}

std::string JsonTextError::describe() const {
    return kind == Kind::Syntax ? "JSON syntax error: " + message : message;
}

} // namespace vitrine
