// The programs' allocator (src/segmesh_alloc): the command line runs on jemalloc with its memory
// marked for transparent huge pages, the setting that halves the default command's time
// (docs/PERFORMANCE.md, "The programs' allocator"). Skipped where the build has no jemalloc (the
// sanitizer build, or a machine without libjemalloc-dev), and saying so.
#include <gtest/gtest.h>

#include <string>

#include "cli/cli_run.hpp"

namespace segmesh {
namespace {

TEST(CliAllocator, RunsOnJemallocWithHugePages) {
#ifndef SEGMESH_PROGRAM_JEMALLOC
  GTEST_SKIP() << "this build's segmesh uses glibc's malloc (no jemalloc, or a sanitizer build)";
#endif
  // jemalloc prints its options at exit when asked through the environment; the program's own
  // settings (malloc_conf) are read first, so they show unless the environment overrides them.
  const test::CliResult r = test::run_segmesh_with_env("MALLOC_CONF=stats_print:true", "--version");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("opt.thp: \"always\""), std::string::npos)
      << "segmesh does not run on jemalloc with thp:always; its statistics said:\n"
      << r.err.substr(0, 2000);
  EXPECT_NE(r.err.find("opt.metadata_thp: \"auto\""), std::string::npos);
}

}  // namespace
}  // namespace segmesh
