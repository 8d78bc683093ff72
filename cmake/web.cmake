# The browser page of `thzmap serve` (issue 18, docs/gui.md): web/src bundled with
# three.js by esbuild, both from npm at the versions web/package-lock.json pins, into
# BUILD/web/{index.html, assets/app.js, assets/app.css}; installed as share/thzmap/web.
# `npm ci` installs into BUILD/web-npm (never the repository) and only when the lockfile
# changes; --prefer-offline takes npm's cache before the network. Without npm the
# configure step stops here: a build without its page would serve nothing.
find_program(THZ_NPM npm)
find_program(THZ_NODE NAMES node nodejs)
if(NOT THZ_NPM OR NOT THZ_NODE)
  message(FATAL_ERROR "thzmap's web page needs Node.js and npm (Debian: apt-get install "
    "nodejs npm; scripts/install-deps.sh installs them)")
endif()
set(THZ_WEB_NPM_DIR ${CMAKE_BINARY_DIR}/web-npm)
set(THZ_WEB_DIR ${CMAKE_BINARY_DIR}/web)
# The npm step runs in THZ_WEB_NPM_DIR: it must exist before the step's first command
# (Ninja creates a custom command's working directory; the Makefile generators cd into it).
file(MAKE_DIRECTORY ${THZ_WEB_NPM_DIR})
add_custom_command(OUTPUT ${THZ_WEB_NPM_DIR}/npm-ci.stamp
  COMMAND ${CMAKE_COMMAND} -E make_directory ${THZ_WEB_NPM_DIR}
  COMMAND ${CMAKE_COMMAND} -E copy ${CMAKE_SOURCE_DIR}/web/package.json
          ${CMAKE_SOURCE_DIR}/web/package-lock.json ${THZ_WEB_NPM_DIR}
  COMMAND ${THZ_NPM} ci --prefer-offline --no-audit --no-fund --loglevel=error
  COMMAND ${CMAKE_COMMAND} -E touch ${THZ_WEB_NPM_DIR}/npm-ci.stamp
  WORKING_DIRECTORY ${THZ_WEB_NPM_DIR}
  DEPENDS ${CMAKE_SOURCE_DIR}/web/package.json ${CMAKE_SOURCE_DIR}/web/package-lock.json
  COMMENT "npm ci: three.js and esbuild as web/package-lock.json pins them")
file(GLOB THZ_WEB_SOURCES CONFIGURE_DEPENDS web/src/*)
add_custom_command(OUTPUT ${THZ_WEB_DIR}/index.html ${THZ_WEB_DIR}/assets/app.js
                          ${THZ_WEB_DIR}/assets/app.css
  COMMAND ${THZ_NODE} ${CMAKE_SOURCE_DIR}/web/build.mjs ${THZ_WEB_NPM_DIR}/node_modules
          ${THZ_WEB_DIR}
  DEPENDS ${THZ_WEB_NPM_DIR}/npm-ci.stamp ${CMAKE_SOURCE_DIR}/web/build.mjs ${THZ_WEB_SOURCES}
  COMMENT "esbuild: the web page into ${THZ_WEB_DIR}")
add_custom_target(web_bundle ALL DEPENDS ${THZ_WEB_DIR}/index.html)
install(DIRECTORY ${THZ_WEB_DIR}/ DESTINATION ${THZ_INSTALL_DATADIR}/web)

# The end-to-end test: headless Chromium (Debian's chromium and chromium-driver) driven by
# Selenium (python3-selenium) against a real `thzmap serve`. Release build only: the
# sanitizers would time the page, not check it.
# test_e2e.py: the paper's session; test_e2e_audit.py: what audits of the page found.
if(NOT THZ_SANITIZE)
  foreach(name test_e2e test_e2e_audit)
    add_test(NAME gui/${name}
      COMMAND /usr/bin/python3 ${CMAKE_SOURCE_DIR}/tests/gui/${name}.py
              $<TARGET_FILE:thzmap_cli> ${CMAKE_SOURCE_DIR} ${CMAKE_BINARY_DIR}/gui-screenshots)
    set_tests_properties(gui/${name} PROPERTIES LABELS "gui;no-sanitizer" TIMEOUT 300
      ENVIRONMENT "PYTHONDONTWRITEBYTECODE=1")
  endforeach()
endif()
