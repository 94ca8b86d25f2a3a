#pragma once
// `pbflow bench --scaling`: the cost model. One scene at doubling particle counts (10 000
// up to 4 000 000, or as far as a wall-clock budget and the device's memory allow), each
// warmed up for a frame and then measured for a fixed simulated time. Writes under --out
//   scaling.csv  one row per count: ms per step (GPU timestamps), particle-steps/s, device
//                bytes per particle, each pass group's ms, and the fit of step cost
//                against particles (a + b N; the log-log slope over the larger half);
//   scaling.png  the same, log-log (bench/charts.py);
// and prints them as a table.
#include <string>
#include <vector>

namespace pbflow::bench {

struct ScalingOptions {
  std::string out = "bench_out";
  std::string device = "auto";
  std::string scene = "dam_break";
  std::vector<int> counts;  // empty: 10 000 x 2^k up to 4 000 000
  std::string method;       // "pbf" or "ldc"; empty: the scene's
  int iterations = 0;       // 0: the scene's
  double seconds = 0.05;    // simulated per count, after one warm-up frame
  double budget_minutes = 15;  // no count starts that would end past this
  bool charts = true;
};

int run_scaling(const ScalingOptions& options);

// The columns of scaling.csv, in order (tests check them).
const std::vector<std::string>& scaling_columns();

}  // namespace pbflow::bench
