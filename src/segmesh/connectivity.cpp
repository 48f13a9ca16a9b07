#include "segmesh/connectivity.hpp"

#include <stdexcept>
#include <string>

namespace segmesh {

void require_connectivity(int connectivity, std::string_view who) {
  if (!is_connectivity(connectivity)) {
    throw std::invalid_argument(std::string(who) + ": connectivity must be 6, 18 or 26 (got " +
                                std::to_string(connectivity) + ")");
  }
}

}  // namespace segmesh
