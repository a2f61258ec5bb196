#include "tools/vitrine/cli.hpp"

#include "core/base/error.hpp"

#include <algorithm>

namespace vitrine::cli {

std::string Args::get(const std::string& name, const std::string& fallback) const {
    auto it = options.find(name);
    return it == options.end() || it->second.empty() ? fallback : it->second.back();
}

const std::vector<std::string>& Args::all(const std::string& name) const {
    static const std::vector<std::string> kNone;
    auto it = options.find(name);
    return it == options.end() ? kNone : it->second;
}

uint32_t Args::getUint(const std::string& name, uint32_t fallback) const {
    if (!has(name)) return fallback;
    std::string v = get(name);
    if (v.empty() || !std::all_of(v.begin(), v.end(), ::isdigit) || v.size() > 9)
        throw UserError("--" + name + ": expected a non-negative integer, got '" + v + "'");
    return static_cast<uint32_t>(std::stoul(v));
}

Args parse(int argc, char** argv, const std::vector<std::string>& valued,
           const std::map<std::string, std::vector<std::string>>& optional) {
    auto listed = [](const std::vector<std::string>& list, const std::string& name) {
        return std::find(list.begin(), list.end(), name) != list.end();
    };
    // The command decides which options have optional values, so find it first: the first argument that is neither
    // an option nor the value of one.
    std::string command;
    for (int i = 1; i < argc; ++i) {
        std::string s = argv[i];
        if (s.rfind("--", 0) != 0 || s.size() == 2) {
            command = s;
            break;
        }
        if (s.find('=') == std::string::npos && listed(valued, s.substr(2))) ++i;
    }
    auto commandOptional = optional.find(command);

    Args a;
    for (int i = 1; i < argc; ++i) {
        std::string s = argv[i];
        if (s.rfind("--", 0) == 0 && s.size() > 2) {
            std::string name = s.substr(2), value;
            auto eq = name.find('=');
            bool hasValue = eq != std::string::npos;
            if (hasValue) {
                value = name.substr(eq + 1);
                name = name.substr(0, eq);
            }
            bool mayOmit = commandOptional != optional.end() && listed(commandOptional->second, name);
            bool takes = mayOmit || listed(valued, name);
            if (takes && !hasValue) {
                bool nextIsValue = i + 1 < argc && std::string(argv[i + 1]).rfind("--", 0) != 0;
                if (nextIsValue)
                    value = argv[++i];
                else if (!mayOmit)
                    throw UserError("--" + name + " needs a value");
            } else if (!takes && hasValue) {
                throw UserError("--" + name + " takes no value");
            }
            a.options[name].push_back(value);
        } else if (a.command.empty()) {
            a.command = s;
        } else {
            a.positional.push_back(s);
        }
    }
    return a;
}

} // namespace vitrine::cli
