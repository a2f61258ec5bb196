// vitrine jitter: plots the camera jitter patterns (core/scene/jitter.hpp) as SVG, one file per pattern.
#include "core/base/atomic_file.hpp"
#include "core/base/error.hpp"
#include "core/scene/jitter.hpp"
#include "tools/vitrine/cli.hpp"

#include <cstdio>
#include <filesystem>

namespace vitrine::cli {

int jitterCommand(const Args& args) {
    const auto& names = scene::jitterPatternNames();
    std::vector<size_t> chosen;
    for (const std::string& name : args.positional) {
        size_t i = 0;
        while (i < names.size() && names[i] != name)
            ++i;
        if (i == names.size() || i == 0) {
            std::string known;
            for (size_t k = 1; k < names.size(); ++k)
                known += (k > 1 ? ", " : "") + names[k];
            throw UserError("jitter: unknown pattern '" + name + "'; expected one of: " + known);
        }
        chosen.push_back(i);
    }
    if (chosen.empty())
        for (size_t i = 1; i < names.size(); ++i)
            chosen.push_back(i);
    const uint32_t frames = args.getUint("frames", 64);
    const std::filesystem::path dir = args.get("out", "out/jitter");
    std::filesystem::create_directories(dir);
    for (size_t i : chosen) {
        const std::filesystem::path file = dir / ("jitter_" + names[i] + ".svg");
        writeFileAtomically(file, scene::jitterPatternSvg(static_cast<scene::JitterPattern>(i), frames));
        std::printf("wrote %s\n", file.string().c_str());
    }
    return 0;
}

} // namespace vitrine::cli
