#include "segmesh_io/write_mesh.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <system_error>

#include "segmesh_io/atomic_file.hpp"
#include "segmesh_io/detail/mesh_io_common.hpp"
#include "segmesh_io/detail/text.hpp"
#include "segmesh_io/gltf_writer.hpp"
#include "segmesh_io/obj_writer.hpp"
#include "segmesh_io/ply_writer.hpp"
#include "segmesh_io/stl_writer.hpp"

namespace segmesh {

namespace fs = std::filesystem;
using namespace mesh_io;

namespace {

// Flushes and closes the temporary file, checking that every byte was accepted, so that many
// part files can be finished before any of them is renamed without keeping them all open.
void finish(AtomicFile& file) {
  file.stream();  // opened even when a writer wrote nothing, so the file exists
  file.close_stream();
}

// The temporaries of one write, renamed together at the end.
using Files = std::vector<std::unique_ptr<AtomicFile>>;

void write_to(const PartList& parts, const fs::path& file, MeshFormat format, const std::string& name,
              const MeshWriteOptions& options, Files& files) {
  require_parent_folder(file);  // names the file asked for, not the .mtl that OBJ opens first
  const auto open = [&](const fs::path& target) -> AtomicFile& {
    files.push_back(std::make_unique<AtomicFile>(target));
    return *files.back();
  };
  // Formats of one file: write, then finish it.
  const auto write_one = [&](const auto& write) {
    AtomicFile& f = open(file);
    write(f.stream());
    finish(f);
  };
  switch (format) {
    case MeshFormat::stl:
      write_one([&](std::ostream& out) { write_stl(parts, out, name); });
      break;
    case MeshFormat::ply:
      write_one([&](std::ostream& out) { write_ply(parts, out); });
      break;
    case MeshFormat::obj: {
      fs::path mtl_path = file;
      mtl_path.replace_extension(".mtl");
      if (mtl_path == file) {
        throw Error(file.string() + ": an OBJ file needs a name other than its .mtl material file");
      }
      // The MTL is listed first so it is renamed before the OBJ that refers to it appears.
      AtomicFile& mtl = open(mtl_path);
      AtomicFile& obj = open(file);
      write_obj(parts, obj.stream(), mtl.stream(), mtl_path.filename().string());
      finish(mtl);
      finish(obj);
      break;
    }
    case MeshFormat::glb:
      write_one([&](std::ostream& out) { write_glb(parts, out, options.quantize); });
      break;
  }
}

void check_write_options(const fs::path& path, MeshFormat format, const MeshWriteOptions& options) {
  if (options.quantize && format != MeshFormat::glb) {
    throw Error(path.string() + ": quantized positions (--quantize) are a glTF extension; write glb, not " +
                std::string(extension(format)));
  }
}

void commit_all(Files& files) {
  for (auto& f : files) f->commit();
}

// The file of every part in `parts`, in order, in `dir`.
std::vector<fs::path> file_paths(const PartList& parts, const fs::path& dir, MeshFormat format) {
  std::vector<fs::path> paths;
  UniqueNames used(/*fold_case=*/true);
  for (const Part* part : parts) {
    const std::string stem = unique_stem(file_stem_for(part->name, "part"), used);
    paths.push_back(dir / (stem + "." + std::string(extension(format))));
  }
  return paths;
}

// The target without the options' checks (resolve_mesh_target).
MeshTarget target_of(const std::string& output, const std::string& format) {
  MeshTarget out;
  out.path = output;
  std::optional<MeshFormat> requested;
  if (!format.empty()) {
    requested = parse_mesh_format(format);
    if (!requested) throw Error("--format must be stl, ply, obj or glb (got \"" + format + "\")");
  }
  const bool trailing_slash = !output.empty() && output.back() == '/';
  if (trailing_slash || fs::is_directory(out.path)) {
    out.folder = true;
    out.format = requested.value_or(MeshFormat::ply);
    fs::path folder = out.path;
    if (trailing_slash) folder = folder.parent_path();  // "dir/" -> "dir"
    if (!fs::exists(folder)) require_parent_folder(folder);
    out.path = folder;
    return out;
  }
  const auto by_name = mesh_format_from_path(out.path);
  if (!by_name) {
    throw Error(output + ": unknown mesh format \"" + out.path.extension().string() +
                "\"; use .stl, .ply, .obj or .glb, or end the path with / for one file per part");
  }
  if (requested && *requested != *by_name) {
    throw Error(output + ": --format " + format + " disagrees with the file extension");
  }
  out.format = *by_name;
  require_parent_folder(out.path);
  return out;
}

}  // namespace

MeshTarget resolve_mesh_target(const std::string& output, const std::string& format,
                               const MeshWriteOptions& options) {
  MeshTarget out = target_of(output, format);
  if (options.quantize && out.format != MeshFormat::glb) {
    throw Error("--quantize writes glTF's KHR_mesh_quantization; it needs glb output, not " +
                std::string(extension(out.format)));
  }
  return out;
}

std::vector<fs::path> part_file_paths(const Scene& scene, const fs::path& dir, MeshFormat format) {
  return file_paths(parts_to_write(scene), dir, format);
}

void write_scene(const Scene& scene, const fs::path& file, MeshFormat format,
                 const MeshWriteOptions& options) {
  check_write_options(file, format, options);
  const PartList parts = parts_to_write(scene);
  const std::string name = parts.size() == 1 ? parts.front()->name : file.stem().string();
  Files files;
  write_to(parts, file, format, name, options, files);
  commit_all(files);
}

std::vector<fs::path> write_parts(const Scene& scene, const fs::path& dir, MeshFormat format,
                                  const MeshWriteOptions& options) {
  check_write_options(dir, format, options);
  const PartList parts = parts_to_write(scene);
  std::error_code ec;
  bool created = false;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) throw Error(dir.string() + ": exists and is not a folder");
  } else {
    require_parent_folder(dir);
    if (!fs::create_directory(dir, ec) && ec) {
      throw Error(dir.string() + ": cannot create the folder (" + ec.message() + ")");
    }
    created = true;
  }

  const std::vector<fs::path> written = file_paths(parts, dir, format);
  try {
    Files files;
    for (size_t i = 0; i < parts.size(); ++i) {
      write_to({parts[i]}, written[i], format, parts[i]->name, options, files);
    }
    commit_all(files);
  } catch (...) {
    if (created) fs::remove(dir, ec);  // only removes it when empty
    throw;
  }
  return written;
}

}  // namespace segmesh
