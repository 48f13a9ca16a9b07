#include "segmesh/progress.hpp"

#include "segmesh/error.hpp"

namespace segmesh {

Progress& null_progress() {
  static Progress none;
  return none;
}

void throw_if_cancelled(const Progress& progress) {
  if (progress.cancelled()) throw Cancelled();
}

}  // namespace segmesh
