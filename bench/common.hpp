#pragma once
// Shared by the benches (study, scaling): CSV cells, the spacing for a particle count, charts.
#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace pbflow::bench {

std::string number(double v);                             // 6 significant digits
std::string join(const std::vector<std::string>& cells);  // one CSV line, RFC 4180 quoting

// The particle spacing at which `scene` holds about `particles` fluid particles.
double spacing_for(const Scene& scene, int particles);

// Runs the embedded bench/charts.py on `out` (Debian's python3 with matplotlib), leaving
// the script beside its charts; returns the exit status (1 with a message on failure).
int draw_charts(const std::string& out);

}  // namespace pbflow::bench
