// libFuzzer target for the scene parser: any input either parses into a scene whose
// derived constants and particles can be built, or is refused with InputError. Any
// other exception, crash, leak or undefined behaviour is a bug.
// Build and run: see tests/fuzz/README.md.
#include <cstddef>
#include <cstdint>
#include <string>

#include "scene/derive.hpp"
#include "scene/parse.hpp"
#include "scene/seeding.hpp"
#include "sim/params.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  try {
    pbflow::Scene scene = pbflow::parse_scene(text, "fuzz");
    pbflow::derive(scene);
    // Particles only for small scenes: the fuzzer looks for parser bugs, not big allocations.
    double cells = 1;
    for (int k = 0; k < 3; ++k) cells *= (scene.domain.max[k] - scene.domain.min[k]) / scene.particle_spacing;
    if (cells < 2e5) pbflow::initial_particles(scene);
  } catch (const pbflow::InputError&) {
  }
  return 0;
}
