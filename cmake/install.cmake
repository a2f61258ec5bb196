# `cmake --install build --prefix P`: P/bin/vitrine and what it reads at run time under P/share/vitrine/ (shaders/, the
# GLSL sources that vitrine compiles at run time; data/: OCIO config, LUTs, lenses, models; graphs/; editor/dist/ when
# the editor is built). The installed binary finds share/vitrine from its own location (core/base/paths.cpp:
# <dir of the binary>/../share/vitrine), so these two destinations are fixed, not GNUInstallDirs variables.
install(TARGETS vitrine RUNTIME DESTINATION bin)
install(DIRECTORY ${CMAKE_SOURCE_DIR}/shaders ${CMAKE_SOURCE_DIR}/data ${CMAKE_SOURCE_DIR}/graphs
        DESTINATION share/vitrine)
if(NOT VITRINE_EDITOR_MISSING)
    install(DIRECTORY ${CMAKE_SOURCE_DIR}/editor/dist DESTINATION share/vitrine/editor)
endif()
install(FILES ${CMAKE_SOURCE_DIR}/README.md DESTINATION share/doc/vitrine)
# The Python module (tools/python/) into the prefix's Debian Python folder: /usr/lib/python3/dist-packages in the
# .deb (on python3's path there), P/lib/python3/dist-packages for another prefix (PYTHONPATH). The module finds
# P/share/vitrine from its own location (core/base/paths.cpp), three folders up.
set(VITRINE_PYTHON_INSTALL_DIR "lib/python3/dist-packages" CACHE STRING
    "Where `cmake --install` puts the vitrine Python module, relative to the prefix")
if(VITRINE_PYTHON)
    install(TARGETS vitrine_python LIBRARY DESTINATION ${VITRINE_PYTHON_INSTALL_DIR})
endif()

# `cpack --config build/CPackConfig.cmake`: a .deb installing into /usr. Its Depends are the Debian runtime packages
# of the libraries the binary links (dpkg-shlibdeps, from dpkg-dev); a Vulkan driver is recommended (Mesa's includes
# lavapipe, the CPU device the tests run on).
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME vitrine)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Headless Vulkan render-graph toolkit")
set(CPACK_PACKAGE_CONTACT "vitrine developers <vitrine@localhost>")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "mesa-vulkan-drivers")
# The Python module is built for one Python version (its file name says cpython-3XY) and imports NumPy.
if(VITRINE_PYTHON)
    math(EXPR next_minor "${Python_VERSION_MINOR} + 1")
    set(CPACK_DEBIAN_PACKAGE_DEPENDS "python3 (>= ${Python_VERSION_MAJOR}.${Python_VERSION_MINOR}), \
python3 (<< ${Python_VERSION_MAJOR}.${next_minor}), python3-numpy")
endif()
set(CPACK_STRIP_FILES ON)
include(CPack)
