#!/usr/bin/env bash
# Installs the Debian 12 packages PoroMPM builds and tests with. Idempotent: packages already present
# are skipped, and apt is only touched when something is missing. Run as root (or with sudo available).
set -euo pipefail

packages=(
  build-essential pkg-config
  libjansson-dev        # JSON everywhere (case files, API)
  libsuitesparse-dev    # CHOLMOD (pressure Poisson), UMFPACK (u-p-U)
  libhdf5-dev hdf5-tools  # results; h5dump for inspecting
  libmicrohttpd-dev     # server HTTP
  libsqlite3-dev        # server store
  libcurl4-openssl-dev  # worker and CLI HTTP client
  python3               # test harness helpers
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
