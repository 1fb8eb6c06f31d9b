# ctest script: install autograv into a fresh prefix, then configure, build and run a consumer
# project that only does find_package(autograv) and links autograv::core.
# Arguments: -DBINARY_DIR=<autograv build> -DSOURCE_DIR=<tests/install/consumer> -DWORK_DIR=<scratch>
#            [-DCONSUMER_LINK_FLAGS=<flags the consumer links with, e.g. the sanitizers>]
#            [-DWITH_CHAI3D=1: autograv was built with the CHAI3D bridge; build its consumer too]
#            [-DWITH_VIZ=0|1 -DWITH_GL=0|1: whether autograv::viz and autograv::gl were built]
#            [-DEXAMPLE_DIR=<demo/examples/own_device>: also build that example against the
#             install, with warnings as errors, calibrate with it and use its map]
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
include(${CMAKE_CURRENT_LIST_DIR}/run_step.cmake)
run(${CMAKE_COMMAND} --install "${BINARY_DIR}" --prefix "${WORK_DIR}/prefix" --component Unspecified)
# Each component installs its own headers and no other's: none for a library that was not built,
# and the device registry's header only with the registry.
foreach(component viz gl)
  string(TOUPPER ${component} upper)
  if(DEFINED WITH_${upper})
    set(headers "${WORK_DIR}/prefix/include/autograv/${component}")
    if(WITH_${upper} AND NOT IS_DIRECTORY "${headers}")
      message(FATAL_ERROR "autograv::${component} was built but installed no headers")
    elseif(NOT WITH_${upper} AND EXISTS "${headers}")
      message(FATAL_ERROR "autograv::${component} was not built, yet ${headers} was installed")
    endif()
  endif()
endforeach()
file(GLOB installed_registry "${WORK_DIR}/prefix/lib*/libautograv_devices.*"
     "${WORK_DIR}/prefix/lib*/*/libautograv_devices.*")
if(EXISTS "${WORK_DIR}/prefix/include/autograv/devices/device_registry.h" AND NOT installed_registry)
  message(FATAL_ERROR "autograv/devices/device_registry.h was installed without its library")
endif()
# The installed headers are the API only: one folder per concept, error.h and version.h beside
# them, and none of the internals that live in plugin/src (the estimation's inner loop, the
# research harness of the simulators).
set(include_dir "${WORK_DIR}/prefix/include/autograv")
file(GLOB flat_headers RELATIVE "${include_dir}" "${include_dir}/*.h")
list(SORT flat_headers)
if(NOT flat_headers STREQUAL "error.h;version.h")
  message(FATAL_ERROR "headers outside the folders of include/autograv: ${flat_headers}")
endif()
foreach(internal estimation/vertex_estimator.h estimation/steady_state_detector.h
                 estimation/minimum_jerk_move.h sim/experiments.h)
  if(EXISTS "${include_dir}/${internal}")
    message(FATAL_ERROR "an internal header was installed: autograv/${internal}")
  endif()
endforeach()
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}" -B "${WORK_DIR}/build" "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix"
    "-DCMAKE_EXE_LINKER_FLAGS=${CONSUMER_LINK_FLAGS}" "-DCONSUMER_WITH_CHAI3D=${WITH_CHAI3D}")
run(${CMAKE_COMMAND} --build "${WORK_DIR}/build")
run("${WORK_DIR}/build/consumer")
if(WITH_CHAI3D)
  run("${WORK_DIR}/build/consumer_chai3d")
endif()
if(EXAMPLE_DIR)
  run(${CMAKE_COMMAND} -S "${EXAMPLE_DIR}" -B "${WORK_DIR}/own_device"
      "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix" -DCMAKE_BUILD_TYPE=Release
      "-DCMAKE_CXX_FLAGS=-Wall -Wextra -Wpedantic -Werror"
      "-DCMAKE_EXE_LINKER_FLAGS=${CONSUMER_LINK_FLAGS}")
  run(${CMAKE_COMMAND} --build "${WORK_DIR}/own_device")
  # The calibrating program, then the application that uses its map.
  set(example_map "${WORK_DIR}/own_device_map.json")
  run("${WORK_DIR}/own_device/own_device" "${example_map}")
  message(STATUS "own_device example:\n${run_output}")
  if(NOT run_output MATCHES "\\[8/8\\] Done" OR NOT run_output MATCHES "saved .*own_device_map")
    message(FATAL_ERROR "the own_device example did not calibrate to the end:\n${run_output}")
  endif()
  if(NOT EXISTS "${example_map}")
    message(FATAL_ERROR "the own_device example saved no map")
  endif()
  run("${WORK_DIR}/own_device/use_map" "${example_map}")
  message(STATUS "use_map example:\n${run_output}")
  if(NOT run_output MATCHES "workspace: median [0-9.]+ mN, max [0-9.]+ mN")
    message(FATAL_ERROR "the use_map example did not use the map:\n${run_output}")
  endif()
endif()
message(STATUS "consumer built against ${WORK_DIR}/prefix and ran")
