#pragma once
// `pbflow diff A B`: two run directories compared as a CI job compares a result with its golden
// copy: the manifest's status and frames, every stats.csv column but the timing, and every
// frame, particle and white water file, byte for byte. A difference is named where it first
// shows: the file, the frame's row and column, the particle and its field, or the pixel, and by
// how much.
#include <filesystem>
#include <iosfwd>

namespace pbflow {

// 0 where A and B hold the same results, 1 after one line naming the first difference on `out`;
// InputError where either is not a run directory (no run.json).
int diff_runs(const std::filesystem::path& a, const std::filesystem::path& b, std::ostream& out);

}  // namespace pbflow
