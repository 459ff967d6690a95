# Run by cpack before packaging (CPACK_PROJECT_CONFIG_FILE). Without dpkg-shlibdeps CPack would
# write packages with no Depends at all, which install and then fail to start: refuse instead.
if(CPACK_GENERATOR STREQUAL "DEB")
  find_program(INBETWEEN_DPKG_SHLIBDEPS dpkg-shlibdeps)
  if(NOT INBETWEEN_DPKG_SHLIBDEPS)
    message(FATAL_ERROR "cpack needs dpkg-shlibdeps for the packages' Depends: apt-get install dpkg-dev")
  endif()
endif()
