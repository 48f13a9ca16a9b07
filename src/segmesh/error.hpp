// Error types shared by every module.
//
// segmesh::Error is a fault in the user's input or request: a file that is missing, corrupt or
// lying, an option that makes no sense. Its message is one line a user can act on and names the
// file first ("ct.nii.gz: 4-D images are not supported (dims 512x512x20x3)"). Front ends print it
// as "segmesh: error: <message>" and exit with code 2. Anything else thrown is an internal fault
// (exit code 1).
#pragma once

#include <stdexcept>
#include <string>

namespace segmesh {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Thrown when a Progress reports cancelled(); the pipeline unwinds and nothing is written.
struct Cancelled : std::runtime_error {
  Cancelled() : std::runtime_error("cancelled") {}
};

}  // namespace segmesh
