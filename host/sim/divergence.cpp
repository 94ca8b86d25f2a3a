#include <sstream>

#include "sim/solver.hpp"

namespace pbflow {

std::string Divergence::describe(double speed_limit) const {
  std::ostringstream s;
  const char* sep = "";
  if (not_finite) s << sep << not_finite << " particle(s) with a NaN or infinite position or velocity", sep = "; ";
  if (too_fast) s << sep << too_fast << " particle(s) faster than " << speed_limit << " m/s", sep = "; ";
  if (outside) s << sep << outside << " particle(s) outside the domain", sep = "; ";
  return s.str();
}

}  // namespace pbflow
