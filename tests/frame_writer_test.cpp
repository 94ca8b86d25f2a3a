// The frame writer: PNGs written on worker threads, reported whole and in frame order.
#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <vector>

#include "capture/frame_writer.hpp"
#include "capture/png.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

namespace fs = std::filesystem;

capture::Image numbered(int k) {  // a small frame whose pixels say which it is
  capture::Image image{64, 36, std::vector<uint8_t>(64 * 36 * 3)};
  for (size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = uint8_t((k * 37 + i) % 251);
  return image;
}

// Twelve frames, four in flight: each is reported after its file reads back whole, in order.
TEST(FrameWriter, ReportsEachFrameInOrderOnceItsFileIsWhole) {
  const fs::path dir = test::fresh_dir("frame_writer");
  fs::create_directories(dir);
  std::vector<int> reported;
  capture::FrameWriter writer(4);
  for (int k = 0; k < 12; ++k) {
    const fs::path png = dir / ("frame_" + std::to_string(k) + ".png");
    writer.push(png, numbered(k), [&, k, png] {
      EXPECT_EQ(capture::read_png(png).rgb, numbered(k).rgb) << "frame " << k << " reported before it was whole";
      reported.push_back(k);
    });
    EXPECT_LE(k + 1 - int(reported.size()), 4) << "more than four frames in flight";
  }
  writer.finish();
  ASSERT_EQ(reported.size(), 12u);
  for (int k = 0; k < 12; ++k) EXPECT_EQ(reported[k], k);
}

// A frame that cannot be written fails the writer with the file's name; the frames before it
// are reported, none after it.
TEST(FrameWriter, AFailedFrameNamesItsFileAndEndsTheReports) {
  const fs::path dir = test::fresh_dir("frame_writer_fail");
  fs::create_directories(dir);
  std::vector<int> reported;
  capture::FrameWriter writer(2);
  try {
    for (int k = 0; k < 6; ++k) {
      const fs::path png = (k == 2 ? dir / "missing" : dir) / ("frame_" + std::to_string(k) + ".png");
      writer.push(png, numbered(k), [&, k] { reported.push_back(k); });
    }
    writer.finish();
    FAIL() << "a frame into a missing directory was written";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("frame_2.png"), std::string::npos) << e.what();
  }
  EXPECT_EQ(reported, (std::vector<int>{0, 1}));
}

}  // namespace
}  // namespace pbflow
