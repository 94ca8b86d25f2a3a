#!/usr/bin/env bash
# Builds pbflow and its tests with AddressSanitizer + UndefinedBehaviorSanitizer in
# build-sanitize/ and runs the tests there (lavapipe and llvmpipe are not instrumented;
# leak detection is off because the drivers' own allocations would be reported).
# Any sanitizer report fails the test that triggered it.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh --test
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPBFLOW_SANITIZE=ON >/dev/null
cmake --build build-sanitize -j"$(nproc)"
ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-sanitize --output-on-failure -j"$(nproc)" "$@"
