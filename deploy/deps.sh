#!/usr/bin/env bash
# Installs the Debian 12 packages PoroMPM builds and tests with. Idempotent: packages already present
# are skipped, and apt is only touched when something is missing. Run as root (or with sudo available).
set -euo pipefail

packages=(
  build-essential pkg-config
  libjansson-dev        # JSON everywhere (case files, API)
  libsuitesparse-dev    # CHOLMOD (pressure Poisson), UMFPACK (u-p-U)
  libopenblas0-openmp   # the BLAS CHOLMOD's supernodal factor and solves run on: Debian's default
                        # is the reference BLAS, which made the pressure solve twice as slow
                        # (docs/performance.md); the OpenMP build shares our OpenMP runtime
  libhdf5-dev hdf5-tools  # results; h5dump for inspecting
  libmicrohttpd-dev     # server HTTP
  libsqlite3-dev        # server store
  sqlite3               # the sqlite3 shell, used by the service tests
  libcurl4-openssl-dev  # worker and CLI HTTP client
  python3               # test harness helpers
  python3-matplotlib python3-h5py  # poro-plot: pictures of a run from its result.h5
  python3-jsonschema    # tests/cli/schema_test.sh: the case schemas against the solver's loader
                        # (Debian 12's 4.10 knows JSON Schema draft 2020-12)
  python3-paraview      # ParaView's own XDMF readers, which tests/cli/paraview_test.sh opens
                        # result.xdmf with (no display needed: readers only)
  curl procps           # the service tests speak HTTP with curl and find processes with pgrep
  systemd               # systemd-analyze: tests/install/install_test.sh verifies the installed units
                        # (no systemd needs to run for that)
  man-db                # man -l: the same test renders the installed man pages
)

# The OpenAPI linter of make test (tools/openapi-lint, pinned in its package-lock.json) runs on
# Node.js >= 20.19; Debian's nodejs package is installed only where no node is present at all.
command -v node >/dev/null 2>&1 || packages+=(nodejs npm)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

lint_dir="$(cd "$(dirname "$0")/.." && pwd)/tools/openapi-lint"
install_linter() {
  [ -x "$lint_dir/node_modules/.bin/redocly" ] && return 0
  echo "deps: installing the OpenAPI linter (npm ci in tools/openapi-lint)"
  (cd "$lint_dir" && npm ci --no-audit --no-fund --loglevel=error)
}

if [ ${#missing[@]} -eq 0 ]; then
  install_linter
  exit 0
fi

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
install_linter
