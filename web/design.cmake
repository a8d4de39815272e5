# The playground's design (issue 55): design/ compiled into the module with NLopt built from its source,
# when that source is at hand -- PLATE_WEB_NLOPT_SOURCE (an unpacked NLopt), else Debian's source package
# fetched once into build/web/nlopt-source by fetch_nlopt.sh. Optional: where it cannot be fetched (no
# network, no deb-src), the module is built without it, answers a design request by saying so, and the
# page says so too; nothing else changes. A failed fetch is not tried again until build/web/nlopt-fetch.failed
# is removed (each build of `web` configures again).
set(PLATE_WEB_NLOPT_SOURCE "" CACHE PATH "an unpacked NLopt source (empty: Debian's source package, fetched into the build tree)")
set(nlopt_source ${PLATE_WEB_NLOPT_SOURCE})
if(NOT nlopt_source)
  set(nlopt_source ${CMAKE_CURRENT_BINARY_DIR}/nlopt-source)
  set(failed ${CMAKE_CURRENT_BINARY_DIR}/nlopt-fetch.failed)
  if(NOT EXISTS ${nlopt_source}/CMakeLists.txt AND NOT EXISTS ${failed})
    message(STATUS "plate web: fetching NLopt's Debian source package (web/fetch_nlopt.sh)")
    execute_process(COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/fetch_nlopt.sh ${nlopt_source} ${CMAKE_CURRENT_BINARY_DIR}/nlopt-fetch
                    RESULT_VARIABLE fetched OUTPUT_VARIABLE said ERROR_VARIABLE complaint TIMEOUT 600)
    if(NOT fetched EQUAL 0)
      file(WRITE ${failed} "web/fetch_nlopt.sh: ${fetched}\n${complaint}")
      message(STATUS "plate web: NLopt's source could not be fetched (${failed} says why): no design in the playground")
    endif()
  endif()
endif()

if(EXISTS ${nlopt_source}/CMakeLists.txt)
  # NLopt as a static library, without its bindings, tests and installation rules' extras.
  foreach(off NLOPT_PYTHON NLOPT_OCTAVE NLOPT_MATLAB NLOPT_GUILE NLOPT_SWIG NLOPT_FORTRAN NLOPT_TESTS BUILD_SHARED_LIBS)
    set(${off} OFF CACHE BOOL "(the playground's NLopt)" FORCE)
  endforeach()
  add_subdirectory(${nlopt_source} ${CMAKE_CURRENT_BINARY_DIR}/nlopt EXCLUDE_FROM_ALL)
  set(design ${PLATE_ROOT}/design/src)
  target_sources(plate_web PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/plate_web_design.cpp
    ${design}/design.cpp ${design}/design_target.cpp ${design}/summary_json.cpp ${design}/search.cpp ${design}/symmetry.cpp
    ${design}/orientation_harmonics.cpp ${design}/verify.cpp ${design}/sink.cpp ${design}/line_sink.cpp ${design}/transport.cpp
    ${design}/orient.cpp ${design}/rigid_fixed_point.cpp ${design}/break_pair.cpp ${design}/robust.cpp
    ${numeric}/random_scene.cpp ${numeric}/uncertainty.cpp ${numeric}/robustness.cpp ${numeric}/robustness_sensitivity.cpp
    ${numeric}/robustness_json.cpp ${numeric}/peaks.cpp)
  target_include_directories(plate_web PRIVATE ${PLATE_ROOT}/design/include ${design})
  # (Debian's patch names the library nlopt_cxx, as its package does; upstream's is nlopt)
  if(TARGET nlopt_cxx)
    target_link_libraries(plate_web PRIVATE nlopt_cxx)
  else()
    target_link_libraries(plate_web PRIVATE nlopt)
  endif()
  message(STATUS "plate web: the design with NLopt from ${nlopt_source}")
else()
  target_sources(plate_web PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/plate_web_no_design.cpp)
endif()
