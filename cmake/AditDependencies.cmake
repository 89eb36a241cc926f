# Every third-party dependency comes from a Debian package installed by
# scripts/install-deps.sh; nothing is downloaded at configure or build time.

find_package(Threads REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(Ceres 2.1 REQUIRED)  # the loop-closure pose graph (slam/pose_graph_solver.cpp)
find_package(yaml-cpp REQUIRED)
find_package(fmt REQUIRED)
find_package(spdlog REQUIRED)
find_package(CLI11 REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
# Ray casting for the simulator (Debian libembree-dev); the target is `embree`.
find_package(embree 3 REQUIRED)
# MD5 for the Ouster digest (libssl-dev): a vetted implementation beats our own.
find_package(OpenSSL 3 REQUIRED COMPONENTS Crypto)
find_package(ZLIB REQUIRED)  # CRC-32 of the session journal's records
find_package(PkgConfig REQUIRED)
pkg_check_modules(PCAP REQUIRED IMPORTED_TARGET libpcap)
pkg_check_modules(GPIODCXX REQUIRED IMPORTED_TARGET libgpiodcxx)
pkg_check_modules(SYSTEMD REQUIRED IMPORTED_TARGET libsystemd)
pkg_check_modules(ZSTD REQUIRED IMPORTED_TARGET libzstd)
# LCM (liblcm-dev) ships only a pkg-config file; its lcm-gen is found in protocol/.
pkg_check_modules(LCM REQUIRED IMPORTED_TARGET lcm)
pkg_check_modules(SODIUM REQUIRED IMPORTED_TARGET libsodium)  # command authentication (HMAC-SHA-256)
pkg_check_modules(HTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)  # adit console (Debian libcpp-httplib-dev 0.11, a compiled library)
pkg_check_modules(PROJ REQUIRED IMPORTED_TARGET proj)  # adit georef: EPSG code -> OGC WKT for LAS files (libproj-dev)
if(ADIT_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(ADIT_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()

# Where the read-only real recordings live (beside the project root). Tests
# read ADIT_SHARED_DATA from the environment first, so a checkout elsewhere can
# point at them; when neither exists the realdata tests skip with a message.
set(ADIT_SHARED_DATA_DEFAULT "${CMAKE_SOURCE_DIR}/../shared/data")
