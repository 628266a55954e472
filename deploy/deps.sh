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
  libmicrohttpd-dev     # server HTTP; Debian's libmicrohttpd12 is built with GnuTLS (--tls-listen)
  openssl               # tests/service/tls_test.sh makes its certificate authority with it
  iproute2              # ... and its two hosts with ip netns and a veth pair
  slurmctld slurmd slurm-client munge  # tests/service/slurm_test.sh starts a one-node Slurm of its
                        # own (no systemd; the packages' services are not used) for the pilots
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
  python3-jsonschema    # the metrics and suite documents checked against schemas/ (tests)
  python3-junitparser   # a JUnit XML reader: the nightly's JUnit report read by a real consumer
  python3-pil           # the nightly test looks for the plots in chromium's screenshot
  chromium              # headless: the nightly's HTML report opened and drawn (tests)
  util-linux            # taskset: the nightly test's second machine fingerprint (one processor)
  systemd               # systemd-analyze: tests/install/install_test.sh verifies the installed units
                        # (no systemd needs to run for that)
  man-db                # man -l: the same test renders the installed man pages
  chromium fonts-dejavu-core  # the dashboard's browser tests (tests/web): Debian's headless chromium,
                        # driven by playwright-core; no browser is ever downloaded
)

# `deps.sh fuzz` (make fuzz) adds what the fuzzers build with: clang with libFuzzer and its
# sanitizer runtimes, clang's OpenMP runtime, and dpkg-source to unpack jansson's Debian source
# (fuzz/jansson.sh). make test needs none of them.
if [ "${1:-}" = fuzz ]; then
  packages=(clang libclang-rt-14-dev libomp-dev dpkg-dev)
fi

# The OpenAPI linter of make test (tools/openapi-lint, pinned in its package-lock.json) runs on
# Node.js >= 20.19; Debian's nodejs package is installed only where no node is present at all.
[ "${1:-}" = fuzz ] || command -v node >/dev/null 2>&1 || packages+=(nodejs npm)

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

# The dashboard's npm libraries (web/, docs/web.md), pinned in tools/web-vendor/package-lock.json:
# npm ci there, then each library's browser files and licence are copied into web/vendor/, which
# poro-server serves (no build step; nothing is fetched at run time). The browser tests'
# playwright-core is pinned in tests/web/package-lock.json.
repo="$(cd "$(dirname "$0")/.." && pwd)"
install_web() {
  local vendor="$repo/tools/web-vendor" tests="$repo/tests/web" dest="$repo/web/vendor/uplot"
  if [ ! -f "$vendor/node_modules/uplot/package.json" ]; then
    echo "deps: installing the dashboard's libraries (npm ci in tools/web-vendor)"
    (cd "$vendor" && npm ci --no-audit --no-fund --loglevel=error)
  fi
  local src="$vendor/node_modules/uplot"
  if ! cmp -s "$src/dist/uPlot.esm.js" "$dest/uPlot.esm.js" 2>/dev/null; then
    mkdir -p "$dest"
    cp "$src/dist/uPlot.esm.js" "$src/dist/uPlot.min.css" "$src/LICENSE" "$dest/"
    mv "$dest/LICENSE" "$dest/LICENSE.txt"
    node -e 'process.stdout.write(require(process.argv[1]).version + "\n")' "$src/package.json" > "$dest/VERSION.txt"
  fi
  if [ ! -f "$tests/node_modules/playwright-core/package.json" ]; then
    echo "deps: installing the browser tests' playwright-core (npm ci in tests/web)"
    (cd "$tests" && npm ci --no-audit --no-fund --loglevel=error)
  fi
}

if [ ${#missing[@]} -eq 0 ]; then
  install_linter
  install_web
  exit 0
fi

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
install_linter
install_web
