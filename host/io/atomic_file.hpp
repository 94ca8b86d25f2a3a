#pragma once
// Files that appear whole or not at all: written under a temporary name in the same
// directory (NAME.tmpDIGITS, created exclusively: never a file that was there), flushed, then
// renamed over the final name.
#include <cstdio>
#include <filesystem>
#include <functional>

namespace pbflow::capture {

// Calls write(file) on a temporary file and renames it to `path`; on any failure the
// temporary is removed and std::runtime_error names the file.
void write_atomically(const std::filesystem::path& path, const std::function<void(std::FILE*)>& write);

}  // namespace pbflow::capture
