#include "segmesh_render/detail/shaders.hpp"

namespace segmesh::render::shaders {

// How every fragment shader of a mesh pass begins: the version and mesh_vertex's outputs, written
// once so the passes cannot drift from the vertex shader. No newline at its end: each source
// below goes on with R"( and a line break.
#define SEGMESH_MESH_FRAGMENT_INPUTS \
  "#version 330 core\n"              \
  "in vec3 v_position;\n"            \
  "in vec3 v_normal;\n"              \
  "in vec4 v_color;"

const char* const mesh_vertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_color;
uniform mat4 u_model;         // the part's transform (world mm)
uniform mat4 u_model_view;    // view * model, composed in double precision
uniform mat3 u_normal_view;   // normals to view space: view * inverse transpose of model
uniform mat4 u_projection;
uniform vec4 u_clip;          // kept where dot(u_clip, world position) >= 0
out vec3 v_position;          // view space
out vec3 v_normal;            // view space
out vec4 v_color;
invariant gl_Position;
void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  vec4 view = u_model_view * vec4(a_position, 1.0);
  v_position = view.xyz;
  v_normal = u_normal_view * a_normal;
  v_color = a_color;
  gl_ClipDistance[0] = dot(u_clip, world);
  gl_Position = u_projection * view;
}
)";

const char* const shade_fragment = SEGMESH_MESH_FRAGMENT_INPUTS R"(
uniform vec3 u_base_color;     // linear
uniform float u_metallic;
uniform float u_roughness;
uniform float u_opacity;
uniform bool u_vertex_color;   // base colour from the vertex colours (sRGB bytes)
uniform bool u_clipped;        // back faces are cut surfaces (else: two-sided lighting)
uniform bool u_use_ao;
uniform sampler2D u_ao;        // at the output size
uniform int u_ao_step;         // internal pixels per output pixel
uniform float u_ao_strength;
uniform float u_highlight;
uniform float u_hatch_period;  // pixels
layout(location = 0) out vec4 o_color;

const float PI = 3.14159265;
// Lights in view space (fixed to the camera): direction towards the light, radiance.
const vec3 KEY_DIR = vec3(-0.4386, 0.5848, 0.6823);
const vec3 KEY_RADIANCE = vec3(2.10, 2.05, 1.95);
const vec3 FILL_DIR = vec3(0.7719, -0.3088, 0.5558);
const vec3 FILL_RADIANCE = vec3(0.38, 0.41, 0.48);
// The sky light: a hemisphere, bright above the screen, dark ground below.
const vec3 SKY = vec3(0.27, 0.30, 0.36);
const vec3 GROUND = vec3(0.09, 0.085, 0.08);

vec3 srgb_to_linear(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(0.04045, c));
}

float d_ggx(float noh, float a) {
  float a2 = a * a;
  float d = noh * noh * (a2 - 1.0) + 1.0;
  return a2 / (PI * d * d);
}

// Height-correlated Smith visibility term V = G / (4 NoL NoV) (Heitz 2014).
float v_smith(float nov, float nol, float a) {
  float a2 = a * a;
  float gv = nol * sqrt(nov * nov * (1.0 - a2) + a2);
  float gl = nov * sqrt(nol * nol * (1.0 - a2) + a2);
  return 0.5 / max(gv + gl, 1e-5);
}

vec3 f_schlick(float voh, vec3 f0) {
  return f0 + (vec3(1.0) - f0) * pow(1.0 - voh, 5.0);
}

// Karis, "Physically Based Shading on Mobile" (2014): the split-sum environment BRDF, fitted.
vec3 env_brdf(vec3 f0, float roughness, float nov) {
  const vec4 c0 = vec4(-1.0, -0.0275, -0.572, 0.022);
  const vec4 c1 = vec4(1.0, 0.0425, 1.04, -0.04);
  vec4 r = roughness * c0 + c1;
  float a004 = min(r.x * r.x, exp2(-9.28 * nov)) * r.x + r.y;
  vec2 ab = vec2(-1.04, 1.04) * a004 + r.zw;
  return f0 * ab.x + ab.y;
}

// Irradiance of the hemisphere light for a surface facing n.
vec3 sky_irradiance(vec3 n) {
  return mix(GROUND, SKY, 0.5 + 0.5 * n.y);
}

// The sky as a metal sees it along direction r (view space): a dark ground below the horizon, a
// bright sky above it, brightest at the zenith, and a soft window around the key light. Roughness
// widens every transition (a cheap stand-in for prefiltering an environment map).
vec3 sky_reflection(vec3 r, float roughness) {
  float w = 0.06 + 0.45 * roughness;
  vec3 env = mix(GROUND * 0.2, SKY * 1.8, smoothstep(-w, w, r.y));
  env += SKY * 2.2 * smoothstep(0.3, 1.0 + w, r.y);
  env += KEY_RADIANCE * 1.3 * smoothstep(1.0 - 0.9 * w, 1.0, dot(r, KEY_DIR));
  return env;
}

vec3 direct(vec3 n, vec3 v, vec3 l, vec3 radiance, vec3 diffuse, vec3 f0, float a) {
  float nol = dot(n, l);
  if (nol <= 0.0) return vec3(0.0);
  vec3 h = normalize(l + v);
  float nov = max(dot(n, v), 1e-4);
  float noh = max(dot(n, h), 0.0);
  float voh = max(dot(v, h), 0.0);
  vec3 f = f_schlick(voh, f0);
  vec3 specular = d_ggx(noh, a) * v_smith(nov, nol, a) * f;
  return ((vec3(1.0) - f) * diffuse / PI + specular) * radiance * nol;
}

void main() {
  vec3 base = u_vertex_color ? srgb_to_linear(v_color.rgb) : u_base_color;
  if (!gl_FrontFacing && u_clipped) {
    // A cut surface: flat, darkened, hatched diagonally.
    float stripe = mod(gl_FragCoord.x + gl_FragCoord.y, u_hatch_period) < 0.5 * u_hatch_period ? 1.0 : 0.0;
    vec3 cap = base * mix(0.15, 0.24, stripe);
    o_color = vec4(cap * u_opacity, u_opacity);
    return;
  }
  vec3 n = normalize(gl_FrontFacing ? v_normal : -v_normal);
  vec3 v = normalize(-v_position);
  float metallic = u_vertex_color ? 0.0 : u_metallic;
  float roughness = u_vertex_color ? 0.8 : clamp(u_roughness, 0.04, 1.0);
  float a = roughness * roughness;
  vec3 f0 = mix(vec3(0.04), base, metallic);
  vec3 diffuse = base * (1.0 - metallic);
  float nov = max(dot(n, v), 1e-4);

  float ao = 1.0;
  if (u_use_ao) {
    // Steepened (power 2) so a crease reads clearly while open surfaces (ao near 1) keep
    // their brightness.
    ao = mix(1.0, pow(texelFetch(u_ao, ivec2(gl_FragCoord.xy) / u_ao_step, 0).r, 2.0), u_ao_strength);
  }

  vec3 lit = direct(n, v, KEY_DIR, KEY_RADIANCE, diffuse, f0, a) +
             direct(n, v, FILL_DIR, FILL_RADIANCE, diffuse, f0, a);
  lit *= mix(1.0, ao, 0.75);
  vec3 fs = env_brdf(f0, roughness, nov);
  vec3 r = reflect(-v, n);
  vec3 ambient = sky_irradiance(n) * diffuse * (vec3(1.0) - fs) + sky_reflection(r, roughness) * fs;
  vec3 color = lit + ambient * ao;
  color += u_highlight * vec3(0.35, 0.65, 1.0) * (0.25 + pow(1.0 - nov, 2.0));
  o_color = vec4(color * u_opacity, u_opacity);
}
)";

const char* const normal_fragment = SEGMESH_MESH_FRAGMENT_INPUTS R"(
layout(location = 0) out vec4 o_normal;
void main() {
  vec3 n = normalize(gl_FrontFacing ? v_normal : -v_normal);
  o_normal = vec4(n, 1.0);
}
)";

const char* const id_fragment = SEGMESH_MESH_FRAGMENT_INPUTS R"(
uniform uint u_id;
layout(location = 0) out uint o_id;
void main() { o_id = u_id; }
)";

const char* const fullscreen_vertex = R"(#version 330 core
void main() {
  // One triangle that covers the viewport: (-1,-1), (3,-1), (-1,3).
  vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
)";

const char* const ssao_fragment = R"(#version 330 core
// Ambient obscurance from the depth buffer in the manner of McGuire et al., "The Alchemy
// Screen-Space Ambient Obscurance Algorithm" (HPG 2011) and "Scalable Ambient Obscurance"
// (HPG 2012): points Q of the visible surfaces around the pixel's point P, picked on a spiral over
// a screen disc that is the world radius at P's depth, occlude by how far they rise above P's
// tangent plane, (v.n - bias) / |v| with v = Q - P, fading to nothing at the radius. A flat open
// surface has v.n = 0 everywhere and a convex one v.n < 0: neither occludes itself, whatever the
// radius; the floor of a crease sees its wall rise and darkens, most at the wall's foot.
// Runs at the output resolution; reads the prepass at the centre of each output pixel.
uniform sampler2D u_depth;       // internal size
uniform sampler2D u_normal;      // view space
uniform sampler2D u_noise;       // 4x4 (cos, sin) of the spiral's starting angle
uniform mat4 u_inverse_projection;
uniform int u_step;              // internal pixels per output pixel (the supersampling)
uniform vec2 u_internal_size;    // pixels
uniform float u_radius;          // view-space mm
uniform float u_bias;            // mm
uniform float u_pixels_per_mm;   // output pixels per mm at 1 mm from the eye
uniform float u_intensity;
layout(location = 0) out float o_ao;

const int SAMPLES = 24;
const float TURNS = 7.0;  // coprime with SAMPLES, so no two samples share a direction

// The internal pixel at the centre of output pixel `p`, and the view-space point it shows
// (w = 0 for the background).
ivec2 internal_pixel(ivec2 p) {
  return min(p * u_step + u_step / 2, ivec2(u_internal_size) - 1);
}
vec4 view_position(ivec2 p) {
  ivec2 q = internal_pixel(p);
  float depth = texelFetch(u_depth, q, 0).r;
  if (depth >= 1.0) return vec4(0.0);
  vec4 v = u_inverse_projection * vec4((vec2(q) + 0.5) / u_internal_size * 2.0 - 1.0, depth * 2.0 - 1.0, 1.0);
  return vec4(v.xyz / v.w, 1.0);
}

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  vec4 c = view_position(pixel);
  if (c.w == 0.0) { o_ao = 1.0; return; }
  vec3 p = c.xyz;
  vec3 n = normalize(texelFetch(u_normal, internal_pixel(pixel), 0).xyz);
  float disc = u_pixels_per_mm * u_radius / max(-p.z, 1e-6);  // the radius in pixels
  if (disc < 1.5) { o_ao = 1.0; return; }  // too small to resolve anything
  vec2 start = texelFetch(u_noise, pixel % 4, 0).xy;
  float phi = atan(start.y, start.x);
  ivec2 size = ivec2(u_internal_size) / u_step;
  float r2 = u_radius * u_radius;
  float sum = 0.0;
  for (int i = 0; i < SAMPLES; ++i) {
    float a = (float(i) + 0.5) / float(SAMPLES);
    float angle = a * TURNS * 6.2831853 + phi;
    ivec2 q = ivec2(floor(vec2(pixel) + 0.5 + a * disc * vec2(cos(angle), sin(angle))));
    if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size)) || q == pixel) continue;
    vec4 s = view_position(q);
    if (s.w == 0.0) continue;  // the background occludes nothing
    vec3 v = s.xyz - p;
    float vv = dot(v, v);
    float falloff = max(1.0 - vv / r2, 0.0);
    sum += falloff * falloff * max(dot(v, n) - u_bias, 0.0) / sqrt(vv + 1e-4 * r2);
  }
  o_ao = max(0.0, 1.0 - u_intensity * sum / float(SAMPLES));
}
)";

const char* const blur_fragment = R"(#version 330 core
uniform sampler2D u_ao;          // output size
uniform sampler2D u_depth;       // internal size
uniform mat4 u_inverse_projection;
uniform int u_step;              // internal pixels per output pixel
uniform float u_radius;
layout(location = 0) out float o_ao;

float view_z(ivec2 pixel) {
  ivec2 q = min(pixel * u_step + u_step / 2, textureSize(u_depth, 0) - 1);
  float d = texelFetch(u_depth, q, 0).r;
  vec4 p = u_inverse_projection * vec4(0.0, 0.0, d * 2.0 - 1.0, 1.0);
  return p.z / p.w;
}

void main() {
  // 4x4, the size of the noise tile, so the rotation pattern averages out; samples across a
  // depth discontinuity are left out, so occlusion does not bleed over silhouettes.
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  ivec2 size = textureSize(u_ao, 0);
  float z0 = view_z(pixel);
  float sum = 0.0, weight = 0.0;
  for (int y = -2; y < 2; ++y)
    for (int x = -2; x < 2; ++x) {
      ivec2 q = clamp(pixel + ivec2(x, y), ivec2(0), size - 1);
      float w = abs(view_z(q) - z0) < 0.5 * u_radius ? 1.0 : 0.0;
      sum += w * texelFetch(u_ao, q, 0).r;
      weight += w;
    }
  o_ao = weight > 0.0 ? sum / weight : 1.0;
}
)";

const char* const composite_fragment = R"(#version 330 core
uniform sampler2D u_color;     // linear, premultiplied, supersampled
uniform int u_samples;         // supersampling factor per axis
uniform vec2 u_origin;         // the viewport's lower-left corner in the target
uniform vec2 u_size;           // the viewport's size
uniform vec3 u_background_top;     // linear
uniform vec3 u_background_bottom;  // linear
uniform float u_exposure;
layout(location = 0) out vec4 o_color;

// Narkowicz's fit of the ACES filmic curve.
vec3 tone_map(vec3 x) {
  return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

vec3 linear_to_srgb(vec3 c) {
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

void main() {
  vec2 local = gl_FragCoord.xy - u_origin;
  vec3 background = mix(u_background_bottom, u_background_top, clamp(local.y / u_size.y, 0.0, 1.0));
  ivec2 base = ivec2(local) * u_samples;
  vec3 sum = vec3(0.0);
  for (int y = 0; y < u_samples; ++y)
    for (int x = 0; x < u_samples; ++x) {
      vec4 c = texelFetch(u_color, base + ivec2(x, y), 0);
      vec3 shaded = c.a > 0.0 ? tone_map(u_exposure * c.rgb / c.a) : vec3(0.0);
      sum += shaded * c.a + background * (1.0 - c.a);
    }
  o_color = vec4(linear_to_srgb(sum / float(u_samples * u_samples)), 1.0);
}
)";

#undef SEGMESH_MESH_FRAGMENT_INPUTS

}  // namespace segmesh::render::shaders
