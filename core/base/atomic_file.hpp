#pragma once

#include <filesystem>
#include <functional>
#include <string_view>

namespace vitrine {

// Every file vitrine writes for the user (images, EXRs, metrics.json, report.html, golden images, bench JSON, GLB)
// goes through here: the bytes go to a temporary file in the same directory (".NAME.tmp-PID-N", so the rename never
// crosses file systems), which is flushed to disk and then renamed over `path`. A run that is killed, crashes or
// loses power halfway leaves the previous file as it was (plus, at worst, a stray temporary file), never a
// half-written one under the real name.
//
// `write` fills the temporary file it is given (for writers that want a path, like OpenEXR). What it throws is
// rethrown with the temporary's name replaced by `path`, after the temporary is removed. UserError when the directory
// does not exist or the file cannot be written or renamed.
//
// Test hook: with VITRINE_TEST_KILL_DURING_WRITE=NAME in the environment, writing a file called NAME cuts its
// temporary file to half its size and then kills the process (SIGKILL) before the rename: what a crash halfway
// through a write leaves behind. Used by the tests of atomic outputs; never set it otherwise.
void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(const std::filesystem::path& temporary)>& write);
void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);

} // namespace vitrine
