#!/usr/bin/env bash
# Installs exactly the Debian 12 packages adit needs to build and test.
# Idempotent: when everything is present it changes nothing and needs no network.
# Runs apt-get update once, only when something is missing.
set -euo pipefail

packages=(
  # toolchain
  g++ cmake ninja-build pkg-config ccache git
  # clang and its sanitizer/libFuzzer runtimes: fuzz targets (CI runs them briefly)
  clang libclang-rt-14-dev
  # libraries
  libeigen3-dev          # geometry and linear algebra
  libceres-dev           # the loop-closure pose graph
  libyaml-cpp-dev        # payload configuration
  libspdlog-dev libfmt-dev  # logging, formatting
  libcli11-dev           # command-line options of aditd and adit
  nlohmann-json3-dev     # Ouster metadata, JSON output
  libpcap-dev            # pcap replay
  libgpiod-dev           # GPIO (libgpiod v1 C++ API)
  libsystemd-dev         # sd_notify
  libzstd-dev            # map tile compression
  zlib1g-dev             # CRC-32 of the session journal's records
  libssl-dev             # MD5 for the Ouster field digests (OpenSSL EVP)
  libsodium-dev          # command authentication: HMAC-SHA-256 tags (docs/decisions/022-command-authentication.md)
  liblcm-dev liblcm-bin libglib2.0-dev  # LCM messages and lcm-gen (lcm.pc needs glib)
  liblcm-java openjdk-17-jdk-headless  # the Java bindings and client for tablet apps (protocol/java)
  libcpp-httplib-dev     # adit console's HTTP server (docs/CONSOLE.md)
  libjs-three            # three.js for the console's web app, served from /usr/share/javascript/three
  libembree-dev          # ray casting in the simulator
  libpcl-dev mpi-default-dev  # PCL GICP, the odometry benchmark's baseline (PCL's VTK config needs MPI); products' SOR filter
  liboctomap-dev         # session products: 3D occupancy by ray casting, .bt/.ot files (products/)
  libpng-dev             # session products: the top-down picture of the map (products/)
  libproj-dev            # adit georef: an EPSG code as OGC WKT in LAS files (tools/src/crs_wkt.cpp; pulls proj-data, its database)
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  libfaketime            # tests: the wall clock stepped under aditd (tests/daemon/test_clock_steps.cpp)
  chromium               # the console's browser tests: headless, driven over the DevTools protocol
  time python3           # benchmark scripts: GNU time's peak resident size, small JSON and binary reading
)
# node and npm run the browser tests (puppeteer-core, tests/console); a node
# already installed (e.g. from NodeSource) is used as it is.
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  packages+=(nodejs npm)
fi

# puppeteer-core for the browser tests, exactly as tests/console/package-lock.json pins it
# (npm ci; never run by the build). Needs the npm registry only when it is not installed yet.
install_browser_test_modules() {
  local dir
  dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/tests/console"
  if [ -d "$dir/node_modules/puppeteer-core" ] && [ "$dir/node_modules/.package-lock.json" -nt "$dir/package-lock.json" ]; then
    return 0
  fi
  echo "install-deps: npm ci in tests/console (puppeteer-core for the browser tests)"
  npm ci --prefix "$dir" --no-audit --no-fund --loglevel=error
}

if ! command -v apt-get >/dev/null 2>&1 || ! command -v dpkg-query >/dev/null 2>&1; then
  echo "install-deps: apt-get/dpkg not found: this script is for Debian 12 (bookworm)" >&2
  exit 1
fi

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages are installed"
  install_browser_test_modules
  exit 0
fi

sudo=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    sudo=(sudo)
  else
    echo "install-deps: missing ${missing[*]}; run this script as root to install them" >&2
    exit 1
  fi
fi

echo "install-deps: installing ${missing[*]}"
"${sudo[@]}" apt-get update
"${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
install_browser_test_modules
