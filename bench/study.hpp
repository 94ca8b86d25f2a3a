#pragma once
// `pbflow bench`: the speed-accuracy study. Runs methods x iterations x particle counts
// on dam_break and hydrostatic for a fixed simulated time and writes, under --out,
//   runs.csv    one row per run: cost (mean/max step, per pass group, throughput) and
//               accuracy (time-averaged compression, the tank's settling, energy and
//               its gain);
//   series.csv  one row per run and frame: compression and energies over time;
//   charts      accuracy vs cost, time per step vs iterations, compression and kinetic
//               energy over time (bench/charts.py, run with Debian's matplotlib).
#include <string>
#include <vector>

namespace pbflow::bench {

struct StudyOptions {
  bool quick = false;             // a small subset, minutes on a CPU device
  std::string out = "bench_out";
  std::string device = "auto";
  std::vector<int> counts;        // particles per scene; empty: by --quick
  std::vector<int> iterations;    // empty: by --quick
  double seconds = 0;             // simulated per run; 0: by --quick
  std::vector<double> ldc_strength;  // LDC strengths for the ldc runs (a sweep); empty: the scene's
  std::vector<std::string> scenes;  // empty: dam_break and hydrostatic
  std::vector<double> targets;      // adaptive runs to these mean compressions instead of fixed iterations
  std::vector<int> substeps;        // steps per frame to try; empty: the scene's
  // The stability map: dam_break and drop, 4000 particles, substeps {1,2,4} x iterations
  // {1,2,4} x LDC strength {0.25,0.5,0.9} (each unless given), 1 s; every run classified
  // (stable, compressed, gains energy, diverged).
  bool stability = false;
  bool charts = true;
};

// Returns the exit status; throws InputError for bad options.
int run_study(const StudyOptions& options);

// The columns of runs.csv, in order (tests check them).
const std::vector<std::string>& run_columns();

}  // namespace pbflow::bench
