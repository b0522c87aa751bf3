// Drawing with Mesa's off-screen OpenGL (OSMesa): fixed-function GL 1.x, and a GLSL 1.20
// program that lights point and spot lights per pixel (LitProgram).
// libOSMesa is opened at run time (dlopen), so a machine without it runs
// every world that renders nothing and gets a clear message otherwise.
// One context per thread, made once and kept for the process.
#include "modules/rendering/render.h"

#include <GL/gl.h>
#include <GL/osmesa.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>

#include "framework/error.h"
#include "framework/shared_library.h"
#include "modules/rendering/geometry.h"

namespace swarmsim::rendering {

namespace {

// The GL and OSMesa entry points we use, from the library opened at run time.
struct Gl {
  // clang-format off
#define SWARMSIM_GL_FUNCTIONS(X) \
  X(glViewport) X(glClearColor) X(glClear) X(glMatrixMode) X(glLoadIdentity) \
  X(glLoadMatrixd) X(glEnable) X(glDisable) X(glLightfv) X(glLightf) \
  X(glLightModelfv) X(glLightModeli) X(glColorMaterial) X(glEnableClientState) \
  X(glDisableClientState) X(glVertexPointer) X(glNormalPointer) X(glColorPointer) \
  X(glTexCoordPointer) X(glDrawArrays) X(glFinish) X(glReadPixels) \
  X(glPixelStorei) X(glGenTextures) X(glBindTexture) X(glTexImage2D) \
  X(glTexParameteri) X(glShadeModel) X(glDepthFunc) X(glColor3f) X(glNormal3f) \
  X(glTexEnvi) X(glDepthMask) X(glGetError) X(glLineWidth)
  // clang-format on
#define SWARMSIM_DECLARE(name) decltype(&::name) name = nullptr;
  SWARMSIM_GL_FUNCTIONS(SWARMSIM_DECLARE)
#undef SWARMSIM_DECLARE
  // GL 2.0's shaders, for point and spot lights lit per pixel (LitProgram);
  // optional: without them every light is lit per vertex, as before.
  // clang-format off
#define SWARMSIM_GL_SHADER_FUNCTIONS(X) \
  X(glCreateShader) X(glShaderSource) X(glCompileShader) X(glGetShaderiv) \
  X(glCreateProgram) X(glAttachShader) X(glLinkProgram) X(glGetProgramiv) \
  X(glUseProgram) X(glGetUniformLocation) X(glUniform1i)
  // clang-format on
#define SWARMSIM_DECLARE(name) PFN##name##PROC name = nullptr;
  struct Shaders {
    using PFNglCreateShaderPROC = GLuint (*)(GLenum);
    using PFNglShaderSourcePROC = void (*)(GLuint, GLsizei, const char* const*, const GLint*);
    using PFNglCompileShaderPROC = void (*)(GLuint);
    using PFNglGetShaderivPROC = void (*)(GLuint, GLenum, GLint*);
    using PFNglCreateProgramPROC = GLuint (*)();
    using PFNglAttachShaderPROC = void (*)(GLuint, GLuint);
    using PFNglLinkProgramPROC = void (*)(GLuint);
    using PFNglGetProgramivPROC = void (*)(GLuint, GLenum, GLint*);
    using PFNglUseProgramPROC = void (*)(GLuint);
    using PFNglGetUniformLocationPROC = GLint (*)(GLuint, const char*);
    using PFNglUniform1iPROC = void (*)(GLint, GLint);
    SWARMSIM_GL_SHADER_FUNCTIONS(SWARMSIM_DECLARE)
    bool present = false;
  } shaders;
#undef SWARMSIM_DECLARE
  decltype(&::OSMesaCreateContextExt) CreateContextExt = nullptr;
  decltype(&::OSMesaMakeCurrent) MakeCurrent = nullptr;
  decltype(&::OSMesaPixelStore) PixelStore = nullptr;
  std::string error;  // why the library could not be used
};

const Gl& Library() {
  static const Gl gl = [] {
    Gl g;
    // llvmpipe rasterises in the calling thread: images are small and drawn
    // many at a time, one per worker thread (its own rasteriser threads
    // would fight the scheduler's for the cores). A user's setting wins.
    setenv("LP_NUM_THREADS", "0", /*overwrite=*/0);
    const char* name = std::getenv("SWARMSIM_OSMESA_LIBRARY");  // tests name a missing one
    const std::string file = name != nullptr && *name != '\0' ? name : "libOSMesa.so.8";
    std::string why;
    void* lib = OpenSharedLibrary(file, &why);
    if (lib == nullptr) {
      // Installed, but no room to map it (a tight ulimit -v): installing
      // it was the wrong advice.
      const bool memory = why.find("annot allocate memory") != std::string::npos ||
                          why.find("failed to map segment") != std::string::npos;
      g.error = "rendering needs Mesa's off-screen OpenGL, " + file +
                (memory ? ", and there was no memory to load it (the machine, or a ulimit -v, "
                          "gave no more): "
                        : " (Debian package libosmesa6; tools/setup.sh installs it), and it "
                          "could not be loaded: ") +
                why;
      return g;
    }
    const auto sym = [&](const char* symbol) {
      void* p = FindSymbol(lib, symbol);
      if (p == nullptr && g.error.empty())
        g.error = file + " lacks " + symbol + ": not a usable OSMesa library";
      return p;
    };
    g.CreateContextExt =
        reinterpret_cast<decltype(g.CreateContextExt)>(sym("OSMesaCreateContextExt"));
    g.MakeCurrent = reinterpret_cast<decltype(g.MakeCurrent)>(sym("OSMesaMakeCurrent"));
    g.PixelStore = reinterpret_cast<decltype(g.PixelStore)>(sym("OSMesaPixelStore"));
#define SWARMSIM_LOAD(name) g.name = reinterpret_cast<decltype(g.name)>(sym(#name));
    SWARMSIM_GL_FUNCTIONS(SWARMSIM_LOAD)
#undef SWARMSIM_LOAD
    g.shaders.present = true;
#define SWARMSIM_LOAD(name)                                                            \
  g.shaders.name = reinterpret_cast<decltype(g.shaders.name)>(FindSymbol(lib, #name)); \
  g.shaders.present = g.shaders.present && g.shaders.name != nullptr;
    SWARMSIM_GL_SHADER_FUNCTIONS(SWARMSIM_LOAD)
#undef SWARMSIM_LOAD
    return g;
  }();
  return gl;
}

// One thread's context and colour buffer.
struct Context {
  OSMesaContext ctx = nullptr;
  std::vector<uint8_t> buffer;  // RGBA, rows bottom to top
  std::vector<float> depth;
  unsigned paint_texture = 0;
  const uint8_t* paint_source = nullptr;  // what the texture holds, and of which step
  int64_t paint_step = -2;
  // The per-pixel lighting program (LitProgram): 0 until made, or when the
  // library cannot make it (then lights are per vertex).
  unsigned lit_program = 0;
  bool lit_tried = false;
  int lit_lights = -1, lit_textured = -1, lit_paint = -1;  // its uniforms
};

Context& ThisThreadContext(const Gl& gl) {
  thread_local Context* context = nullptr;
  if (context == nullptr) {
    // Kept for the life of the process (reachable from here, never freed).
    static std::mutex mutex;
    static auto* contexts = new std::vector<Context*>();
    auto* c = new Context();
    c->ctx = gl.CreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
    if (c->ctx == nullptr) {
      delete c;
      throw Error("OSMesa could not create an OpenGL context");
    }
    const std::lock_guard lock(mutex);
    contexts->push_back(c);
    context = c;
  }
  return *context;
}

// GL's lighting equation as the fixed-function pipeline computes it per
// vertex (ambient model x colour, plus each light's diffuse x attenuation x
// spot factor x max(n.l, 0); two-sided; colour material), computed per
// pixel instead: a spot or point light aimed at the middle of a wall much
// larger than its cone lit no vertex of it, so per vertex the wall stayed
// dark (QA: a 15-degree spot on a 10 m wall). Directional lights give the
// same light at every point of a flat face either way, so a world without
// point or spot lights keeps the fixed-function pipeline (and its bytes).
constexpr const char* kLitVertexShader = R"(#version 120
varying vec3 eye_position;
varying vec3 eye_normal;
void main() {
  vec4 p = gl_ModelViewMatrix * gl_Vertex;
  eye_position = p.xyz / p.w;
  eye_normal = gl_NormalMatrix * gl_Normal;
  gl_FrontColor = gl_Color;
  gl_BackColor = gl_Color;
  gl_TexCoord[0] = gl_MultiTexCoord0;
  gl_Position = ftransform();
}
)";
constexpr const char* kLitFragmentShader = R"(#version 120
uniform int lights;
uniform int textured;
uniform sampler2D paint;
varying vec3 eye_position;
varying vec3 eye_normal;
void main() {
  vec3 n = normalize(eye_normal);
  if (!gl_FrontFacing) n = -n;
  vec3 colour = gl_Color.rgb;
  vec3 light = gl_LightModel.ambient.rgb;
  for (int i = 0; i < 8; ++i) {
    if (i >= lights) break;
    vec3 l;
    float attenuation = 1.0;
    if (gl_LightSource[i].position.w == 0.0) {
      l = normalize(gl_LightSource[i].position.xyz);
    } else {
      vec3 d = gl_LightSource[i].position.xyz - eye_position;
      float distance = length(d);
      l = d / distance;
      attenuation = 1.0 / (gl_LightSource[i].constantAttenuation +
                           gl_LightSource[i].linearAttenuation * distance +
                           gl_LightSource[i].quadraticAttenuation * distance * distance);
      if (gl_LightSource[i].spotCutoff <= 90.0) {
        float c = dot(-l, normalize(gl_LightSource[i].spotDirection));
        // GLSL leaves pow(0, 0) undefined; GL's spot factor is then 1.
        float e = gl_LightSource[i].spotExponent;
        attenuation *= c >= gl_LightSource[i].spotCosCutoff
                           ? (e == 0.0 ? 1.0 : pow(max(c, 0.0), e)) : 0.0;
      }
    }
    light += attenuation * max(dot(n, l), 0.0) * gl_LightSource[i].diffuse.rgb;
  }
  vec4 result = vec4(min(light * colour, vec3(1.0)), 1.0);
  if (textured != 0) result *= texture2D(paint, gl_TexCoord[0].st);
  gl_FragColor = result;
}
)";

// The context's per-pixel lighting program, made the first time it is
// asked for; 0 when it cannot be (no GL 2.0 in this library).
unsigned LitProgram(const Gl& gl, Context* c) {
  if (c->lit_tried) return c->lit_program;
  c->lit_tried = true;
  const auto& sh = gl.shaders;
  if (!sh.present) return 0;
  const auto compile = [&](GLenum kind, const char* text) -> GLuint {
    const GLuint shader = sh.glCreateShader(kind);
    sh.glShaderSource(shader, 1, &text, nullptr);
    sh.glCompileShader(shader);
    GLint ok = 0;
    sh.glGetShaderiv(shader, 0x8B81 /* GL_COMPILE_STATUS */, &ok);
    return ok ? shader : 0;
  };
  const GLuint vertex = compile(0x8B31 /* GL_VERTEX_SHADER */, kLitVertexShader);
  const GLuint fragment = compile(0x8B30 /* GL_FRAGMENT_SHADER */, kLitFragmentShader);
  if (vertex == 0 || fragment == 0) return 0;
  const GLuint program = sh.glCreateProgram();
  sh.glAttachShader(program, vertex);
  sh.glAttachShader(program, fragment);
  sh.glLinkProgram(program);
  GLint ok = 0;
  sh.glGetProgramiv(program, 0x8B82 /* GL_LINK_STATUS */, &ok);
  if (!ok) return 0;
  c->lit_lights = sh.glGetUniformLocation(program, "lights");
  c->lit_textured = sh.glGetUniformLocation(program, "textured");
  c->lit_paint = sh.glGetUniformLocation(program, "paint");
  c->lit_program = program;
  return program;
}

struct Mat4 {
  double m[16] = {};  // column-major
};

struct Eye {
  Vec3 x, y, z, p;  // the eye's axes in the world frame (looking along -z) and position
  Vec3 ToEye(const Vec3& w) const {
    const Vec3 d = w - p;
    return {x.Dot(d), y.Dot(d), z.Dot(d)};
  }
};

Eye EyeOf(const View& view) {
  const Quat& q = view.pose.q;
  return {q.Rotate({0, -1, 0}), q.Rotate({0, 0, 1}), q.Rotate({-1, 0, 0}), view.pose.p};
}

Mat4 ViewMatrix(const Eye& e) {
  Mat4 v;
  const Vec3 axes[3] = {e.x, e.y, e.z};
  for (int r = 0; r < 3; ++r) {
    v.m[0 + r] = axes[r].x;
    v.m[4 + r] = axes[r].y;
    v.m[8 + r] = axes[r].z;
    v.m[12 + r] = -axes[r].Dot(e.p);
  }
  v.m[15] = 1;
  return v;
}

Mat4 Projection(const View& view, double half_w, double half_h) {
  Mat4 p;
  const double n = view.near, f = view.far;
  if (view.orthographic) {
    p.m[0] = 1 / half_w;
    p.m[5] = 1 / half_h;
    p.m[10] = -2 / (f - n);
    p.m[14] = -(f + n) / (f - n);
    p.m[15] = 1;
  } else {
    p.m[0] = 1 / half_w;  // half_w, half_h: tangents of the half angles
    p.m[5] = 1 / half_h;
    p.m[10] = -(f + n) / (f - n);
    p.m[11] = -1;
    p.m[14] = -2 * f * n / (f - n);
  }
  return p;
}

// Does the bounding sphere reach into the view volume?
bool Visible(const DrawItem& item, const View& view, const Eye& eye, double half_w, double half_h) {
  const Vec3 c = eye.ToEye({item.center[0], item.center[1], item.center[2]});
  const double r = item.radius, d = -c.z;
  if (d < view.near - r || d > view.far + r) return false;
  if (view.orthographic) return std::abs(c.x) <= half_w + r && std::abs(c.y) <= half_h + r;
  // Side planes through the eye: |x| <= d tan(a), distance (|x| cos a - d sin a).
  const double cw = 1 / std::sqrt(1 + half_w * half_w), ch = 1 / std::sqrt(1 + half_h * half_h);
  return (std::abs(c.x) - d * half_w) * cw <= r && (std::abs(c.y) - d * half_h) * ch <= r;
}

void SetLights(const Gl& gl, const DrawList& list) {
  const float ambient_default[4] = {0.3f, 0.3f, 0.3f, 1};
  const float ambient_lit[4] = {0.2f, 0.2f, 0.2f, 1};
  gl.glLightModelfv(GL_LIGHT_MODEL_AMBIENT, list.scene_has_lights ? ambient_lit : ambient_default);
  for (int i = 0; i < 8; ++i) gl.glDisable(GL_LIGHT0 + i);
  const float black[4] = {0, 0, 0, 1};
  if (!list.scene_has_lights) {  // a sun from above, a little to the side (and the headlight)
    const float direction[4] = {0.3f, 0.2f, 1.0f, 0};
    const float white[4] = {0.5f, 0.5f, 0.5f, 1};
    gl.glLightfv(GL_LIGHT0, GL_POSITION, direction);
    gl.glLightfv(GL_LIGHT0, GL_DIFFUSE, white);
    gl.glLightfv(GL_LIGHT0, GL_SPECULAR, black);
    gl.glLightfv(GL_LIGHT0, GL_AMBIENT, black);
    gl.glLightf(GL_LIGHT0, GL_SPOT_CUTOFF, 180);
    gl.glEnable(GL_LIGHT0);
    gl.glEnable(GL_LIGHT1);  // the headlight, placed before the view matrix (Draw)
    return;
  }
  const size_t n = std::min<size_t>(8, list.lights.size());
  for (size_t i = 0; i < n; ++i) {
    const LightSource& l = list.lights[i];
    const GLenum id = static_cast<GLenum>(GL_LIGHT0 + i);
    const float color[4] = {static_cast<float>(l.color.x), static_cast<float>(l.color.y),
                            static_cast<float>(l.color.z), 1};
    gl.glLightfv(id, GL_DIFFUSE, color);
    gl.glLightfv(id, GL_SPECULAR, black);
    gl.glLightfv(id, GL_AMBIENT, black);
    if (l.kind == LightSource::kDirectional) {
      const float position[4] = {static_cast<float>(-l.direction.x),
                                 static_cast<float>(-l.direction.y),
                                 static_cast<float>(-l.direction.z), 0};
      gl.glLightfv(id, GL_POSITION, position);
      gl.glLightf(id, GL_SPOT_CUTOFF, 180);
    } else {
      const float position[4] = {static_cast<float>(l.position.x), static_cast<float>(l.position.y),
                                 static_cast<float>(l.position.z), 1};
      gl.glLightfv(id, GL_POSITION, position);
      if (l.kind == LightSource::kSpot) {
        const float direction[3] = {static_cast<float>(l.direction.x),
                                    static_cast<float>(l.direction.y),
                                    static_cast<float>(l.direction.z)};
        gl.glLightfv(id, GL_SPOT_DIRECTION, direction);
        gl.glLightf(id, GL_SPOT_CUTOFF, static_cast<float>(std::min(90.0, l.cutoff * 180 / M_PI)));
        gl.glLightf(id, GL_SPOT_EXPONENT, static_cast<float>(std::clamp(l.exponent, 0.0, 128.0)));
      } else {
        gl.glLightf(id, GL_SPOT_CUTOFF, 180);
      }
    }
    gl.glLightf(id, GL_CONSTANT_ATTENUATION, static_cast<float>(l.attenuation[0]));
    gl.glLightf(id, GL_LINEAR_ATTENUATION, static_cast<float>(l.attenuation[1]));
    gl.glLightf(id, GL_QUADRATIC_ATTENUATION, static_cast<float>(l.attenuation[2]));
    gl.glEnable(id);
  }
}

// The floor: a square under the eye reaching the far plane, then the paint
// layer's texture over its area, just above. `lit`: drawn with LitProgram.
void DrawFloor(const Gl& gl, Context* c, const DrawList& list, const View& view, bool lit) {
  // (An orthographic view sees as far sideways as its width, whatever its far plane.)
  const double s = view.far + std::abs(view.pose.p.z) + (view.orthographic ? view.ortho_width : 0);
  const float x0 = static_cast<float>(view.pose.p.x - s),
              x1 = static_cast<float>(view.pose.p.x + s);
  const float y0 = static_cast<float>(view.pose.p.y - s),
              y1 = static_cast<float>(view.pose.p.y + s);
  const float quad[18] = {x0, y0, 0, x1, y0, 0, x1, y1, 0, x0, y0, 0, x1, y1, 0, x0, y1, 0};
  gl.glDisableClientState(GL_NORMAL_ARRAY);
  gl.glDisableClientState(GL_COLOR_ARRAY);
  gl.glNormal3f(0, 0, 1);
  gl.glColor3f(0.92f, 0.92f, 0.90f);
  gl.glVertexPointer(3, GL_FLOAT, 0, quad);
  gl.glDrawArrays(GL_TRIANGLES, 0, 6);
  const FloorLayer& f = list.floor;
  if (f.present && f.width > 0 && f.height > 0) {
    if (c->paint_texture == 0) gl.glGenTextures(1, &c->paint_texture);
    gl.glBindTexture(GL_TEXTURE_2D, c->paint_texture);
    if (c->paint_source != f.rgb || c->paint_step != list.step) {
      gl.glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
      gl.glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, f.width, f.height, 0, GL_RGB, GL_UNSIGNED_BYTE,
                      f.rgb);
      gl.glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      gl.glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      c->paint_source = f.rgb;
      c->paint_step = list.step;
    }
    gl.glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    gl.glEnable(GL_TEXTURE_2D);
    if (lit) gl.shaders.glUniform1i(c->lit_textured, 1);
    const float z = 1e-4f;
    const float px0 = static_cast<float>(f.min_x), px1 = static_cast<float>(f.max_x);
    const float py0 = static_cast<float>(f.min_y), py1 = static_cast<float>(f.max_y);
    // Texture row 0 is the layer's row 0, at max_y.
    const float paint[18] = {px0, py0, z, px1, py0, z, px1, py1, z,
                             px0, py0, z, px1, py1, z, px0, py1, z};
    const float uv[12] = {0, 1, 1, 1, 1, 0, 0, 1, 1, 0, 0, 0};
    gl.glColor3f(1, 1, 1);
    gl.glEnableClientState(GL_TEXTURE_COORD_ARRAY);
    gl.glTexCoordPointer(2, GL_FLOAT, 0, uv);
    gl.glVertexPointer(3, GL_FLOAT, 0, paint);
    gl.glDrawArrays(GL_TRIANGLES, 0, 6);
    gl.glDisableClientState(GL_TEXTURE_COORD_ARRAY);
    gl.glDisable(GL_TEXTURE_2D);
    if (lit) gl.shaders.glUniform1i(c->lit_textured, 0);
  }
  gl.glEnableClientState(GL_NORMAL_ARRAY);
  gl.glEnableClientState(GL_COLOR_ARRAY);
}

}  // namespace

void Draw(const DrawList& list, const View& view, const DrawOptions& options, Image* image) {
  const Gl& gl = Library();
  if (!gl.error.empty()) throw Error(gl.error);
  if (view.width <= 0 || view.height <= 0 || view.width > 8192 || view.height > 8192)
    throw Error("image size " + std::to_string(view.width) + "x" + std::to_string(view.height) +
                " is outside 1..8192 pixels a side");
  Context& c = ThisThreadContext(gl);
  const size_t pixels = static_cast<size_t>(view.width) * static_cast<size_t>(view.height);
  c.buffer.resize(pixels * 4);
  if (!gl.MakeCurrent(c.ctx, c.buffer.data(), GL_UNSIGNED_BYTE, view.width, view.height))
    throw Error("OSMesa could not draw a " + std::to_string(view.width) + "x" +
                std::to_string(view.height) + " image");
  gl.PixelStore(OSMESA_Y_UP, 1);

  const double aspect = static_cast<double>(view.height) / view.width;
  const double half_w = view.orthographic ? view.ortho_width / 2 : std::tan(view.fov / 2);
  const double half_h = half_w * aspect;
  const Eye eye = EyeOf(view);

  gl.glViewport(0, 0, view.width, view.height);
  gl.glClearColor(static_cast<float>(options.background.x),
                  static_cast<float>(options.background.y),
                  static_cast<float>(options.background.z), 1);
  gl.glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  gl.glEnable(GL_DEPTH_TEST);
  gl.glDepthFunc(GL_LEQUAL);
  gl.glShadeModel(GL_SMOOTH);
  gl.glMatrixMode(GL_PROJECTION);
  gl.glLoadMatrixd(Projection(view, half_w, half_h).m);
  gl.glMatrixMode(GL_MODELVIEW);
  gl.glLoadIdentity();
  if (!list.scene_has_lights) {  // a headlight: from the eye along the view, in eye coordinates
    const float headlight[4] = {0, 0, 1, 0}, grey[4] = {0.45f, 0.45f, 0.45f, 1},
                black[4] = {0, 0, 0, 1};
    gl.glLightfv(GL_LIGHT1, GL_POSITION, headlight);
    gl.glLightfv(GL_LIGHT1, GL_DIFFUSE, grey);
    gl.glLightfv(GL_LIGHT1, GL_SPECULAR, black);
    gl.glLightfv(GL_LIGHT1, GL_AMBIENT, black);
    gl.glLightf(GL_LIGHT1, GL_SPOT_CUTOFF, 180);
  }
  gl.glLoadMatrixd(ViewMatrix(eye).m);
  SetLights(gl, list);  // positions in world coordinates, under the view matrix
  gl.glEnable(GL_LIGHTING);
  gl.glEnable(GL_NORMALIZE);
  gl.glEnable(GL_COLOR_MATERIAL);
  gl.glColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
  gl.glLightModeli(GL_LIGHT_MODEL_TWO_SIDE, 1);
  gl.glEnableClientState(GL_VERTEX_ARRAY);
  gl.glEnableClientState(GL_NORMAL_ARRAY);
  gl.glEnableClientState(GL_COLOR_ARRAY);
  // Point and spot lights: lit per pixel (LitProgram).
  const size_t lights = list.scene_has_lights ? std::min<size_t>(8, list.lights.size()) : 0;
  bool local_lights = false;
  for (size_t i = 0; i < lights; ++i)
    local_lights = local_lights || list.lights[i].kind != LightSource::kDirectional;
  const unsigned program = local_lights ? LitProgram(gl, &c) : 0;
  if (program != 0) {
    gl.shaders.glUseProgram(program);
    gl.shaders.glUniform1i(c.lit_lights, static_cast<int>(lights));
    gl.shaders.glUniform1i(c.lit_textured, 0);
    gl.shaders.glUniform1i(c.lit_paint, 0);
  }
  if (options.floor) DrawFloor(gl, &c, list, view, program != 0);

  gl.glVertexPointer(3, GL_FLOAT, 0, list.xyz.data());
  gl.glNormalPointer(GL_FLOAT, 0, list.normal.data());
  gl.glColorPointer(3, GL_UNSIGNED_BYTE, 0, list.rgb.data());
  // Runs of neighbouring visible items make one call each; lit items, then
  // emissive ones (LEDs) without lighting.
  for (const bool emissive : {false, true}) {
    if (emissive) {
      if (program != 0) gl.shaders.glUseProgram(0);  // unlit: the fixed pipeline
      gl.glDisable(GL_LIGHTING);
    }
    uint32_t run_first = 0, run_count = 0;
    for (const DrawItem& item : list.items) {
      bool draw = item.emissive == emissive;
      if (draw && options.visible != nullptr && item.slot != kNoSlot)
        draw = item.slot < options.visible->size() && (*options.visible)[item.slot] != 0;
      if (draw) draw = Visible(item, view, eye, half_w, half_h);
      if (draw && run_count > 0 && run_first + run_count == item.first) {
        run_count += item.count;
        continue;
      }
      if (run_count > 0) gl.glDrawArrays(GL_TRIANGLES, static_cast<GLint>(run_first), run_count);
      run_count = 0;
      if (draw) {
        run_first = item.first;
        run_count = item.count;
      }
    }
    if (run_count > 0) gl.glDrawArrays(GL_TRIANGLES, static_cast<GLint>(run_first), run_count);
  }
  // Rays (markers): unlit lines one pixel wide, in front of what they start in.
  if (!list.ray_xyz.empty()) {
    gl.glDisable(GL_LIGHTING);
    gl.glDisableClientState(GL_NORMAL_ARRAY);
    gl.glLineWidth(1);
    gl.glVertexPointer(3, GL_FLOAT, 0, list.ray_xyz.data());
    gl.glColorPointer(3, GL_UNSIGNED_BYTE, 0, list.ray_rgb.data());
    gl.glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(list.ray_xyz.size() / 3));
    gl.glEnableClientState(GL_NORMAL_ARRAY);
  }
  gl.glFinish();

  // Rows top to bottom.
  image->Resize(view.width, view.height);
  const size_t row = static_cast<size_t>(view.width);
  for (int y = 0; y < view.height; ++y) {
    const uint8_t* src = c.buffer.data() + static_cast<size_t>(view.height - 1 - y) * row * 4;
    uint8_t* dst = image->rgb.data() + static_cast<size_t>(y) * row * 3;
    for (size_t x = 0; x < row; ++x) {
      dst[3 * x] = src[4 * x];
      dst[3 * x + 1] = src[4 * x + 1];
      dst[3 * x + 2] = src[4 * x + 2];
    }
  }
  image->depth.clear();
  if (view.depth) {
    c.depth.resize(pixels);
    gl.glReadPixels(0, 0, view.width, view.height, GL_DEPTH_COMPONENT, GL_FLOAT, c.depth.data());
    image->depth.resize(pixels);
    const double n = view.near, f = view.far;
    for (int y = 0; y < view.height; ++y)
      for (size_t x = 0; x < row; ++x) {
        const double d = c.depth[static_cast<size_t>(view.height - 1 - y) * row + x];
        const double z = view.orthographic ? n + d * (f - n) : n * f / (f - d * (f - n));
        image->depth[static_cast<size_t>(y) * row + x] = static_cast<float>(d >= 1 ? f : z);
      }
  }
}

}  // namespace swarmsim::rendering
