# SPDX-License-Identifier: GPL-3.0-or-later
# What `cmake --install` puts where, and the Debian packages CPack makes of it
# (`cmake --build build --target package`, docs/howto/install.md):
#   component cli -> package underfoot:     bin/underfoot, share/underfoot/{surfaces,ir,grf,
#                    wading,soundscapes,protocols}, man pages, fetch-recordings.sh, doc files
#   component gui -> package underfoot-gui: bin/underfoot-gui, share/underfoot/gui (the demo
#                    study's data), a desktop entry, an icon, its man page
# The programs find the data relative to themselves (base/DataDir.h: <bin>/../share/underfoot),
# so an installed tree can be moved (cmake --install build --prefix ANY).

set(underfoot_share ${CMAKE_INSTALL_DATADIR}/underfoot)

install(TARGETS underfoot RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT cli)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/engine/data/surfaces ${PROJECT_SOURCE_DIR}/engine/data/ir
                  ${PROJECT_SOURCE_DIR}/engine/data/grf ${PROJECT_SOURCE_DIR}/engine/data/wading
        DESTINATION ${underfoot_share} COMPONENT cli)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/soundscapes/data/
        DESTINATION ${underfoot_share}/soundscapes COMPONENT cli)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/protocols/
        DESTINATION ${underfoot_share}/protocols COMPONENT cli)
install(PROGRAMS ${PROJECT_SOURCE_DIR}/scripts/fetch-recordings.sh
        DESTINATION ${underfoot_share} COMPONENT cli)
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/packaging/copyright
        DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/underfoot COMPONENT cli)

# Man pages from the programs' own --help (tools/docs/cli_reference.py), made at build time.
find_package(Python3 COMPONENTS Interpreter)
set(underfoot_man_dir ${PROJECT_BINARY_DIR}/man)
if(Python3_FOUND)
  set(man_args --program $<TARGET_FILE:underfoot> --man ${underfoot_man_dir})
  set(man_deps underfoot)
  if(TARGET underfoot-gui)
    list(APPEND man_args --gui $<TARGET_FILE:underfoot-gui>)
    list(APPEND man_deps underfoot-gui)
  endif()
  add_custom_command(OUTPUT ${underfoot_man_dir}/underfoot.1
    COMMAND ${CMAKE_COMMAND} -E rm -rf ${underfoot_man_dir}
    COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/docs/cli_reference.py ${man_args}
    DEPENDS ${man_deps} ${PROJECT_SOURCE_DIR}/tools/docs/cli_reference.py
    COMMENT "Man pages from --help (tools/docs/cli_reference.py)"
    VERBATIM)
  # Built with the programs, except in sanitizer builds: there nobody installs them, and ~50
  # runs of an instrumented program took 103 s of a loaded machine (the target stays on demand).
  if(UNDERFOOT_SANITIZE)
    add_custom_target(underfoot_man DEPENDS ${underfoot_man_dir}/underfoot.1)
  else()
    add_custom_target(underfoot_man ALL DEPENDS ${underfoot_man_dir}/underfoot.1)
  endif()
  # The committed Markdown reference (docs/reference/cli), rewritten on request:
  # `ninja -C build cli_reference`. tests/app's CliReference fails while it is stale.
  list(REMOVE_ITEM man_args --man ${underfoot_man_dir})
  set(UNDERFOOT_CLI_REFERENCE_ARGS ${man_args} --markdown ${PROJECT_SOURCE_DIR}/docs/reference/cli)
  add_custom_target(cli_reference
    COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/docs/cli_reference.py
            ${UNDERFOOT_CLI_REFERENCE_ARGS}
    DEPENDS ${man_deps}
    COMMENT "docs/reference/cli from --help"
    VERBATIM)
  # docs/reference/presets.md from the keys the engine declares (`underfoot surfaces --keys`),
  # rewritten on request: `ninja -C build presets_reference`. tests/app's PresetsReference fails
  # while it is stale.
  set(UNDERFOOT_PRESETS_REFERENCE_ARGS --program $<TARGET_FILE:underfoot>
      --output ${PROJECT_SOURCE_DIR}/docs/reference/presets.md)
  add_custom_target(presets_reference
    COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/tools/docs/presets_reference.py
            ${UNDERFOOT_PRESETS_REFERENCE_ARGS}
    DEPENDS underfoot
    COMMENT "docs/reference/presets.md from underfoot surfaces --keys"
    VERBATIM)
  install(DIRECTORY ${underfoot_man_dir}/ DESTINATION ${CMAKE_INSTALL_MANDIR}/man1
          COMPONENT cli FILES_MATCHING PATTERN "underfoot.1" PATTERN "underfoot-*.1"
          PATTERN "underfoot-gui.1" EXCLUDE)
  if(TARGET underfoot-gui)
    install(FILES ${underfoot_man_dir}/underfoot-gui.1 DESTINATION ${CMAKE_INSTALL_MANDIR}/man1
            COMPONENT gui)
  endif()
else()
  message(STATUS "python3 not found: no man pages (the packages are made without them)")
endif()

if(TARGET underfoot-gui)
  install(TARGETS underfoot-gui RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT gui)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/app/gui/data/ DESTINATION ${underfoot_share}/gui
          COMPONENT gui)
  install(FILES ${PROJECT_SOURCE_DIR}/packaging/underfoot-gui.desktop
          DESTINATION ${CMAKE_INSTALL_DATADIR}/applications COMPONENT gui)
  install(FILES ${PROJECT_SOURCE_DIR}/packaging/underfoot.svg
          DESTINATION ${CMAKE_INSTALL_DATADIR}/icons/hicolor/scalable/apps COMPONENT gui)
  install(FILES ${PROJECT_SOURCE_DIR}/packaging/copyright
          DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/underfoot-gui COMPONENT gui)
endif()

# What scripts/setup.sh builds: the programs and their man pages, not the tests.
add_custom_target(underfoot_programs)
add_dependencies(underfoot_programs underfoot)
if(TARGET underfoot-gui)
  add_dependencies(underfoot_programs underfoot-gui)
endif()
if(TARGET underfoot_man)
  add_dependencies(underfoot_programs underfoot_man)
endif()

# ---------------------------------------------------------------------------- Debian packages
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME underfoot)
set(CPACK_PACKAGE_VENDOR "Underfoot")
set(CPACK_PACKAGE_CONTACT "Underfoot maintainers <underfoot@localhost>")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL cli)
if(TARGET underfoot-gui)
  list(APPEND CPACK_COMPONENTS_ALL gui)
endif()
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT) # underfoot_0.1.0-1_amd64.deb
set(CPACK_DEBIAN_PACKAGE_RELEASE 1)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON) # Depends from the shared libraries the programs link
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS OFF)
set(CPACK_DEBIAN_CLI_PACKAGE_NAME underfoot)
set(CPACK_DEBIAN_CLI_DESCRIPTION
    "physically based footstep synthesis and perception experiments
Underfoot synthesises the sound of walking on gravel, snow, wood, metal, water and
other surfaces from a walker's ground reaction force, in real time or offline, and
runs perception experiments on it: randomized protocols, a crash-proof SQLite study
store, R-compatible statistics, online listening tests and replay. This package holds
the command-line program `underfoot`, its surfaces, rooms, soundscapes and protocols.")
# jackd2: the live path's usual server; the browser test's tools are not needed to use it.
set(CPACK_DEBIAN_CLI_PACKAGE_RECOMMENDS "jackd2")
set(CPACK_DEBIAN_GUI_PACKAGE_NAME underfoot-gui)
set(CPACK_DEBIAN_GUI_PACKAGE_SECTION science)
set(CPACK_DEBIAN_GUI_DESCRIPTION
    "experimenter's console for Underfoot footstep perception studies
The Qt 6 console of Underfoot: design and run a study, see the participant's
window on a second screen, watch results, tune surfaces in the sound palette and
set up audio devices and sensors. It creates a demo study on first start.")
# The console's own package needs the command line's data; Qt's platform plugins (xcb) are in
# qt6-qpa-plugins, which no library names, so shlibdeps cannot find it.
set(CPACK_DEBIAN_GUI_PACKAGE_DEPENDS "underfoot (= ${PROJECT_VERSION}-1), qt6-qpa-plugins")
set(CPACK_COMPONENT_CLI_DISPLAY_NAME "underfoot (command line)")
set(CPACK_COMPONENT_GUI_DISPLAY_NAME "underfoot-gui (console)")
set(CPACK_OUTPUT_FILE_PREFIX ${PROJECT_BINARY_DIR}/packages)
include(CPack)
