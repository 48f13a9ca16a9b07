#include "segmesh_render/headless_context.hpp"

#include <dlfcn.h>
#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstdio>
#include <string>
#include <vector>

#include "segmesh/error.hpp"

namespace segmesh::render {

namespace {

const char* const kHint =
    "install Mesa's EGL and drivers (Debian: libegl1 libegl-mesa0 libgl1-mesa-dri)";

std::string egl_error_text(EGLint code) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "EGL error 0x%04x", unsigned(code));
  return buf;
}

bool has_extension(const char* list, const std::string& name) {
  if (!list) return false;
  const std::string all = std::string(" ") + list + " ";
  return all.find(" " + name + " ") != std::string::npos;
}

struct Attempt {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  EGLSurface surface = EGL_NO_SURFACE;
  std::string failure;
};

// Creates a 3.3 core context on an initialised display; with `pbuffer`, also a 1x1 surface.
Attempt make_context(EGLDisplay display, bool pbuffer) {
  Attempt a;
  a.display = display;
  if (display == EGL_NO_DISPLAY) {
    a.failure = "no display";
    return a;
  }
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) {
    a.failure = "eglInitialize failed (" + egl_error_text(eglGetError()) + ")";
    return a;
  }
  if (!eglBindAPI(EGL_OPENGL_API)) {
    a.failure = "the EGL driver has no desktop OpenGL";
    return a;
  }
  const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
  EGLConfig config = nullptr;
  const bool configless = has_extension(extensions, "EGL_KHR_no_config_context") ||
                          has_extension(extensions, "EGL_MESA_configless_context");
  if (pbuffer || !configless) {
    const EGLint want[] = {EGL_SURFACE_TYPE,    EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                           EGL_OPENGL_BIT,      EGL_RED_SIZE,    8,
                           EGL_GREEN_SIZE,      8,               EGL_BLUE_SIZE,
                           8,                   EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(display, want, &config, 1, &count) || count < 1) {
      a.failure = "no EGL configuration for desktop OpenGL";
      return a;
    }
  }
  const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                               3,
                               EGL_CONTEXT_MINOR_VERSION,
                               3,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK,
                               EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                               EGL_NONE};
  a.context = eglCreateContext(display, config ? config : EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT,
                               attributes);
  if (a.context == EGL_NO_CONTEXT) {
    a.failure = "no OpenGL 3.3 core context (" + egl_error_text(eglGetError()) + ")";
    return a;
  }
  if (pbuffer || !has_extension(extensions, "EGL_KHR_surfaceless_context")) {
    const EGLint size[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
    a.surface = config ? eglCreatePbufferSurface(display, config, size) : EGL_NO_SURFACE;
    if (a.surface == EGL_NO_SURFACE) {
      eglDestroyContext(display, a.context);
      a.context = EGL_NO_CONTEXT;
      a.failure = "no pbuffer surface";
      return a;
    }
  }
  if (!eglMakeCurrent(display, a.surface, a.surface, a.context)) {
    a.failure = "eglMakeCurrent failed (" + egl_error_text(eglGetError()) + ")";
    if (a.surface != EGL_NO_SURFACE) eglDestroySurface(display, a.surface);
    eglDestroyContext(display, a.context);
    a.context = EGL_NO_CONTEXT;
    a.surface = EGL_NO_SURFACE;
    return a;
  }
  return a;
}

}  // namespace

HeadlessContext::HeadlessContext() {
  // libepoxy aborts the process when it cannot load libEGL; look first, so a machine without it
  // gets a message instead.
  if (void* lib = dlopen("libEGL.so.1", RTLD_LAZY | RTLD_LOCAL)) {
    dlclose(lib);
  } else {
    throw Error(std::string("cannot create an OpenGL 3.3 context without a display: libEGL.so.1 "
                            "is missing; ") + kHint);
  }
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  std::vector<std::string> failures;
  Attempt done;
  std::string how;

  if (has_extension(client, "EGL_MESA_platform_surfaceless")) {
    done = make_context(
        eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr), false);
    how = "surfaceless";
    if (done.context == EGL_NO_CONTEXT) failures.push_back("surfaceless: " + done.failure);
  }
  if (done.context == EGL_NO_CONTEXT && has_extension(client, "EGL_EXT_platform_device")) {
    EGLDeviceEXT devices[8];
    EGLint count = 0;
    if (eglQueryDevicesEXT(8, devices, &count)) {
      for (EGLint i = 0; i < count && done.context == EGL_NO_CONTEXT; ++i) {
        done = make_context(eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr),
                            false);
        how = "EGL device " + std::to_string(i);
        if (done.context == EGL_NO_CONTEXT) failures.push_back(how + ": " + done.failure);
      }
    }
  }
  if (done.context == EGL_NO_CONTEXT) {
    done = make_context(eglGetDisplay(EGL_DEFAULT_DISPLAY), true);
    how = "default display, pbuffer";
    if (done.context == EGL_NO_CONTEXT) failures.push_back("default display: " + done.failure);
  }
  if (done.context == EGL_NO_CONTEXT) {
    std::string why;
    for (const std::string& f : failures) why += (why.empty() ? "" : "; ") + f;
    throw Error("cannot create an OpenGL 3.3 context without a display (" + why + "); " + kHint);
  }
  display_ = done.display;
  context_ = done.context;
  surface_ = done.surface;
  if (epoxy_gl_version() < 33) {
    const std::string version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (surface_) eglDestroySurface(display_, surface_);
    eglDestroyContext(display_, context_);
    throw Error("cannot create an OpenGL 3.3 context without a display: the driver gives only " +
                version + "; " + kHint);
  }
  description_ = std::string("OpenGL ") + reinterpret_cast<const char*>(glGetString(GL_VERSION)) +
                 " on " + reinterpret_cast<const char*>(glGetString(GL_RENDERER)) + " (" + how + ")";
}

HeadlessContext::~HeadlessContext() {
  // The display is left initialised: EGL displays are shared within a process, and terminating
  // one would break any other context made on it.
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (surface_) eglDestroySurface(display_, surface_);
  eglDestroyContext(display_, context_);
}

void HeadlessContext::make_current() {
  if (!eglMakeCurrent(display_, surface_, surface_, context_)) {
    throw Error("cannot make the OpenGL context current (" + egl_error_text(eglGetError()) + ")");
  }
}

}  // namespace segmesh::render
