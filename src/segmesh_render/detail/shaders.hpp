// The GLSL 3.30 core sources of the renderer's passes (renderer.hpp describes the frame), as
// constant strings. Internal to segmesh_render: the renderer compiles and links them into its
// programs once per Renderer; nothing here touches OpenGL.
//
// Guarantees: the mesh passes share one vertex shader (below) and the fragment shaders of those
// passes declare its outputs from one definition, so every pass sees the same interface.
#pragma once

namespace segmesh::render::shaders {

// Every pass that draws meshes uses this vertex shader, so depth is identical across passes
// (invariant gl_Position) and the depth prepass can be reused.
extern const char* const mesh_vertex;
extern const char* const shade_fragment;   // lit colour, premultiplied alpha
extern const char* const normal_fragment;  // view-space normals for ambient occlusion
extern const char* const id_fragment;      // part index + 1

// Full-screen passes: one triangle covering the viewport.
extern const char* const fullscreen_vertex;
extern const char* const ssao_fragment;
extern const char* const blur_fragment;
extern const char* const composite_fragment;

}  // namespace segmesh::render::shaders
