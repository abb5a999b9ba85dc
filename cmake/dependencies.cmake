# The Debian packages the libraries link, found alike by the main project and by the fuzz
# project (fuzz/CMakeLists.txt), which links the main build's static libraries.
# OpenVDB ships its own FindTBB.cmake, which clashes with TBB's config package.
set(CMAKE_FIND_PACKAGE_PREFER_CONFIG ON)
list(APPEND CMAKE_MODULE_PATH /usr/lib/x86_64-linux-gnu/cmake/OpenVDB)

find_package(Threads REQUIRED)
find_package(TBB REQUIRED)
find_package(Eigen3 3.4 REQUIRED)
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs video calib3d)
find_package(embree 3 REQUIRED)
# Sparse occupancy grids (geometry/occupancy). A find module (module path above); it
# needs libboost-iostreams-dev and sets BUILD_SHARED_LIBS=ON in this scope.
find_package(OpenVDB REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(SQLite3 REQUIRED)  # reads COLMAP's database for --sfm colmap
find_package(PkgConfig REQUIRED)
pkg_check_modules(LIBDEFLATE REQUIRED IMPORTED_TARGET libdeflate)  # plain PNGs' inflate
# Every other PNG and every JPEG (geometry/image/codecs.h): the libraries themselves, not
# OpenCV's imgcodecs, whose ~120 dependencies every process would load at start.
pkg_check_modules(LIBPNG REQUIRED IMPORTED_TARGET libpng16)
pkg_check_modules(LIBJPEG REQUIRED IMPORTED_TARGET libjpeg)
# What the libraries and the program link of OpenCV (imgcodecs only in the tests, which
# check our codecs against it).
set(SARESGS_OPENCV_LIBS opencv_core opencv_imgproc opencv_video opencv_calib3d)
