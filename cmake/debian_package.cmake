# The Debian package: in a build tree, `cpack -G DEB` (or plain `cpack`) writes
# autograv_<version>_<arch>.deb with what `cmake --install` installs, under /usr (the DEB
# generator's default prefix): the libraries (static archives), the public headers with
# autograv/version.h, the CMake package (lib/cmake/autograv), the pkg-config files
# (lib/pkgconfig/autograv.pc, autograv-sim.pc), the `autograv` command line, `autograv-demo` when
# autograv::gl is built, and the changelog.
# tests/install/debian_package_test.cmake builds it, unpacks it and builds a program against it.
#
# What goes in is what the build built, so a package is always coherent with its Depends:
# - The VTK and GL parts (autograv::viz, autograv::gl, autograv::image, autograv-demo) go in when
#   they are built, as they are by default: the command line's render, plot and export and the
#   real-time demo are what the README shows a user, and a package without them would be a
#   different program. Their run-time libraries (VTK, GLFW, OSMesa, libpng, X11) are not listed
#   by hand: dpkg-shlibdeps reads them off the installed programs (dpkg-dev, which
#   .ci/install-deps.sh installs). A build with -DAUTOGRAV_BUILD_VIZ=OFF -DAUTOGRAV_BUILD_GL=OFF
#   makes a package with no VTK or GL in it or in its Depends (its render, plot and export then
#   say that autograv was built without viz).
# - The libraries are static archives: an application linking autograv::core needs Eigen's
#   headers (a public dependency: Depends libeigen3-dev), nothing else. Linking the static viz,
#   gl or image archives needs the -dev packages of their private libraries: Suggests, since
#   most users link core only.
# - A build with the CHAI3D bridge (AUTOGRAV_CHAI3D_DIR) would package a bridge tied to a CHAI3D
#   tree that is not a Debian package; make packages from builds without it.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME autograv)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "The autograv project")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "autocalibrated gravity compensation for 3-DoF impedance haptic devices")
set(CPACK_PACKAGE_DESCRIPTION
    "autograv learns the position-dependent apparent gravity of a haptic device's
end-effector on a grid, then adds the interpolated map to every force an
application sends, so that the stylus floats weightless without a kinematic
model of the device. This package holds the C++17 library (static archives,
headers, CMake package and pkg-config files) and the autograv command line
that calibrates, verifies and renders gravity maps.")
# Programs and archives without their debug sections, as dh_strip makes packages (and
# plugin/CMakeLists.txt strips the archives): 0.2.0 from a RelWithDebInfo build is 2.6 MB, not 105.
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # autograv_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "The autograv project")
set(CPACK_DEBIAN_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "libeigen3-dev (>= 3.3)")
set(autograv_deb_recommends "")
set(autograv_deb_suggests "pkg-config")
if(TARGET autograv_image)
  list(APPEND autograv_deb_suggests libpng-dev)
endif()
if(TARGET autograv_viz)
  # Scene and plot text (VTK's own font lacks brackets and Greek letters); an X server for VTK.
  list(APPEND autograv_deb_recommends fonts-dejavu-core)
  list(APPEND autograv_deb_suggests xvfb libvtk9-dev mpi-default-dev libx11-dev)
endif()
if(TARGET autograv_gl)
  list(APPEND autograv_deb_suggests libglfw3-dev libosmesa6-dev)
endif()
string(REPLACE ";" ", " CPACK_DEBIAN_PACKAGE_RECOMMENDS "${autograv_deb_recommends}")
string(REPLACE ";" ", " CPACK_DEBIAN_PACKAGE_SUGGESTS "${autograv_deb_suggests}")
# include(CPack) also makes the package_source target: a tarball of the sources, without the
# build trees and outputs that .gitignore leaves out.
set(CPACK_SOURCE_GENERATOR TXZ)
set(CPACK_SOURCE_IGNORE_FILES "/\\.git/" "/\\.cache/" "/build[^/]*/" "/out/" "\\.swp$")
include(CPack)
