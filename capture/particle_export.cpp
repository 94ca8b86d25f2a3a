#include "capture/particle_export.hpp"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/input_error.hpp"
#include "io/atomic_file.hpp"

static_assert(std::endian::native == std::endian::little, "the particle writers emit the host's float bytes");

namespace pbflow::capture {

ExportFormat parse_export_format(const std::string& name) {
  if (name.empty()) return ExportFormat::None;
  if (name == "ply") return ExportFormat::Ply;
  if (name == "vtk") return ExportFormat::Vtk;
  throw InputError("--export must be ply or vtk, not '" + name + "'");
}

const char* export_extension(ExportFormat format) { return format == ExportFormat::Vtk ? "vtp" : "ply"; }

namespace {

// A point attribute: a name and `components` values a particle (1 or 3; the positions are the
// first column, named ""), floats or, `whole`, 32-bit unsigned integers held in their bits.
struct Column {
  std::string name;
  int components;
  std::vector<float> values;
  bool whole = false;
};

// The frame's fluid particles in ascending id order (0 to n - 1 unless emitters or drains changed
// them): positions, velocity, density and, `with_ids`, each one's id.
std::vector<Column> fluid_columns(const ParticleFrame& f, bool with_ids) {
  const size_t n = f.x.size();
  if (f.v.size() != n || f.rho.size() != n || f.id.size() != n) throw std::runtime_error("inconsistent particle frame");
  std::vector<Column> c = {{"", 3, std::vector<float>(3 * n)}, {"velocity", 3, std::vector<float>(3 * n)},
                           {"density", 1, std::vector<float>(n)}};
  if (with_ids) c.push_back({"id", 1, std::vector<float>(n), true});
  const std::vector<size_t> order = ascending_ids(f.id);
  for (size_t i = 0; i < n; ++i) {
    const size_t k = order[i];
    for (int a = 0; a < 3; ++a) c[0].values[3 * i + a] = f.x[k][a], c[1].values[3 * i + a] = f.v[k][a];
    c[2].values[i] = f.rho[k];
    if (with_ids) c[3].values[i] = std::bit_cast<float>(f.id[k]);
  }
  return c;
}

// The white water alive: positions, velocity, life left (s) and kind (0 spray, 1 foam, 2 bubble).
std::vector<Column> white_water_columns(const ParticleFrame& f) {
  const size_t n = f.white_x.size();
  if (f.white_v.size() != n) throw std::runtime_error("inconsistent white water frame");
  std::vector<Column> c = {{"", 3, {}}, {"velocity", 3, {}}, {"life", 1, {}}, {"kind", 1, {}}};
  for (size_t k = 0; k < n; ++k) {
    for (int a = 0; a < 3; ++a) c[0].values.push_back(f.white_x[k][a]), c[1].values.push_back(f.white_v[k][a]);
    c[2].values.push_back(f.white_x[k].w);
    c[3].values.push_back(float(WhiteParticle::unpacked(f.white_x[k], f.white_v[k]).kind()));
  }
  return c;
}

void put(std::FILE* out, const void* data, size_t bytes) {
  if (bytes && std::fwrite(data, 1, bytes, out) != bytes) throw std::runtime_error(std::strerror(errno));
}

// Binary PLY: one vertex element, its properties the columns' floats (x y z, then vx vy vz for
// velocity, the others by name), a record per particle.
void write_ply(std::FILE* out, const std::vector<Column>& columns, size_t n, const char* comment) {
  std::fprintf(out, "ply\nformat binary_little_endian 1.0\ncomment %s\nelement vertex %zu\n", comment, n);
  for (const Column& c : columns) {
    if (c.components == 1) std::fprintf(out, "property %s %s\n", c.whole ? "uint" : "float", c.name.c_str());
    for (int a = 0; a < c.components && c.components == 3; ++a)
      std::fprintf(out, "property float %s%c\n", c.name.empty() ? "" : "v", "xyz"[a]);
  }
  std::fprintf(out, "end_header\n");
  std::vector<float> records;
  for (size_t i = 0; i < n; ++i)
    for (const Column& c : columns)
      for (int a = 0; a < c.components; ++a) records.push_back(c.values[i * c.components + a]);
  put(out, records.data(), records.size() * sizeof(float));
}

// VTK XML PolyData, raw appended: each array a UInt32 byte count and its values; the points,
// the point data, then one vertex cell per particle (connectivity 0..n-1, offsets 1..n), as SPH
// codes write them: without cells ParaView's default representation of the file shows nothing.
void write_vtp(std::FILE* out, const std::vector<Column>& columns, size_t n) {
  std::vector<int32_t> connectivity(n), offsets(n);
  for (size_t i = 0; i < n; ++i) connectivity[i] = int32_t(i), offsets[i] = int32_t(i + 1);
  if (n * 3 * sizeof(float) > UINT32_MAX) throw std::runtime_error("too many particles for a .vtp file (UInt32 array sizes)");
  std::vector<size_t> at;  // each array's offset in the appended data
  size_t next = 0;
  for (const Column& c : columns) at.push_back(next), next += 4 + c.values.size() * sizeof(float);
  const size_t connectivity_at = next, offsets_at = next + 4 + n * sizeof(int32_t);
  std::fprintf(out,
               "<?xml version=\"1.0\"?>\n"
               "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt32\">\n"
               "  <PolyData>\n"
               "    <Piece NumberOfPoints=\"%zu\" NumberOfVerts=\"%zu\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
               "NumberOfPolys=\"0\">\n"
               "      <PointData Vectors=\"velocity\" Scalars=\"%s\">\n",
               n, n, columns[2].name.c_str());
  for (size_t k = 1; k < columns.size(); ++k)
    std::fprintf(out, "        <DataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%d\" format=\"appended\" offset=\"%zu\"/>\n",
                 columns[k].whole ? "UInt32" : "Float32", columns[k].name.c_str(), columns[k].components, at[k]);
  std::fprintf(out,
               "      </PointData>\n"
               "      <Points>\n"
               "        <DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/>\n"
               "      </Points>\n"
               "      <Verts>\n"
               "        <DataArray type=\"Int32\" Name=\"connectivity\" format=\"appended\" offset=\"%zu\"/>\n"
               "        <DataArray type=\"Int32\" Name=\"offsets\" format=\"appended\" offset=\"%zu\"/>\n"
               "      </Verts>\n"
               "    </Piece>\n"
               "  </PolyData>\n"
               "  <AppendedData encoding=\"raw\">\n_",
               connectivity_at, offsets_at);
  auto append = [&](const auto& array) {
    uint32_t bytes = uint32_t(array.size() * sizeof(array[0]));
    put(out, &bytes, sizeof bytes);
    put(out, array.data(), bytes);
  };
  for (const Column& c : columns) append(c.values);
  append(connectivity);
  append(offsets);
  std::fprintf(out, "\n  </AppendedData>\n</VTKFile>\n");
}

void write_columns(const std::filesystem::path& path, ExportFormat format, const std::vector<Column>& columns,
                   const char* comment) {
  const size_t n = columns[0].values.size() / 3;
  write_atomically(path, [&](std::FILE* out) {
    if (format == ExportFormat::Vtk)
      write_vtp(out, columns, n);
    else
      write_ply(out, columns, n, comment);
  });
}

}  // namespace

void write_particles(const std::filesystem::path& path, ExportFormat format, const ParticleFrame& frame, bool with_ids) {
  write_columns(path, format, fluid_columns(frame, with_ids), "pbflow particles");
}

void write_white_water(const std::filesystem::path& path, ExportFormat format, const ParticleFrame& frame) {
  write_columns(path, format, white_water_columns(frame), "pbflow white water");
}

}  // namespace pbflow::capture
