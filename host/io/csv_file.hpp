#pragma once
// A CSV file a run writes row by row (stats.csv, solids.csv): created new, each row written and
// flushed whole, so that a run stopped at any point leaves whole rows.
#include <cstdio>
#include <filesystem>

namespace pbflow {

class CsvFile {
 public:
  // A new file under `path` (not opened through a link or an existing file) with its header row.
  CsvFile(const std::filesystem::path& path, const char* header);
  ~CsvFile();
  CsvFile(const CsvFile&) = delete;
  CsvFile& operator=(const CsvFile&) = delete;
  // Throws std::runtime_error naming the file and the cause when the row cannot be written.
  void append(const char* row);

 private:
  std::filesystem::path path_;
  std::FILE* file_;
};

}  // namespace pbflow
