// link_program, the one way the renderer builds its programs: good sources link (with the mesh
// attributes at their fixed locations); a shader that does not compile and a program that does
// not link throw, naming the program and carrying the driver's log, whichever step failed.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "segmesh_render/detail/gl_program.hpp"
#include "segmesh_render/detail/shaders.hpp"
#include "segmesh_render/headless_context.hpp"

namespace segmesh {
namespace {

using namespace segmesh::render;

// The message of what link_program throws; empty when it links (the program is then deleted).
std::string link_error(const char* vertex, const char* fragment, const char* name) {
  try {
    const GLuint program = link_program(vertex, fragment, name);
    glDeleteProgram(program);
    return "";
  } catch (const std::runtime_error& e) {
    return e.what();
  }
}

constexpr const char* kFragment = R"(#version 330 core
layout(location = 0) out vec4 o_color;
void main() { o_color = vec4(1.0); }
)";

TEST(GlProgram, LinksTheRenderersSourcesAndReportsEachStepsFailure) {
  const HeadlessContext context;
  const GLuint shade = link_program(shaders::mesh_vertex, shaders::shade_fragment, "shade");
  EXPECT_NE(shade, 0u);
  EXPECT_EQ(glGetAttribLocation(shade, "a_position"), 0);
  EXPECT_EQ(glGetAttribLocation(shade, "a_normal"), 1);
  glDeleteProgram(shade);
  EXPECT_EQ(link_error(shaders::fullscreen_vertex, kFragment, "plain"), "");

  const std::string bad_fragment = link_error(
      shaders::fullscreen_vertex, "#version 330 core\nvoid main() { nonsense; }\n", "broken");
  EXPECT_EQ(bad_fragment.rfind("renderer: shader broken does not compile: ", 0), 0u)
      << bad_fragment;
  EXPECT_GT(bad_fragment.size(), std::string("renderer: shader broken does not compile: ").size())
      << "no driver log";
  EXPECT_EQ(link_error("#version 330 core\nvoid main() { nonsense; }\n", kFragment, "vs")
                .rfind("renderer: shader vs does not compile: ", 0),
            0u);

  // Compiles, but the function it calls is defined nowhere: only linking fails.
  const std::string unlinked = link_error(shaders::fullscreen_vertex, R"(#version 330 core
layout(location = 0) out vec4 o_color;
vec4 missing();
void main() { o_color = missing(); }
)",
                                          "unlinked");
  EXPECT_EQ(unlinked.rfind("renderer: program unlinked does not link: ", 0), 0u) << unlinked;
}

}  // namespace
}  // namespace segmesh
