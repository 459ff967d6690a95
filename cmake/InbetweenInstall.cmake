# `cmake --install`: the programs, the public headers, the static libraries and an exported CMake
# package (find_package(Inbetween) -> Inbetween::client, Inbetween::solver, ...), docs/install.md.
# Included from the top-level CMakeLists.txt after every target is defined. The targets keep their
# build-tree definitions; this file only adds what an export needs (names, include and link
# interfaces that do not point into the build machine's trees), so it is the one place to read.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# Headers go under include/inbetween/ with the paths the sources use ("solver/core/types.h",
# "client/inbetween_client.h", "inbetween/v1/inbetween.pb.h"): the generic top-level names
# (solver/, client/, server/) stay out of the shared include directory.
set(INBETWEEN_INSTALL_INCLUDEDIR ${CMAKE_INSTALL_INCLUDEDIR}/inbetween)
set(INBETWEEN_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/Inbetween)

# Exported libraries, as "target:name under Inbetween::". The client links the service library
# publicly (the CLI embeds the service in-process) and the renderer, so both are exported with it.
set(INBETWEEN_EXPORTED_TARGETS
  inbetween_proto:proto inbetween_solver:solver inbetween_render:render
  inbetween_server_lib:server inbetween_client_lib:client)

# Libraries the targets link by absolute path (find_library results: CHOLMOD, KLU, gif, ...). In
# the export each becomes Inbetween::lib_<name>, an imported target that InbetweenConfig.cmake
# creates with find_library on the consumer's machine, so a missing -dev package is reported by
# find_package instead of as a missing file at link time.
set(INBETWEEN_EXPORTED_SYSTEM_LIBS "")
# Namespaced targets the exported link interfaces may name; InbetweenConfig.cmake.in finds each
# namespace's package (PkgConfig:: by the same pkg_check_modules calls as this build).
set(INBETWEEN_CONFIG_NAMESPACES Eigen3 absl spdlog nlohmann_json CGAL Threads prometheus-cpp
    PkgConfig)
# "PREFIX modules..." as in the pkg_check_modules calls of CMakeLists.txt, server/ and
# client/render/.
set(INBETWEEN_CONFIG_PKGCONFIG "PROTOBUF protobuf" "GRPCPP grpc++" "LIBXML2 libxml-2.0"
    "POLYCLIPPING polyclipping" "HIREDIS hiredis" "CAIRO cairo" "WEBP libwebp libwebpmux libwebpdemux")
set(INBETWEEN_CONFIG_PKGCONFIG_TARGETS "")
set(INBETWEEN_CONFIG_PKGCONFIG_ITEMS "")  # quoted, for InbetweenConfig.cmake.in
foreach(modules IN LISTS INBETWEEN_CONFIG_PKGCONFIG)
  string(REGEX REPLACE " .*" "" prefix "${modules}")
  list(APPEND INBETWEEN_CONFIG_PKGCONFIG_TARGETS PkgConfig::${prefix})
  string(APPEND INBETWEEN_CONFIG_PKGCONFIG_ITEMS " \"${modules}\"")
endforeach()

function(inbetween_exportable_link_item item out)
  set(wrapper "")
  set(inner "${item}")
  if(item MATCHES "^\\$<LINK_ONLY:(.*)>$")
    set(wrapper LINK_ONLY)
    set(inner "${CMAKE_MATCH_1}")
  endif()
  if(IS_ABSOLUTE "${inner}" AND inner MATCHES "/lib([^/]+)\\.(so|a)$")
    set(name "${CMAKE_MATCH_1}")
    set(INBETWEEN_EXPORTED_SYSTEM_LIBS ${INBETWEEN_EXPORTED_SYSTEM_LIBS} ${name} PARENT_SCOPE)
    set(inner "$<BUILD_INTERFACE:${inner}>$<INSTALL_INTERFACE:Inbetween::lib_${name}>")
  elseif(inner MATCHES "^([A-Za-z0-9_-]+)::")
    if(NOT CMAKE_MATCH_1 IN_LIST INBETWEEN_CONFIG_NAMESPACES OR
       (CMAKE_MATCH_1 STREQUAL "PkgConfig" AND NOT inner IN_LIST INBETWEEN_CONFIG_PKGCONFIG_TARGETS))
      message(FATAL_ERROR "${inner} is in the link interface of an exported Inbetween target: "
                          "make cmake/InbetweenConfig.cmake.in find it and list it in "
                          "cmake/InbetweenInstall.cmake")
    endif()
  endif()
  if(wrapper)
    set(inner "$<${wrapper}:${inner}>")
  endif()
  set(${out} "${inner}" PARENT_SCOPE)
endfunction()

set(INBETWEEN_EXPORT_TARGET_LIST "")
foreach(pair IN LISTS INBETWEEN_EXPORTED_TARGETS)
  string(REPLACE ":" ";" pair "${pair}")
  list(GET pair 0 target)
  list(GET pair 1 name)
  list(APPEND INBETWEEN_EXPORT_TARGET_LIST ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  # The headers use C++20; consumers compile them with at least that.
  set_property(TARGET ${target} APPEND PROPERTY INTERFACE_COMPILE_FEATURES cxx_std_20)
  # Include directories are the source tree and the proto's generated directory: build-only.
  # install(TARGETS ... INCLUDES DESTINATION) below adds the installed include root.
  get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
  set(exportable "")
  foreach(dir IN LISTS dirs)
    if(IS_ABSOLUTE "${dir}")
      list(APPEND exportable "$<BUILD_INTERFACE:${dir}>")
    else()
      list(APPEND exportable "${dir}")
    endif()
  endforeach()
  set_target_properties(${target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${exportable}")
  get_target_property(links ${target} INTERFACE_LINK_LIBRARIES)
  set(exportable "")
  foreach(item IN LISTS links)
    inbetween_exportable_link_item("${item}" item)
    list(APPEND exportable "${item}")
  endforeach()
  set_target_properties(${target} PROPERTIES INTERFACE_LINK_LIBRARIES "${exportable}")
endforeach()
list(REMOVE_DUPLICATES INBETWEEN_EXPORTED_SYSTEM_LIBS)

# Programs, one Debian package each (cmake/InbetweenPackaging.cmake): the CLI alone in `cli`; the
# server with its load generator in `server`, as in the server container image (docker/Dockerfile).
install(TARGETS inbetween RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT cli)
install(TARGETS inbetween-server inbetween-loadgen
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT server)

# Libraries, headers and the CMake package: component `dev` (not packaged as a .deb).
install(TARGETS ${INBETWEEN_EXPORT_TARGET_LIST} EXPORT InbetweenTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
        INCLUDES DESTINATION ${INBETWEEN_INSTALL_INCLUDEDIR})

# Every header of the libraries' directories, at its path relative to the include root.
function(inbetween_install_headers root)
  foreach(header IN LISTS ARGN)
    file(RELATIVE_PATH rel ${root} ${header})
    get_filename_component(rel_dir ${rel} DIRECTORY)
    install(FILES ${header} DESTINATION ${INBETWEEN_INSTALL_INCLUDEDIR}/${rel_dir} COMPONENT dev)
  endforeach()
endfunction()
file(GLOB_RECURSE solver_headers CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/solver/*.h)
# client/ minus its non-C++ subprojects (python/, web/ with node_modules/): only client/render/.
file(GLOB client_headers CONFIGURE_DEPENDS
     ${PROJECT_SOURCE_DIR}/client/*.h ${PROJECT_SOURCE_DIR}/client/render/*.h)
file(GLOB server_headers CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/server/*.h)
inbetween_install_headers(${PROJECT_SOURCE_DIR} ${solver_headers} ${client_headers} ${server_headers})
# The generated proto headers, relative to the proto target's generated include directory; the
# .proto itself beside them (as protobuf's own packages do), for clients in other languages.
get_target_property(proto_sources inbetween_proto SOURCES)
get_target_property(proto_gen_dir inbetween_proto INCLUDE_DIRECTORIES)
list(GET proto_gen_dir 0 proto_gen_dir)
list(FILTER proto_sources INCLUDE REGEX "\\.h$")
inbetween_install_headers(${proto_gen_dir} ${proto_sources})
install(FILES ${PROJECT_SOURCE_DIR}/proto/inbetween/v1/inbetween.proto
        DESTINATION ${INBETWEEN_INSTALL_INCLUDEDIR}/inbetween/v1 COMPONENT dev)

install(EXPORT InbetweenTargets NAMESPACE Inbetween:: DESTINATION ${INBETWEEN_INSTALL_CMAKEDIR}
        COMPONENT dev)
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/InbetweenConfig.cmake.in
  ${PROJECT_BINARY_DIR}/cmake/InbetweenConfig.cmake INSTALL_DESTINATION ${INBETWEEN_INSTALL_CMAKEDIR})
# 0.x: a minor version may change the API, so only the same minor version is compatible.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cmake/InbetweenConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cmake/InbetweenConfig.cmake
              ${PROJECT_BINARY_DIR}/cmake/InbetweenConfigVersion.cmake
        DESTINATION ${INBETWEEN_INSTALL_CMAKEDIR} COMPONENT dev)
# This file runs in the top-level scope: drop its loop variables before tests/ is added.
unset(pair)
unset(target)
unset(name)
unset(dirs)
unset(links)
unset(item)
unset(exportable)
unset(modules)
unset(prefix)
