#!/usr/bin/env bash
# Installs what swarmsim needs to build and test, from Debian's packages,
# then the viewer page's JavaScript packages (three, fzstd, esbuild) from npm
# with its lockfile (swarm/viewer/web). Idempotent: does nothing when every
# package is already installed.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config ccache clang-format git
  libbox2d-dev libode-dev libfcl-dev liboctomap-dev liblua5.4-dev libtbb-dev
  libosmesa6-dev libyaml-cpp-dev libeigen3-dev libsqlite3-dev libxxhash-dev libzstd-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libompl-dev
  gnuplot-nox libopenmpi-dev openmpi-bin
  libpng-dev libassimp-dev liburdfdom-dev libtinyxml2-dev
  libavcodec-dev libavformat-dev libavutil-dev libswscale-dev
  pybind11-dev python3-dev python3-numpy
  libcpp-httplib-dev nodejs chromium chromium-driver
)
# Debian's nodejs comes without npm (another source's nodejs may bring its own).
command -v npm >/dev/null 2>&1 || packages+=(npm)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -gt 0 ]; then
  echo "swarmsim setup: installing ${missing[*]}"
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then sudo="sudo"; else
      echo "swarmsim setup: need root (or sudo) to install: ${missing[*]}" >&2
      exit 1
    fi
  fi
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  echo "swarmsim setup: done"
fi

# The viewer page's packages, exactly as the lockfile says (no browser
# download: the browser tests use Debian's chromium).
web="$(cd "$(dirname "$0")/.." && pwd)/swarm/viewer/web"
if [ ! -f "$web/node_modules/.package-lock.json" ] ||
   [ "$web/package-lock.json" -nt "$web/node_modules/.package-lock.json" ]; then
  echo "swarmsim setup: npm ci in swarm/viewer/web"
  (cd "$web" && npm ci --no-audit --no-fund --loglevel=error)
fi
