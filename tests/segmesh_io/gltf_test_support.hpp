// GLB files in the tests: the chunks of a file, and the Khronos glTF validator's verdict on it.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace segmesh::test {

struct Glb {
  nlohmann::json json;
  std::string bin;
};

// The little-endian uint32 at byte `at`.
inline uint32_t u32(const std::string& b, size_t at) {
  uint32_t v;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}

// A GLB file's JSON chunk, parsed, and its binary chunk.
inline Glb split_glb(const std::string& b) {
  Glb g;
  const uint32_t json_len = u32(b, 12);
  g.json = nlohmann::json::parse(b.substr(20, json_len));
  if (b.size() > 20 + json_len) g.bin = b.substr(28 + json_len, u32(b, 20 + json_len));
  return g;
}

// The validator's counts for one file (errors and warnings -1 when it did not run).
struct ValidatorReport {
  bool ran = false;
  int errors = -1, warnings = -1;
  std::string output;
};

// Runs tools/npm/validate-gltf.mjs; a missing node or validator is a test failure, not a skip:
// the validator is part of the project's test dependencies.
inline ValidatorReport run_validator(const std::filesystem::path& file) {
  ValidatorReport r;
  const std::filesystem::path npm = std::filesystem::path(SEGMESH_SOURCE_DIR) / "tools" / "npm";
  const std::filesystem::path script = npm / "validate-gltf.mjs";
  const std::filesystem::path package = npm / "node_modules" / "gltf-validator" / "package.json";
  if (std::system("node --version > /dev/null 2>&1") != 0) {
    ADD_FAILURE() << "node (Node.js) is not installed; run scripts/install-deps.sh to install it and the glTF validator";
    return r;
  }
  if (!std::filesystem::exists(package)) {
    ADD_FAILURE() << "the Khronos glTF validator is not installed (" << package
                  << " is missing); run scripts/install-deps.sh";
    return r;
  }
  const std::string cmd = "node '" + script.string() + "' '" + file.string() + "' 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) {
    ADD_FAILURE() << "cannot run " << cmd;
    return r;
  }
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, pipe)) > 0) r.output.append(buf, n);
  pclose(pipe);
  try {
    const nlohmann::json report = nlohmann::json::parse(r.output.substr(0, r.output.find('\n')));
    r.errors = report.at("errors").get<int>();
    r.warnings = report.at("warnings").get<int>();
    r.ran = true;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "the glTF validator's output is not its JSON report (" << e.what() << "):\n" << r.output;
  }
  return r;
}

// The validator runs on `file` and finds neither errors nor warnings.
inline void expect_valid_glb(const std::filesystem::path& file) {
  SCOPED_TRACE(file.string());
  const ValidatorReport r = run_validator(file);
  ASSERT_TRUE(r.ran);
  EXPECT_EQ(r.errors, 0) << r.output;
  EXPECT_EQ(r.warnings, 0) << r.output;
}

}  // namespace segmesh::test
