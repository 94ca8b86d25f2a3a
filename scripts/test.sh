#!/usr/bin/env bash
# Sets up (packages, build) and runs the whole test suite on the Vulkan device that
# `auto` picks (lavapipe where there is no GPU), with the validation layer on.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh --test
ctest --test-dir build --output-on-failure -j"$(nproc)"
