#include "capture/particle_export.hpp"

#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
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

// The frame's columns in id order: x y z vx vy vz density per particle.
std::vector<float> records_by_id(const ParticleFrame& f) {
  const size_t n = f.x.size();
  if (f.v.size() != n || f.rho.size() != n || f.id.size() != n) throw std::runtime_error("inconsistent particle frame");
  std::vector<float> records(n * 7);
  for (size_t k = 0; k < n; ++k) {
    if (f.id[k] >= n) throw std::runtime_error("particle id out of range");
    float* r = &records[size_t(f.id[k]) * 7];
    r[0] = f.x[k].x, r[1] = f.x[k].y, r[2] = f.x[k].z;
    r[3] = f.v[k].x, r[4] = f.v[k].y, r[5] = f.v[k].z;
    r[6] = f.rho[k];
  }
  return records;
}

void put(std::FILE* out, const void* data, size_t bytes) {
  if (bytes && std::fwrite(data, 1, bytes, out) != bytes) throw std::runtime_error(std::strerror(errno));
}

void write_ply(std::FILE* out, const std::vector<float>& records, size_t n) {
  std::fprintf(out,
               "ply\nformat binary_little_endian 1.0\ncomment pbflow particles\nelement vertex %zu\n"
               "property float x\nproperty float y\nproperty float z\nproperty float vx\nproperty float vy\n"
               "property float vz\nproperty float density\nend_header\n",
               n);
  put(out, records.data(), records.size() * sizeof(float));
}

void write_vtp(std::FILE* out, const std::vector<float>& records, size_t n) {
  // Appended arrays, each a UInt32 byte count and the raw values: points, velocity, density,
  // then one vertex cell per particle (connectivity 0..n-1, offsets 1..n), as SPH codes
  // write them: without cells ParaView's default representation of the file shows nothing.
  std::vector<float> points(n * 3), velocity(n * 3), density(n);
  std::vector<int32_t> connectivity(n), offsets(n);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      points[i * 3 + c] = records[i * 7 + c];
      velocity[i * 3 + c] = records[i * 7 + 3 + c];
    }
    density[i] = records[i * 7 + 6];
    connectivity[i] = int32_t(i);
    offsets[i] = int32_t(i + 1);
  }
  const size_t vec_bytes = n * 3 * sizeof(float), scalar_bytes = n * sizeof(float);
  if (vec_bytes > UINT32_MAX) throw std::runtime_error("too many particles for a .vtp file (UInt32 array sizes)");
  const size_t velocity_offset = 4 + vec_bytes, density_offset = velocity_offset + 4 + vec_bytes,
               connectivity_offset = density_offset + 4 + scalar_bytes, offsets_offset = connectivity_offset + 4 + scalar_bytes;
  std::fprintf(out,
               "<?xml version=\"1.0\"?>\n"
               "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt32\">\n"
               "  <PolyData>\n"
               "    <Piece NumberOfPoints=\"%zu\" NumberOfVerts=\"%zu\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
               "NumberOfPolys=\"0\">\n"
               "      <PointData Vectors=\"velocity\" Scalars=\"density\">\n"
               "        <DataArray type=\"Float32\" Name=\"velocity\" NumberOfComponents=\"3\" format=\"appended\" "
               "offset=\"%zu\"/>\n"
               "        <DataArray type=\"Float32\" Name=\"density\" format=\"appended\" offset=\"%zu\"/>\n"
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
               n, n, velocity_offset, density_offset, connectivity_offset, offsets_offset);
  auto append = [&](const auto& array) {
    uint32_t bytes = uint32_t(array.size() * sizeof(array[0]));
    put(out, &bytes, sizeof bytes);
    put(out, array.data(), bytes);
  };
  append(points);
  append(velocity);
  append(density);
  append(connectivity);
  append(offsets);
  std::fprintf(out, "\n  </AppendedData>\n</VTKFile>\n");
}

}  // namespace

void write_particles(const std::filesystem::path& path, ExportFormat format, const ParticleFrame& frame) {
  const std::vector<float> records = records_by_id(frame);
  write_atomically(path, [&](std::FILE* out) {
    if (format == ExportFormat::Vtk)
      write_vtp(out, records, frame.x.size());
    else
      write_ply(out, records, frame.x.size());
  });
}

}  // namespace pbflow::capture
