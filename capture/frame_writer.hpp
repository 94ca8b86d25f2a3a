#pragma once
// Writes frames' PNGs on worker threads while the run simulates and draws the next ones: at
// 1080p the PNG is most of a frame's capture where a GPU simulates and draws it in a few ms.
// Frames are reported written in their order, on the calling thread, so that a run's stats row
// still follows its frame's file.
#include <cstddef>
#include <deque>
#include <filesystem>
#include <functional>
#include <future>

#include "capture/renderer.hpp"

namespace pbflow::capture {

class FrameWriter {
 public:
  // Up to `in_flight` PNGs at once; at least 1.
  explicit FrameWriter(size_t in_flight);
  ~FrameWriter();  // waits for the writes in flight, reporting none
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;

  // Starts writing `image` to `path`; `written` runs once the file is whole and every earlier
  // frame's `written` has run. Blocks while `in_flight` writes are pending. A failed write
  // throws here or in finish(), naming the file, and no later frame is reported.
  void push(const std::filesystem::path& path, Image image, std::function<void()> written);
  void finish();  // waits for every write and reports each

  // Workers for this machine: one core is the run's own.
  static size_t default_in_flight();

 private:
  struct Pending {
    std::future<void> file;
    std::function<void()> written;
  };
  void complete_oldest();

  size_t in_flight_;
  std::deque<Pending> pending_;
};

}  // namespace pbflow::capture
