# Finds every dependency up front and fails early, naming the Debian package
# to install (scripts/install-deps.sh installs them all).

set(_articula_missing "")
macro(articula_require found_var package)
  if(NOT ${found_var})
    list(APPEND _articula_missing ${package})
  endif()
endmacro()

find_package(Eigen3 3.4 QUIET NO_MODULE)
articula_require(Eigen3_FOUND libeigen3-dev)

find_package(Threads REQUIRED)
find_package(OpenSSL QUIET)
articula_require(OpenSSL_FOUND libssl-dev)

find_package(CLI11 QUIET CONFIG)
articula_require(CLI11_FOUND libcli11-dev)

find_package(nlohmann_json 3 QUIET CONFIG)
articula_require(nlohmann_json_FOUND nlohmann-json3-dev)

# Plain find_package(NLopt) finds the C-only build; the C++ one lives here.
# A cache from a configure that ran before the package was installed may
# hold the C-only folder: replace it.
if(NOT NLopt_DIR MATCHES "nlopt_cxx/?$")
  set(NLopt_DIR /usr/lib/x86_64-linux-gnu/cmake/nlopt_cxx CACHE PATH "NLopt C++ config" FORCE)
endif()
find_package(NLopt QUIET CONFIG)
articula_require(NLopt_FOUND libnlopt-cxx-dev)

# The multibody engine of lib/dynamics (and a measured contact peer).
find_package(Simbody QUIET CONFIG)
articula_require(Simbody_FOUND libsimbody-dev)

find_package(ITK 5.2 QUIET)
articula_require(ITK_FOUND libinsighttoolkit5-dev)

# Without a component list VTK looks for Qt5 development files.
find_package(VTK 9.1 QUIET COMPONENTS CommonCore CommonDataModel CommonTransforms
  FiltersCore FiltersGeneral FiltersModeling IOXML IOXMLParser IOGeometry IOPLY IOLegacy)
articula_require(VTK_FOUND libvtk9-dev)

# Boost.Math (headers only): the chi-square and binomial distributions of
# the model selection's tests.
find_package(Boost 1.74 QUIET)
articula_require(Boost_FOUND libboost-dev)

set(CGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE TRUE)
find_package(CGAL QUIET)
articula_require(CGAL_FOUND libcgal-dev)

if(ARTICULA_BUILD_TESTS)
  find_package(GTest QUIET CONFIG)
  articula_require(GTest_FOUND libgtest-dev)
endif()
if(ARTICULA_BUILD_BENCH)
  find_package(benchmark QUIET CONFIG)
  articula_require(benchmark_FOUND libbenchmark-dev)
  # Measured peers for the contact benchmarks.
  find_package(fcl QUIET CONFIG)
  articula_require(fcl_FOUND libfcl-dev)
  find_package(ccd QUIET CONFIG)
  articula_require(ccd_FOUND libccd-dev)
  find_package(PkgConfig QUIET)
  if(PkgConfig_FOUND)
    pkg_check_modules(BULLET64 QUIET IMPORTED_TARGET bullet-float64)
  endif()
  articula_require(BULLET64_FOUND libbullet-dev)
endif()

if(_articula_missing)
  list(REMOVE_DUPLICATES _articula_missing)
  string(REPLACE ";" " " _pkgs "${_articula_missing}")
  message(FATAL_ERROR
    "articula: missing Debian packages: ${_pkgs}\n"
    "Install them with: bash scripts/install-deps.sh  (or: sudo apt-get install ${_pkgs})")
endif()
