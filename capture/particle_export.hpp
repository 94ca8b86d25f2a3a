#pragma once
// Particle files per frame, in particle-id order (stable across frames):
//   ply: binary little-endian PLY, one `vertex` element, float x y z vx vy vz density
//        (docs/design.md);
//   vtk: VTK XML PolyData (.vtp), points plus `velocity` and `density` point data,
//        raw appended binary; opens in ParaView.
// Where particles come and go (emitters, drains), `with_ids` adds each one's id (PLY `uint id`,
// VTK UInt32 `id`): a row is then not the same particle from frame to frame, its id is.
// White water per frame (write_white_water), in no set order: position and velocity as above,
// then life (s left) and kind (0 spray, 1 foam, 2 bubble) in place of density.
// Each file is written atomically.
#include <filesystem>
#include <string>

#include "sim/solver.hpp"

namespace pbflow::capture {

enum class ExportFormat { None, Ply, Vtk };
ExportFormat parse_export_format(const std::string& name);  // "", "ply", "vtk"; else InputError
const char* export_extension(ExportFormat format);          // "ply", "vtp"

void write_particles(const std::filesystem::path& path, ExportFormat format, const ParticleFrame& frame,
                     bool with_ids = false);
void write_white_water(const std::filesystem::path& path, ExportFormat format, const ParticleFrame& frame);

}  // namespace pbflow::capture
