#!/usr/bin/env bash
# Reproduces every table and the plot in bench/README.md: builds the
# benchmarks in Release, runs them with JSON output into bench/results/,
# and prints the tables (bench/tables.py; the plot needs python3-matplotlib
# or `pip install matplotlib`, the tables only the standard library).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-bench -G Ninja -DCMAKE_BUILD_TYPE=Release -DBIREG_BUILD_TESTS=OFF -DBIREG_BUILD_EXAMPLES=OFF
cmake --build build-bench -j2 --target bench_groups bench_regression
mkdir -p bench/results
common=(--benchmark_repetitions=3 --benchmark_report_aggregates_only=true --benchmark_out_format=json)
./build-bench/bench/bench_groups "${common[@]}" --benchmark_out=bench/results/groups.json
./build-bench/bench/bench_regression "${common[@]}" --benchmark_out=bench/results/regression.json
python3 bench/tables.py bench/results
