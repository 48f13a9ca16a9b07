// libFuzzer target for one mesh reader: the input becomes a file named "input" +
// SEGMESH_FUZZ_EXTENSION (.stl, .ply, .obj, .glb) and goes through read_mesh, which must return a
// scene or throw segmesh::Error. An OBJ's "mtllib" may name other files; the scratch folder holds
// only the input.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "segmesh/error.hpp"
#include "segmesh_io/read_mesh.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path =
      segmesh::fuzz::write_file(segmesh::fuzz::scratch_folder(), "input" SEGMESH_FUZZ_EXTENSION,
                                data, size);
  try {
    const segmesh::Scene scene = segmesh::read_mesh(path);
    (void)scene;
  } catch (const segmesh::Error&) {
  }
  return 0;
}
