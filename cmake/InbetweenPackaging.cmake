# `cpack` in a build directory: Debian packages of the programs (docs/install.md), one per install
# component: `inbetween` (component cli: the CLI, which embeds the service) and `inbetween-server`
# (component server: the gRPC server and its load generator). The libraries, headers and CMake
# package (component dev) are for `cmake --install` and are not packaged.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME inbetween)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "Inbetween")
set(INBETWEEN_PACKAGE_MAINTAINER
    "Inbetween maintainers <maintainers@users.noreply.h-seed-3a379adf.example>"
    CACHE STRING "Maintainer field of the Debian packages")
set(CPACK_PACKAGE_CONTACT "${INBETWEEN_PACKAGE_MAINTAINER}")
set(CPACK_COMPONENTS_ALL cli server)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # <package>_<version>-<release>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_RELEASE 1)
# The build type keeps debug info (RelWithDebInfo); the packaged programs are stripped.
set(CPACK_STRIP_FILES ON)
# Depends from the shared libraries the programs load, as dpkg-shlibdeps maps them to Debian
# packages: exact for the machine the packages are built on (Debian 12 here), nothing to keep in
# step by hand. cmake/InbetweenCPackChecks.cmake refuses to package without dpkg-shlibdeps.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_PROJECT_CONFIG_FILE ${CMAKE_CURRENT_LIST_DIR}/InbetweenCPackChecks.cmake)
# dpkg-shlibdeps names any libblas.so.3 provider; the supernodal CHOLMOD factorization is meant to
# run on the pthread OpenBLAS (scripts/setup installs it as the system BLAS).
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS libopenblas0-pthread)

# Descriptions: the synopsis, then the extended text in lines under 80 columns (CPack indents
# them by one space, as the control file wants).
set(CPACK_DEBIAN_CLI_PACKAGE_NAME inbetween)
set(CPACK_DEBIAN_CLI_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_CLI_DESCRIPTION
"smooth 2D inbetween frames from a few key drawings
The inbetween command line: give it 2 to 16 SVG key drawings of a character
and it writes inbetween frames that never fold over (SVG, PNG, GIF, WebP,
Lottie JSON). It runs the Inbetween service in-process, or talks gRPC to an
inbetween-server with --server.")
set(CPACK_DEBIAN_SERVER_PACKAGE_NAME inbetween-server)
set(CPACK_DEBIAN_SERVER_PACKAGE_SECTION net)
set(CPACK_DEBIAN_SERVER_DESCRIPTION
"gRPC service computing 2D inbetween frames from key drawings
inbetween-server serves the Inbetween gRPC API (sessions of key drawings,
multimesh, comesh optimization, streamed frames), with sessions in memory, a
directory or Redis, bearer tokens, TLS and Prometheus metrics.
inbetween-loadgen runs virtual studios against a server or a proxy of
replicas.")

include(CPack)
