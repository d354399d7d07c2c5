# Finds every third-party dependency once and normalises it to one target named
# nsg::dep::<name>. Modules link these names only; nothing else calls find_*.
include_guard(GLOBAL)
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)

function(nsg_alias_pkg name module)
  pkg_check_modules(NSG_PC_${name} REQUIRED IMPORTED_TARGET ${module})
  add_library(nsg::dep::${name} ALIAS PkgConfig::NSG_PC_${name})
endfunction()

# JSON: simdjson for the big tables, nlohmann for small documents.
find_package(simdjson REQUIRED)
add_library(nsg_dep_simdjson INTERFACE)
target_link_libraries(nsg_dep_simdjson INTERFACE simdjson::simdjson)
add_library(nsg::dep::simdjson ALIAS nsg_dep_simdjson)
# simdjson's On-Demand API is compiled inline with the kernel the compiler flags allow;
# without them it is the scalar "fallback" kernel (several times slower on the big
# tables). When the build machine has AVX2/BMI2/PCLMUL (x86-64 "haswell"), the files that
# parse JSON get those flags (not FMA: no contraction of our float arithmetic). A binary
# built this way needs such a CPU; -DNSG_SIMDJSON_HASWELL=OFF builds a portable one.
include(CheckCXXSourceRuns)
check_cxx_source_runs([=[
int main() {
  __builtin_cpu_init();
  return (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("bmi2") &&
          __builtin_cpu_supports("pclmul")) ? 0 : 1;
}]=] NSG_HOST_HAS_HASWELL)
option(NSG_SIMDJSON_HASWELL "Compile JSON parsing for AVX2/BMI2/PCLMUL CPUs" ${NSG_HOST_HAS_HASWELL})
if(NSG_SIMDJSON_HASWELL)
  target_compile_options(nsg_dep_simdjson INTERFACE -mavx2 -mbmi -mbmi2 -mlzcnt -mpclmul)
endif()

find_package(nlohmann_json 3.10 REQUIRED)
add_library(nsg::dep::json ALIAS nlohmann_json::nlohmann_json)

find_package(CLI11 REQUIRED)
add_library(nsg_dep_cli11 INTERFACE)
target_link_libraries(nsg_dep_cli11 INTERFACE CLI11::CLI11)
add_library(nsg::dep::cli11 ALIAS nsg_dep_cli11)

find_package(Eigen3 3.3 REQUIRED NO_MODULE)
add_library(nsg::dep::eigen ALIAS Eigen3::Eigen)

nsg_alias_pkg(crypto libcrypto)
nsg_alias_pkg(turbojpeg libturbojpeg)
nsg_alias_pkg(jpeg libjpeg)  # libjpeg-turbo's libjpeg API: decoding a band of rows
nsg_alias_pkg(png libpng)
nsg_alias_pkg(tiff libtiff-4)
nsg_alias_pkg(archive libarchive)
nsg_alias_pkg(geographiclib geographiclib)

# libgeotiff ships neither a pkg-config file nor a CMake config on Debian 12.
find_path(NSG_GEOTIFF_INCLUDE geotiff.h PATH_SUFFIXES geotiff REQUIRED)
find_library(NSG_GEOTIFF_LIB NAMES geotiff REQUIRED)
add_library(nsg_dep_geotiff INTERFACE)
target_include_directories(nsg_dep_geotiff INTERFACE ${NSG_GEOTIFF_INCLUDE})
target_link_libraries(nsg_dep_geotiff INTERFACE ${NSG_GEOTIFF_LIB} nsg::dep::tiff)
add_library(nsg::dep::geotiff ALIAS nsg_dep_geotiff)

find_package(OpenCV REQUIRED COMPONENTS core imgproc imgcodecs ml ximgproc dnn)
# OpenCV's dnn module (ONNX models, `nsgraph segment`) only where it is used: lib/segment.
set(NSG_OPENCV_LIBS ${OpenCV_LIBS})
list(REMOVE_ITEM NSG_OPENCV_LIBS opencv_dnn)
add_library(nsg_dep_opencv INTERFACE)
target_include_directories(nsg_dep_opencv INTERFACE ${OpenCV_INCLUDE_DIRS})
target_link_libraries(nsg_dep_opencv INTERFACE ${NSG_OPENCV_LIBS})
add_library(nsg::dep::opencv ALIAS nsg_dep_opencv)
add_library(nsg_dep_opencv_dnn INTERFACE)
target_link_libraries(nsg_dep_opencv_dnn INTERFACE nsg::dep::opencv opencv_dnn)
add_library(nsg::dep::opencv_dnn ALIAS nsg_dep_opencv_dnn)

# PCL, for `export-cloud` only (one .cpp in lib/pipeline). Its CMake config drags in VTK,
# OpenNI and Boost targets; we take only the two libraries and the include folders used.
# QUIET: its config warns about optional pcap/png grabbers we do not use.
find_package(PCL 1.10 QUIET COMPONENTS common io)
if(NOT PCL_FOUND)
  message(FATAL_ERROR "PCL (common, io) not found: install libpcl-dev (cmake/debian-packages.txt)")
endif()
add_library(nsg_dep_pcl INTERFACE)
target_include_directories(nsg_dep_pcl SYSTEM INTERFACE ${PCL_ROOT}/include/pcl-${PCL_VERSION_MAJOR}.${PCL_VERSION_MINOR})
target_link_libraries(nsg_dep_pcl INTERFACE ${PCL_COMMON_LIBRARY} ${PCL_IO_LIBRARY} nsg::dep::eigen)
add_library(nsg::dep::pcl ALIAS nsg_dep_pcl)

# valijson is header-only; its nlohmann adapter is what we use.
find_path(NSG_VALIJSON_INCLUDE valijson/validator.hpp REQUIRED)
add_library(nsg_dep_valijson INTERFACE)
target_include_directories(nsg_dep_valijson INTERFACE ${NSG_VALIJSON_INCLUDE})
target_link_libraries(nsg_dep_valijson INTERFACE nsg::dep::json)
add_library(nsg::dep::valijson ALIAS nsg_dep_valijson)

if(NSG_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(NSG_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()
