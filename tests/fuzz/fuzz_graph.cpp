// libFuzzer target: the graph loader (JSON, extends + merge patch, --set, validation, order). See fuzz_inputs.hpp for
// the input format; built and run by tools/fuzz.sh.
#include "core/base/error.hpp"
#include "tests/fuzz/fuzz_inputs.hpp"

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const vitrine::fuzz::Scratch scratch("vitrine-fuzz-graph");
    try {
        vitrine::fuzz::loadGraphInput(data, size, scratch.dir);
    } catch (const vitrine::UserError&) {
        // Rejected with a message for the user: what malformed input should get.
    }
    return 0;
}
