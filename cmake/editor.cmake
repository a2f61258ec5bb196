# The graph editor (editor/, a TypeScript app built with Vite): `npm run build` writes editor/dist/, which
# `vitrine serve` serves at /. Part of ALL when Node.js >= 18, npm and editor/node_modules are present
# (tools/install-deps.sh runs `npm ci` from editor/package-lock.json); the build itself never installs packages.
# Without them configure says why and the editor is skipped; its tests (tests/editor/) then fail, not skip.
find_program(VITRINE_NODE node)
find_program(VITRINE_NPM npm)
set(VITRINE_EDITOR_DIR ${CMAKE_SOURCE_DIR}/editor)
set(VITRINE_EDITOR_MISSING "")
if(NOT EXISTS ${VITRINE_EDITOR_DIR}/package.json)
    set(VITRINE_EDITOR_MISSING "editor/package.json does not exist")
elseif(NOT VITRINE_NODE OR NOT VITRINE_NPM)
    set(VITRINE_EDITOR_MISSING "node or npm not found (run tools/install-deps.sh)")
else()
    execute_process(COMMAND ${VITRINE_NODE} --version OUTPUT_VARIABLE _node_version OUTPUT_STRIP_TRAILING_WHITESPACE)
    string(REGEX REPLACE "^v([0-9]+).*" "\\1" _node_major "${_node_version}")
    if(NOT _node_major MATCHES "^[0-9]+$" OR _node_major LESS 18)
        set(VITRINE_EDITOR_MISSING "node ${_node_version} is older than 18 (run tools/install-deps.sh)")
    elseif(NOT EXISTS ${VITRINE_EDITOR_DIR}/node_modules/.package-lock.json)
        set(VITRINE_EDITOR_MISSING "editor/node_modules is not installed (run tools/install-deps.sh: npm ci in editor/)")
    endif()
endif()

if(VITRINE_EDITOR_MISSING)
    message(WARNING "The graph editor is not built: ${VITRINE_EDITOR_MISSING}. `vitrine serve` then says so at /, and the "
                    "editor tests (editor.*) fail.")
else()
    message(STATUS "Graph editor: built into editor/dist/ with ${VITRINE_NPM} (node ${_node_version})")
    # Everything the bundle is made from; CONFIGURE_DEPENDS re-globs at build time, so a new source file counts.
    file(GLOB_RECURSE _editor_sources CONFIGURE_DEPENDS ${VITRINE_EDITOR_DIR}/src/* ${VITRINE_EDITOR_DIR}/public/*)
    file(GLOB _editor_config CONFIGURE_DEPENDS ${VITRINE_EDITOR_DIR}/*.json ${VITRINE_EDITOR_DIR}/*.ts
         ${VITRINE_EDITOR_DIR}/*.html ${VITRINE_EDITOR_DIR}/*.js ${VITRINE_EDITOR_DIR}/*.mjs)
    add_custom_command(
        OUTPUT ${VITRINE_EDITOR_DIR}/dist/index.html
        COMMAND ${VITRINE_NPM} run --silent build
        COMMAND ${CMAKE_COMMAND} -E touch ${VITRINE_EDITOR_DIR}/dist/index.html
        WORKING_DIRECTORY ${VITRINE_EDITOR_DIR}
        DEPENDS ${_editor_sources} ${_editor_config} ${VITRINE_EDITOR_DIR}/node_modules/.package-lock.json
        COMMENT "Building the graph editor (npm run build -> editor/dist/)"
        VERBATIM)
    add_custom_target(editor ALL DEPENDS ${VITRINE_EDITOR_DIR}/dist/index.html)
endif()
