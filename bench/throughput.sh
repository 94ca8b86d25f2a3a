#!/usr/bin/env bash
# The throughput table of docs/performance.md: GPU solver (Vulkan device `auto`) and the
# C++ reference, dam_break during its first frames. Usage: bench/throughput.sh > table.md
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/bench/pbflow_throughput
echo "| device | particles | method | iterations | steps timed | ms/step | particle-steps/s |"
echo "|---|---|---|---|---|---|---|"
$bin 7000 ldc 2 auto 10
$bin 7000 pbf 2 auto 10
$bin 20000 ldc 1 auto 10
$bin 20000 pbf 1 auto 10
$bin 100000 ldc 1 auto 5
$bin 100000 pbf 1 auto 5
$bin 20000 ldc 1 cpu 2
$bin 100000 ldc 1 cpu 1
