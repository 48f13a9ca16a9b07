// Opening a file in the viewer: the one place that decides what a path is and runs the project's
// own readers and pipeline on it. A mesh or scene file (.glb, .ply, .stl, .obj: mesh_format.hpp)
// is read by read_mesh; anything else (NIfTI, NRRD, MetaImage, MRC, a DICOM folder) is a volume,
// read by read_volume and meshed by build_scene with the panel's MeshingOptions. A volume already
// read can be meshed again with other options without reading it again ("Create mesh"). Every
// part is then measured (part_stats.hpp, contacts included), so the window never measures on its
// own thread, and a meshed volume says which kind of surfaces it got (surfaces_summary.hpp).
//
// run_load is synchronous and throws what the readers and the pipeline throw (segmesh::Error for
// bad input, Cancelled); load_job.hpp runs it on a worker thread and turns failures into messages.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "segmesh/image.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/scene.hpp"
#include "segmesh_viewer/part_stats.hpp"

namespace segmesh::viewer {

enum class InputKind { volume, mesh };

// mesh for a path whose extension names a mesh format, volume otherwise (folders included).
InputKind input_kind(const std::filesystem::path& path);

struct LoadRequest {
  std::filesystem::path path;          // the file or DICOM folder to open; ignored when `image` is set
  std::shared_ptr<const Image> image;  // a volume already read: mesh it again
  // For volumes: the request as the panel makes it (meshing_request), resolved by build_scene;
  // left unresolved so the surfaces line can say why automatic surfaces were not conforming.
  MeshingOptions meshing;
};

struct LoadResult {
  Scene scene;
  std::vector<PartStats> stats;        // one per part
  std::shared_ptr<const Image> image;  // the volume (null for a mesh file)
  std::string source;                  // the path opened
  InputKind kind = InputKind::volume;
  std::string surfaces;                // volumes: which surfaces ran (surfaces_summary); "" for a mesh
};

// Progress steps: "reading", then the pipeline's steps for a volume, then "measuring".
LoadResult run_load(const LoadRequest& request, Progress& progress = null_progress());

}  // namespace segmesh::viewer
