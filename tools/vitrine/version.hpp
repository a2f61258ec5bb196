#pragma once

namespace vitrine {

// The project version (CMake's project(VERSION)) and the git commit the binary was built from (12 hex digits, with
// "-dirty" when tracked files had uncommitted changes; "unknown" when built outside a git checkout). Generated at
// build time by cmake/version.cmake.
const char* versionNumber();
const char* versionCommit();

} // namespace vitrine
