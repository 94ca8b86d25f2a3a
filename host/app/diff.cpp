#include "app/diff.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <set>
#include <sstream>
#include <vector>

#include "capture/png.hpp"
#include "common/input_error.hpp"
#include "common/read_file.hpp"

namespace pbflow {

namespace {

namespace fs = std::filesystem;
using Difference = std::optional<std::string>;
constexpr long long kMostBytes = 4LL << 30;  // a file of a run: a frame of 2^27 particles fits

std::string read_whole(const fs::path& p) { return read_user_file(p.string(), p.string(), {kMostBytes}); }

std::string number(double v) {
  std::ostringstream m;
  m.precision(9);
  m << v;
  return m.str();
}

// The manifest's result: its status and frames (times, pids and paths differ run to run).
Difference diff_manifests(const fs::path& a, const fs::path& b) {
  const nlohmann::json ma = nlohmann::json::parse(read_whole(a / "run.json")),
                       mb = nlohmann::json::parse(read_whole(b / "run.json"));
  for (const char* key : {"status", "frames", "scene", "chosen", "reproducible_on"}) {
    const std::string va = ma.value(key, nlohmann::json()).dump(), vb = mb.value(key, nlohmann::json()).dump();
    if (va == vb) continue;
    if (va.size() + vb.size() > 160) return std::string("run.json: the ") + key + " differs";
    return std::string("run.json: ") + key + " " + va + " against " + vb;
  }
  return std::nullopt;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
  return cells;
}

// Every row and column but step_ms, the one that measures the machine rather than the run.
Difference diff_stats(const fs::path& a, const fs::path& b) {
  std::stringstream ta(read_whole(a / "stats.csv")), tb(read_whole(b / "stats.csv"));
  std::string la, lb, header;
  for (int row = 0;; ++row) {
    const bool more_a = bool(std::getline(ta, la)), more_b = bool(std::getline(tb, lb));
    if (!more_a || !more_b)
      return more_a == more_b ? Difference{} : "stats.csv: " + std::to_string(row - 1) + " rows against more";
    if (row == 0) header = la;
    const std::vector<std::string> names = split(header), ca = split(la), cb = split(lb);
    for (size_t k = 0; k < std::max(ca.size(), cb.size()); ++k) {
      const std::string name = k < names.size() ? names[k] : "column " + std::to_string(k);
      if (name == "step_ms" || (k < ca.size() && k < cb.size() && ca[k] == cb[k])) continue;
      const std::string va = k < ca.size() ? ca[k] : "nothing", vb = k < cb.size() ? cb[k] : "nothing";
      return "stats.csv: frame " + std::to_string(row - 1) + ", " + name + " " + va + " against " + vb;
    }
  }
}

// A binary PLY's vertex properties (pbflow writes floats only) and where its body starts.
struct Ply {
  std::vector<std::string> properties;
  size_t vertices = 0, body = 0;
};

std::optional<Ply> read_ply_header(const std::string& bytes) {
  const size_t end = bytes.find("end_header\n");
  if (bytes.rfind("ply\n", 0) != 0 || end == std::string::npos) return std::nullopt;
  Ply ply;
  std::stringstream header(bytes.substr(0, end));
  for (std::string line; std::getline(header, line);) {
    std::stringstream words(line);
    std::string first, second, third;
    words >> first >> second >> third;
    if (first == "element" && second == "vertex") ply.vertices = std::stoull(third);
    if (first == "property" && second == "float") ply.properties.push_back(third);
  }
  ply.body = end + std::strlen("end_header\n");
  return ply;
}

// The first particle and property that differ, by how much.
Difference diff_ply(const std::string& name, const std::string& a, const std::string& b) {
  const std::optional<Ply> pa = read_ply_header(a), pb = read_ply_header(b);
  if (!pa || !pb || pa->properties != pb->properties) return name + ": the headers differ";
  if (pa->vertices != pb->vertices)
    return name + ": " + std::to_string(pa->vertices) + " particles against " + std::to_string(pb->vertices);
  const size_t fields = pa->properties.size();
  for (size_t k = 0; k < pa->vertices * fields && pa->body + 4 * k + 4 <= a.size() && pb->body + 4 * k + 4 <= b.size();
       ++k) {
    float va, vb;
    std::memcpy(&va, a.data() + pa->body + 4 * k, 4);
    std::memcpy(&vb, b.data() + pb->body + 4 * k, 4);
    if (std::memcmp(&va, &vb, 4) == 0) continue;
    return name + ": particle " + std::to_string(k / fields) + " (in the file's order), " + pa->properties[k % fields] +
           " " + number(va) + " against " + number(vb) + " (by " + number(std::abs(double(va) - vb)) + ")";
  }
  return name + ": the bytes differ past the particles";
}

// The first pixel that differs and the largest channel difference over the image.
Difference diff_png(const std::string& name, const fs::path& a, const fs::path& b) {
  const capture::Image ia = capture::read_png(a), ib = capture::read_png(b);
  if (ia.width != ib.width || ia.height != ib.height)
    return name + ": " + std::to_string(ia.width) + "x" + std::to_string(ia.height) + " against " +
           std::to_string(ib.width) + "x" + std::to_string(ib.height);
  std::optional<size_t> first;
  int largest = 0;
  size_t pixels = 0;
  for (size_t p = 0; p < ia.rgb.size() / 3; ++p) {
    int most = 0;
    for (int c = 0; c < 3; ++c) most = std::max(most, std::abs(int(ia.rgb[3 * p + c]) - int(ib.rgb[3 * p + c])));
    if (most == 0) continue;
    if (!first) first = p;
    largest = std::max(largest, most), ++pixels;
  }
  if (!first) return std::nullopt;  // the same image in other bytes (compression)
  return name + ": pixel (" + std::to_string(*first % ia.width) + ", " + std::to_string(*first / ia.width) + ") first; " +
         std::to_string(pixels) + " pixels differ, by up to " + std::to_string(largest) + " of 255";
}

Difference diff_file(const std::string& name, const fs::path& a, const fs::path& b) {
  const std::string ba = read_whole(a), bb = read_whole(b);
  if (ba == bb) return std::nullopt;
  if (name.ends_with(".ply")) return diff_ply(name, ba, bb);
  if (name.ends_with(".png")) return diff_png(name, a, b);
  const auto at = std::mismatch(ba.begin(), ba.end(), bb.begin(), bb.end());
  return name + ": the bytes differ from offset " + std::to_string(at.first - ba.begin());
}

std::set<std::string> names_in(const fs::path& folder) {
  std::set<std::string> names;
  if (fs::is_directory(folder))
    for (const fs::directory_entry& e : fs::directory_iterator(folder))
      if (e.is_regular_file() && e.path().filename().string().rfind("frame_", 0) == 0)
        names.insert(e.path().filename().string());
  return names;
}

// A folder's frame files: the same names, then each the same.
Difference diff_folder(const std::string& folder, const fs::path& a, const fs::path& b) {
  const std::set<std::string> na = names_in(a / folder), nb = names_in(b / folder);
  if (na != nb) {
    std::vector<std::string> only;
    std::set_symmetric_difference(na.begin(), na.end(), nb.begin(), nb.end(), std::back_inserter(only));
    return folder + "/" + only.front() + " is in one run only (" + std::to_string(na.size()) + " files against " +
           std::to_string(nb.size()) + ")";
  }
  for (const std::string& name : na)
    if (Difference d = diff_file(folder + "/" + name, a / folder / name, b / folder / name)) return d;
  return std::nullopt;
}

}  // namespace

int diff_runs(const fs::path& a, const fs::path& b, std::ostream& out) {
  for (const fs::path& dir : {a, b})
    if (!fs::is_regular_file(dir / "run.json")) throw InputError(dir.string() + " is not a run directory (no run.json)");
  Difference d = diff_manifests(a, b);
  if (!d) d = diff_stats(a, b);
  for (const char* folder : {"particles", "white_water", "frames"})
    if (!d) d = diff_folder(folder, a, b);
  if (!d) return 0;
  out << "differ: " << *d << "\n";
  return 1;
}

}  // namespace pbflow
