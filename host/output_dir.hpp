#pragma once
// The --out directory: reused only for pbflow's own files (stats.csv, frames/,
// particles/), so that a run never overwrites or deletes what a person put there.
#include <filesystem>

namespace pbflow {

// Throws InputError when `out` is not a directory, or frames/ or particles/ in it
// hold anything but pbflow's frame files.
void check_output_dir(const std::filesystem::path& out);

// After a complete run of `frames` frames: removes pbflow frame files numbered
// `frames` or more, left by an earlier, longer run into the same directory.
void remove_stale_frames(const std::filesystem::path& out, int frames);

}  // namespace pbflow
