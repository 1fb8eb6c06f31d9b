# ctest script: make the Debian package of a finished build with cpack, check what it holds,
# unpack it into a scratch root (dpkg-deb -x: no root needed, nothing installed on the system) and
# build the consumer of tests/install/consumer against that root twice, with find_package(autograv)
# and with `pkg-config --cflags --libs autograv`, then run what was built.
# Arguments: -DBINARY_DIR=<autograv build> -DCONSUMER_DIR=<tests/install/consumer>
#            -DWORK_DIR=<scratch> -DVERSION=<PROJECT_VERSION> -DCPACK=<cpack> -DCXX=<c++ compiler>
#            [-DWITH_TOOL=0|1: whether the `autograv` program was built]
#            [-DCONSUMER_LINK_FLAGS=<flags the consumer links with, e.g. the sanitizers>]
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
include(${CMAKE_CURRENT_LIST_DIR}/run_step.cmake)

# The package, from the build as it is: cpack installs the build (no compilation when it is up to
# date) into its own staging folder and writes the .deb to WORK_DIR.
execute_process(COMMAND "${CPACK}" -G DEB --config "${BINARY_DIR}/CPackConfig.cmake"
                        -B "${WORK_DIR}/package"
                WORKING_DIRECTORY "${BINARY_DIR}" RESULT_VARIABLE result OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "cpack -G DEB failed:\n${out}\n${err}")
endif()
file(GLOB debs "${WORK_DIR}/package/*.deb")
list(LENGTH debs deb_count)
if(NOT deb_count EQUAL 1)
  message(FATAL_ERROR "cpack made ${deb_count} .deb files, not one: ${debs}\n${out}")
endif()
get_filename_component(deb_name "${debs}" NAME)
if(NOT deb_name MATCHES "^autograv_${VERSION}_[a-z0-9]+\\.deb$")
  message(FATAL_ERROR "the package is ${deb_name}, not autograv_${VERSION}_<arch>.deb")
endif()
message(STATUS "package: ${deb_name}")

# Its control fields: name, the CMake version, and Depends with Eigen (the headers' one public
# dependency) and, when there are programs, the libraries dpkg-shlibdeps found they link.
run(dpkg-deb -f "${debs}" Package Version Depends)
message(STATUS "control fields:\n${run_stdout}")
set(expected_fields "Package: autograv" "Version: ${VERSION}" "Depends: libeigen3-dev")
if(WITH_TOOL)
  list(APPEND expected_fields "libstdc\\+\\+6")
endif()
foreach(field ${expected_fields})
  if(NOT run_stdout MATCHES "${field}")
    message(FATAL_ERROR "no '${field}' in the package's control fields:\n${run_stdout}")
  endif()
endforeach()

# What it holds: the library, the headers, the CMake package, the pkg-config files, the program.
run(dpkg-deb -c "${debs}")
set(contents "${run_stdout}")
set(expected_files
  "/usr/lib/([^ /]+/)?libautograv_core\\.a"
  "/usr/lib/([^ /]+/)?libautograv_sim\\.a"
  "/usr/include/autograv/map/gravity_map\\.h"
  "/usr/include/autograv/compensation/gravity_compensated_device\\.h"
  "/usr/include/autograv/version\\.h"
  "/usr/lib/([^ /]+/)?cmake/autograv/autogravConfig\\.cmake"
  "/usr/lib/([^ /]+/)?cmake/autograv/autogravConfigVersion\\.cmake"
  "/usr/lib/([^ /]+/)?cmake/autograv/autogravTargets\\.cmake"
  "/usr/lib/([^ /]+/)?pkgconfig/autograv\\.pc"
  "/usr/lib/([^ /]+/)?pkgconfig/autograv-sim\\.pc")
if(WITH_TOOL)
  list(APPEND expected_files "/usr/bin/autograv")
endif()
foreach(file ${expected_files})
  if(NOT contents MATCHES "\\.${file}\n")
    string(REPLACE "\\" "" shown "${file}")
    message(FATAL_ERROR "the package holds no ${shown}:\n${contents}")
  endif()
endforeach()
if(contents MATCHES "/usr/local/")
  message(FATAL_ERROR "the package installs under /usr/local:\n${contents}")
endif()

set(root "${WORK_DIR}/root")
run(dpkg-deb -x "${debs}" "${root}")

# 1. CMake: find_package(autograv) with the scratch root's /usr as prefix, as /usr is found once the
#    package is installed.
run(${CMAKE_COMMAND} -S "${CONSUMER_DIR}" -B "${WORK_DIR}/cmake_consumer"
    "-DCMAKE_PREFIX_PATH=${root}/usr" "-DCMAKE_EXE_LINKER_FLAGS=${CONSUMER_LINK_FLAGS}")
file(STRINGS "${WORK_DIR}/cmake_consumer/CMakeCache.txt" autograv_dir REGEX "^autograv_DIR:")
string(FIND "${autograv_dir}" "=${root}/usr/lib/" at)
if(at EQUAL -1)
  message(FATAL_ERROR "find_package(autograv) found another autograv than the package's: "
                      "${autograv_dir}")
endif()
run(${CMAKE_COMMAND} --build "${WORK_DIR}/cmake_consumer")
run("${WORK_DIR}/cmake_consumer/consumer")
message(STATUS "find_package(autograv) consumer built against the package and ran")

# 2. pkg-config: the scratch root as a sysroot (PKG_CONFIG_SYSROOT_DIR prefixes the package's /usr
#    paths with it). A sysroot holds the package's dependencies too: Eigen's headers, linked from
#    this system's.
file(GLOB pc_files "${root}/usr/lib/pkgconfig/autograv.pc" "${root}/usr/lib/*/pkgconfig/autograv.pc")
list(LENGTH pc_files pc_count)
if(NOT pc_count EQUAL 1)
  message(FATAL_ERROR "not one autograv.pc in ${root}: ${pc_files}")
endif()
get_filename_component(pc_dir "${pc_files}" DIRECTORY)
run(pkg-config --cflags-only-I eigen3)
separate_arguments(eigen_flags UNIX_COMMAND "${run_stdout}")
foreach(flag ${eigen_flags})
  string(REGEX REPLACE "^-I" "" eigen_dir "${flag}")
  get_filename_component(eigen_parent "${root}${eigen_dir}" DIRECTORY)
  file(MAKE_DIRECTORY "${eigen_parent}")
  file(CREATE_LINK "${eigen_dir}" "${root}${eigen_dir}" SYMBOLIC)
endforeach()
set(ENV{PKG_CONFIG_PATH} "${pc_dir}")
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${root}")
run(pkg-config --modversion autograv)
string(STRIP "${run_stdout}" pc_version)
if(NOT pc_version STREQUAL VERSION)
  message(FATAL_ERROR "pkg-config --modversion autograv says ${pc_version}, CMake ${VERSION}")
endif()
run(pkg-config --libs autograv-sim)
if(NOT run_stdout MATCHES "-lautograv_sim .*-lautograv_core")
  message(FATAL_ERROR "pkg-config --libs autograv-sim: ${run_stdout}")
endif()
run(pkg-config --cflags --libs autograv)
string(STRIP "${run_stdout}" pc_flags)
message(STATUS "pkg-config --cflags --libs autograv: ${pc_flags}")
string(FIND " ${pc_flags} " " -I${root}/usr/include " include_at)
if(include_at EQUAL -1 OR NOT pc_flags MATCHES "-lautograv_core")
  message(FATAL_ERROR "pkg-config --cflags --libs autograv does not point into the package: "
                      "${pc_flags}")
endif()
separate_arguments(pc_flags UNIX_COMMAND "${pc_flags}")
separate_arguments(link_flags UNIX_COMMAND "${CONSUMER_LINK_FLAGS}")
run("${CXX}" -std=c++17 "${CONSUMER_DIR}/main.cpp" -o "${WORK_DIR}/pkg_config_consumer"
    ${pc_flags} ${link_flags})
run("${WORK_DIR}/pkg_config_consumer")
message(STATUS "pkg-config consumer built against the package and ran")

# 3. The command line from the package says the version CMake does.
if(WITH_TOOL)
  run("${root}/usr/bin/autograv" --version)
  if(NOT run_output MATCHES "autograv ${VERSION}")
    message(FATAL_ERROR "the packaged autograv --version says: ${run_output}")
  endif()
endif()
message(STATUS "${deb_name}: contents, find_package and pkg-config consumers checked")
