#include "capture/frame_writer.hpp"

#include <algorithm>
#include <thread>

#include "capture/png.hpp"

namespace pbflow::capture {

FrameWriter::FrameWriter(size_t in_flight) : in_flight_(std::max<size_t>(1, in_flight)) {}

FrameWriter::~FrameWriter() {
  for (Pending& p : pending_)
    if (p.file.valid()) p.file.wait();
}

size_t FrameWriter::default_in_flight() {
  const size_t cores = std::thread::hardware_concurrency();
  return std::clamp<size_t>(cores > 1 ? cores - 1 : 1, 1, 8);
}

void FrameWriter::push(const std::filesystem::path& path, Image image, std::function<void()> written) {
  while (pending_.size() >= in_flight_) complete_oldest();
  pending_.push_back({std::async(std::launch::async, [path, image = std::move(image)] { write_png(path, image); }),
                      std::move(written)});
}

void FrameWriter::finish() {
  while (!pending_.empty()) complete_oldest();
}

void FrameWriter::complete_oldest() {
  Pending oldest = std::move(pending_.front());
  pending_.pop_front();
  oldest.file.get();  // rethrows the write's failure
  oldest.written();
}

}  // namespace pbflow::capture
