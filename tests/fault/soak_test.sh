#!/usr/bin/env bash
# soak_test.sh - the soak of tests/fault/soak.sh at the size make test can afford: 300 jobs with
# the server and the workers killed at random every 1-4 s (make soak runs 10,000).
#   bash tests/fault/soak_test.sh BUILD_DIR
cd "$(dirname "$0")/../.."
exec bash tests/fault/soak.sh "${1:-build}" "${SOAK_TEST_JOBS:-300}"
