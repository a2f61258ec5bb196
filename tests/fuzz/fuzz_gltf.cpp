// libFuzzer target: the glTF / GLB loader (preflight checks, tinygltf, conversion to the scene model). See
// fuzz_inputs.hpp; built and run by tools/fuzz.sh.
#include "core/base/error.hpp"
#include "tests/fuzz/fuzz_inputs.hpp"

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const vitrine::fuzz::Scratch scratch("vitrine-fuzz-gltf");
    try {
        vitrine::fuzz::loadGltfInput(data, size, scratch.dir);
    } catch (const vitrine::UserError&) {
        // Rejected with a message for the user: what malformed input should get.
    }
    return 0;
}
