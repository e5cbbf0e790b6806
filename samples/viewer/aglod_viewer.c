/* SPDX-License-Identifier: MIT */
/* aglod_viewer: an engine-style OpenGL 3.3 client of the aggrelod runtime, through its C API
 * only (aggrelod_runtime.h), with GLFW for the window and context.
 *
 *   aglod_viewer SCENE.aglod [--out DIR] [--frames N] [--near D] [--far D] [options]
 *
 * It flies a camera from --near to --far scene diameters away from the centre of the scene's
 * bounding box (geometric steps, elevation --elevation, azimuth turning by --sweep degrees),
 * and for every frame
 *   - selects the cut with frustum culling (aglod_select_view: fov 60 degrees, tau 1 px, no
 *     hysteresis unless --coarsen-ratio is given),
 *   - streams: uploads a node's positions, normals, colours and triangles to the GPU (one
 *     vertex array, one vertex buffer, one index buffer) when it enters the cut and deletes
 *     them when it leaves (aglod_selector_changes), never anything else,
 *   - draws every node of the cut with one glDrawElements each: per-vertex colours (sRGB in
 *     the file, linearised in the shader) lit by a sun and a sky/ground ambient term,
 *   - counts draw calls and triangles, and has the GPU count the triangles it was given
 *     (GL_PRIMITIVES_GENERATED query).
 * Rendering goes to an offscreen framebuffer of --width x --height pixels (default 1920 x
 * 1080), shown in the window unless --hidden. With --out it writes DIR/frames.csv (one row per
 * frame: the camera exactly as passed to the selection, the cut, the streaming, draw calls,
 * triangles, timings), DIR/screenshots.csv and DIR/near.png (first frame) and DIR/far.png
 * (last frame), plus DIR/far_zoom.png (the far view's bounding circle, enlarged). With
 * --compare-originals it also draws every original object at those two frames
 * (DIR/near_originals.png, DIR/far_originals.png) and the cut lit by its triangles' own normals, and reports the pixels
 * of the originals the cut leaves uncovered and the shading difference (docs/runtime.md).
 * --loop flies the path back and forth until the window is closed (or Esc). Headless: run it
 * under xvfb-run (Mesa llvmpipe), e.g.
 *   xvfb-run -a aglod_viewer out/forest/scene.aglod --out shots --hidden
 * Exit status 0 when every frame drew exactly the cut; 1 on an error or a streaming
 * inconsistency; 77 when no OpenGL 3.3 context can be created (no display, no driver). */
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <GL/glcorearb.h>

#include <aggrelod_runtime.h>

#include <stb_image_write.h> /* implementation in Debian's libstb */

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _WIN32
#include <direct.h>
#define make_dir(p) _mkdir(p)
#else
#include <sys/stat.h>
#define make_dir(p) mkdir((p), 0755)
#endif

#include "gl_functions.h"

#define DECLARE_GL(ret, name, params) static ret(APIENTRY* name) params;
AGLOD_VIEWER_GL_FUNCTIONS(DECLARE_GL)
#undef DECLARE_GL

static int load_gl(void) {
    int ok = 1;
#define LOAD_GL(ret, name, params)                                          \
    *(void**)(&name) = (void*)glfwGetProcAddress(#name);                     \
    if (!name) {                                                            \
        fprintf(stderr, "aglod_viewer: OpenGL function %s missing\n", #name); \
        ok = 0;                                                             \
    }
    AGLOD_VIEWER_GL_FUNCTIONS(LOAD_GL)
#undef LOAD_GL
    return ok;
}

static const double kPi = 3.14159265358979323846;
/* Background (sky) colour, sRGB bytes; the tests count the pixels that differ from it. */
static const unsigned char kBackground[3] = {186, 206, 228};

typedef struct options {
    const char* scene;
    const char* out;
    int frames;
    double near_diameters, far_diameters;
    int width, height;
    double fov_degrees, tau, coarsen_ratio;
    double elevation_degrees, azimuth_degrees, sweep_degrees;
    int up; /* 0, 1, 2 = x, y, z; -1 = the scene box's shortest axis */
    int hidden, loop, compare_originals;
} options;

static void usage(void) {
    fprintf(stderr,
            "usage: aglod_viewer SCENE.aglod [--out DIR] [--frames N (default 24)]\n"
            "         [--near D (default 0.3)] [--far D (default 16)]   scene diameters from the centre\n"
            "         [--width W (1920)] [--height H (1080)] [--fov DEG (60)] [--tau PX (1)]\n"
            "         [--coarsen-ratio R (1 = no hysteresis)] [--elevation DEG (25)]\n"
            "         [--azimuth DEG (30)] [--sweep DEG (60)] [--up x|y|z|auto (auto: the scene box's\n"
            "         shortest axis)] [--hidden] [--loop] [--compare-originals]\n");
}

static int parse_options(int argc, char** argv, options* o) {
    o->scene = NULL;
    o->out = NULL;
    o->frames = 24;
    o->near_diameters = 0.3;
    o->far_diameters = 16;
    o->width = 1920;
    o->height = 1080;
    o->fov_degrees = 60;
    o->tau = 1;
    o->coarsen_ratio = 1;
    o->elevation_degrees = 25;
    o->azimuth_degrees = 30;
    o->sweep_degrees = 60;
    o->up = -1;
    o->hidden = 0;
    o->loop = 0;
    o->compare_originals = 0;
    for (int i = 1; i < argc; ++i) {
        const char* a = argv[i];
        if (strcmp(a, "--hidden") == 0) { o->hidden = 1; continue; }
        if (strcmp(a, "--loop") == 0) { o->loop = 1; continue; }
        if (strcmp(a, "--compare-originals") == 0) { o->compare_originals = 1; continue; }
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) { usage(); exit(0); }
        if (a[0] != '-') {
            if (o->scene) { usage(); return 0; }
            o->scene = a;
            continue;
        }
        if (i + 1 >= argc) {
            fprintf(stderr, "aglod_viewer: %s needs a value\n", a);
            return 0;
        }
        const char* v = argv[++i];
        char* end = NULL;
        const double x = strtod(v, &end);
        const int numeric = end && end != v && *end == '\0' && isfinite(x);
        if (strcmp(a, "--out") == 0) { o->out = v; continue; }
        if (strcmp(a, "--up") == 0) {
            if (strcmp(v, "auto") == 0) o->up = -1;
            else if (strlen(v) == 1 && v[0] >= 'x' && v[0] <= 'z') o->up = v[0] - 'x';
            else {
                fprintf(stderr, "aglod_viewer: --up: x, y, z or auto, not '%s'\n", v);
                return 0;
            }
            continue;
        }
        if (!numeric) {
            fprintf(stderr, "aglod_viewer: %s: '%s' is not a number\n", a, v);
            return 0;
        }
        if (strcmp(a, "--frames") == 0) o->frames = (int)x;
        else if (strcmp(a, "--near") == 0) o->near_diameters = x;
        else if (strcmp(a, "--far") == 0) o->far_diameters = x;
        else if (strcmp(a, "--width") == 0) o->width = (int)x;
        else if (strcmp(a, "--height") == 0) o->height = (int)x;
        else if (strcmp(a, "--fov") == 0) o->fov_degrees = x;
        else if (strcmp(a, "--tau") == 0) o->tau = x;
        else if (strcmp(a, "--coarsen-ratio") == 0) o->coarsen_ratio = x;
        else if (strcmp(a, "--elevation") == 0) o->elevation_degrees = x;
        else if (strcmp(a, "--azimuth") == 0) o->azimuth_degrees = x;
        else if (strcmp(a, "--sweep") == 0) o->sweep_degrees = x;
        else {
            fprintf(stderr, "aglod_viewer: unknown option %s\n", a);
            usage();
            return 0;
        }
    }
    if (!o->scene) { usage(); return 0; }
    if (o->frames < 1 || o->near_diameters <= 0 || o->far_diameters <= 0 || o->width < 16 || o->height < 16 ||
        o->width > 8192 || o->height > 8192 || o->fov_degrees <= 0 || o->fov_degrees >= 180 || o->tau <= 0 ||
        o->coarsen_ratio <= 0 || o->coarsen_ratio > 1) {
        fprintf(stderr, "aglod_viewer: option out of range (frames >= 1, distances > 0, 16 <= size <= 8192, "
                        "0 < fov < 180, tau > 0, 0 < coarsen ratio <= 1)\n");
        return 0;
    }
    return 1;
}

/* ---- small vector / matrix helpers (column-major 4x4, as OpenGL reads them) ---- */

static void normalize3(double v[3]) {
    const double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0) { v[0] /= l; v[1] /= l; v[2] /= l; }
}
static void cross3(const double a[3], const double b[3], double out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}
/* projection * view for a camera at eye looking along forward (unit), up hint. */
static void view_projection(const double eye[3], const double forward[3], const double up_hint[3], double fov_y,
                            double aspect, double z_near, double z_far, float out[16]) {
    double s[3], u[3];
    cross3(forward, up_hint, s);
    normalize3(s);
    cross3(s, forward, u);
    double view[16] = {s[0], u[0], -forward[0], 0, s[1], u[1], -forward[1], 0, s[2], u[2], -forward[2], 0,
                       0,    0,    0,           1};
    view[12] = -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]);
    view[13] = -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    view[14] = forward[0] * eye[0] + forward[1] * eye[1] + forward[2] * eye[2];
    const double f = 1.0 / tan(fov_y / 2);
    double proj[16] = {0};
    proj[0] = f / aspect;
    proj[5] = f;
    proj[10] = (z_far + z_near) / (z_near - z_far);
    proj[11] = -1;
    proj[14] = 2 * z_far * z_near / (z_near - z_far);
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) {
            double sum = 0;
            for (int k = 0; k < 4; ++k) sum += proj[k * 4 + r] * view[c * 4 + k];
            out[c * 4 + r] = (float)sum;
        }
}

static double now_ms(void) {
    struct timespec t;
    timespec_get(&t, TIME_UTC);
    return 1e3 * (double)t.tv_sec + 1e-6 * (double)t.tv_nsec;
}

/* ---- shaders ---- */

static const char* kVertexShader =
    "#version 330 core\n"
    "layout(location = 0) in vec3 position;\n"
    "layout(location = 1) in vec3 normal;\n"
    "layout(location = 2) in vec4 color;\n" /* sRGB bytes, normalised */
    "uniform mat4 view_projection;\n"
    "out vec3 v_position;\n"
    "out vec3 v_normal;\n"
    "out vec4 v_color;\n"
    "void main() {\n"
    "  v_position = position;\n"
    "  v_normal = normal;\n"
    "  v_color = color;\n"
    "  gl_Position = view_projection * vec4(position, 1.0);\n"
    "}\n";

static const char* kFragmentShader =
    "#version 330 core\n"
    "in vec3 v_position;\n"
    "in vec3 v_normal;\n"
    "in vec4 v_color;\n"
    "uniform vec3 sun;\n" /* unit, towards the sun, world space */
    "uniform vec3 up;\n"  /* unit, the scene's up axis */
    "uniform vec3 eye;\n"
    "uniform int faceted;\n" /* 1: the triangles' own normals instead of the file's (a check) */
    "out vec4 frag;\n"
    "vec3 to_linear(vec3 c) {\n"
    "  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));\n"
    "}\n"
    "vec3 to_srgb(vec3 c) {\n"
    "  c = clamp(c, 0.0, 1.0);\n"
    "  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));\n"
    "}\n"
    "void main() {\n"
    "  vec3 n = normalize(v_normal);\n"
    "  if (!gl_FrontFacing) n = -n;\n" /* open originals seen from behind */
    "  if (faceted == 1) {\n"
    "    n = normalize(cross(dFdx(v_position), dFdy(v_position)));\n"
    "    if (dot(n, eye - v_position) < 0.0) n = -n;\n"
    "  }\n"
    "  vec3 base = to_linear(v_color.rgb);\n"
    "  float diffuse = max(dot(n, sun), 0.0);\n"
    "  vec3 ambient = mix(vec3(0.20, 0.18, 0.16), vec3(0.38, 0.44, 0.55), 0.5 + 0.5 * dot(n, up));\n"
    "  vec3 lit = base * (ambient + vec3(1.0, 0.96, 0.88) * 0.85 * diffuse);\n"
    "  frag = vec4(to_srgb(lit), 1.0);\n"
    "}\n";

static GLuint compile(GLenum type, const char* source) {
    const GLuint s = glCreateShader(type);
    glShaderSource(s, 1, &source, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[2048];
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        fprintf(stderr, "aglod_viewer: shader: %s\n", log);
        glDeleteShader(s);
        return 0;
    }
    return s;
}

static GLuint make_program(void) {
    const GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader), fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
    if (!vs || !fs) return 0;
    const GLuint p = glCreateProgram();
    glAttachShader(p, vs);
    glAttachShader(p, fs);
    glLinkProgram(p);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[2048];
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        fprintf(stderr, "aglod_viewer: program: %s\n", log);
        glDeleteProgram(p);
        return 0;
    }
    return p;
}

/* ---- GPU residency of node meshes (what an engine's streaming does) ---- */

typedef struct gpu_mesh {
    GLuint vao, vbo, ibo;
    GLsizei index_count;
    uint8_t resident;
    double bytes; /* GPU memory of the three buffers */
} gpu_mesh;

typedef struct streaming {
    gpu_mesh* meshes; /* one per node */
    uint32_t resident, uploads, frees, errors;
    double resident_bytes;
} streaming;

static void upload(const aglod_file* file, streaming* s, uint32_t node) {
    gpu_mesh* m = &s->meshes[node];
    if (m->resident) {
        fprintf(stderr, "aglod_viewer: node %u entered the cut twice\n", node);
        ++s->errors;
        return;
    }
    const float *positions = NULL, *normals = NULL;
    const uint32_t* indices = NULL;
    const uint8_t* colors = NULL;
    uint32_t vertex_count = 0, index_count = 0, normal_count = 0, color_count = 0;
    if (!aglod_node_mesh(file, node, &positions, &vertex_count, &indices, &index_count) ||
        !aglod_node_normals(file, node, &normals, &normal_count) ||
        !aglod_node_colors(file, node, &colors, &color_count) || normal_count != vertex_count ||
        color_count != vertex_count) {
        fprintf(stderr, "aglod_viewer: node %u: no mesh, or normals/colours that do not match it\n", node);
        ++s->errors;
        return;
    }
    const GLsizeiptr pos_bytes = (GLsizeiptr)vertex_count * 12, col_bytes = (GLsizeiptr)vertex_count * 4;
    glGenVertexArrays(1, &m->vao);
    glBindVertexArray(m->vao);
    glGenBuffers(1, &m->vbo);
    glBindBuffer(GL_ARRAY_BUFFER, m->vbo);
    glBufferData(GL_ARRAY_BUFFER, 2 * pos_bytes + col_bytes, NULL, GL_STATIC_DRAW);
    glBufferSubData(GL_ARRAY_BUFFER, 0, pos_bytes, positions);
    glBufferSubData(GL_ARRAY_BUFFER, pos_bytes, pos_bytes, normals);
    glBufferSubData(GL_ARRAY_BUFFER, 2 * pos_bytes, col_bytes, colors);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 12, (const void*)0);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 12, (const void*)(size_t)pos_bytes);
    glVertexAttribPointer(2, 4, GL_UNSIGNED_BYTE, GL_TRUE, 4, (const void*)(size_t)(2 * pos_bytes));
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    glEnableVertexAttribArray(2);
    glGenBuffers(1, &m->ibo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m->ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)index_count * 4, indices, GL_STATIC_DRAW);
    glBindVertexArray(0);
    m->index_count = (GLsizei)index_count;
    m->resident = 1;
    ++s->resident;
    ++s->uploads;
    m->bytes = (double)(2 * pos_bytes + col_bytes) + 4.0 * index_count;
    s->resident_bytes += m->bytes;
}

static void release(streaming* s, uint32_t node) {
    gpu_mesh* m = &s->meshes[node];
    if (!m->resident) {
        fprintf(stderr, "aglod_viewer: node %u left the cut without having entered it\n", node);
        ++s->errors;
        return;
    }
    glDeleteVertexArrays(1, &m->vao);
    glDeleteBuffers(1, &m->vbo);
    glDeleteBuffers(1, &m->ibo);
    s->resident_bytes -= m->bytes;
    memset(m, 0, sizeof *m);
    --s->resident;
    ++s->frees;
}

/* One frame's drawing state: the offscreen target and the program with its uniforms. */
typedef struct renderer {
    GLuint fbo, program;
    GLint u_view_projection, u_sun, u_up, u_eye, u_faceted;
    int width, height;
} renderer;

typedef struct pass_uniforms {
    float view_projection[16], sun[3], up[3], eye[3];
    int faceted;
} pass_uniforms;

static void begin_pass(const renderer* r, const pass_uniforms* u) {
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    glViewport(0, 0, r->width, r->height);
    glClearColor(kBackground[0] / 255.0f, kBackground[1] / 255.0f, kBackground[2] / 255.0f, 1.0f);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE); /* originals may be open or inconsistently wound */
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glUseProgram(r->program);
    glUniformMatrix4fv(r->u_view_projection, 1, GL_FALSE, u->view_projection);
    glUniform3fv(r->u_sun, 1, u->sun);
    glUniform3fv(r->u_up, 1, u->up);
    glUniform3fv(r->u_eye, 1, u->eye);
    glUniform1i(r->u_faceted, u->faceted);
}

/* One draw call per node with triangles; counts them. */
static void draw_mesh(const gpu_mesh* m, uint32_t* draws, unsigned long long* triangles) {
    if (m->index_count == 0) return;
    glBindVertexArray(m->vao);
    glDrawElements(GL_TRIANGLES, m->index_count, GL_UNSIGNED_INT, (const void*)0);
    ++*draws;
    *triangles += (unsigned long long)(m->index_count / 3);
}

static void read_pixels(const renderer* r, unsigned char* rgb) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, r->fbo);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, r->width, r->height, GL_RGB, GL_UNSIGNED_BYTE, rgb);
}

static int is_background(const unsigned char* p) {
    return p[0] == kBackground[0] && p[1] == kBackground[1] && p[2] == kBackground[2];
}

static void apply_changes(const aglod_file* file, const aglod_selector* selector, streaming* s) {
    aglod_cut_changes changes;
    if (!aglod_selector_changes(selector, &changes)) {
        ++s->errors;
        return;
    }
    for (uint32_t i = 0; i < changes.left_count; ++i) release(s, changes.left[i]);
    for (uint32_t i = 0; i < changes.entered_count; ++i) upload(file, s, changes.entered[i]);
}

/* ---- screenshots ---- */

static int write_png(const char* path, int w, int h, unsigned char* rgb, double* coverage) {
    size_t covered = 0;
    for (size_t i = 0; i < (size_t)w * (size_t)h; ++i) covered += is_background(rgb + 3 * i) ? 0 : 1;
    *coverage = (double)covered / ((double)w * (double)h);
    stbi_flip_vertically_on_write(1); /* GL rows go bottom-up */
    return stbi_write_png(path, w, h, 3, rgb, 3 * w) != 0;
}

/* The square around (cx, cy) (pixels from the top left) of half side `half`, enlarged with
 * nearest-neighbour sampling to about 600 pixels: a far view made visible. */
static int write_zoom(const char* path, int w, int h, const unsigned char* rgb, double cx, double cy, double half) {
    int side = (int)ceil(2 * half);
    if (side < 8) side = 8;
    if (side > w) side = w;
    if (side > h) side = h;
    int x0 = (int)floor(cx - 0.5 * side), y0 = (int)floor(cy - 0.5 * side);
    if (x0 < 0) x0 = 0;
    if (y0 < 0) y0 = 0;
    if (x0 + side > w) x0 = w - side;
    if (y0 + side > h) y0 = h - side;
    int zoom = 600 / side;
    if (zoom < 1) zoom = 1;
    const int out = side * zoom;
    unsigned char* img = (unsigned char*)malloc((size_t)out * (size_t)out * 3);
    if (!img) return 0;
    for (int y = 0; y < out; ++y)
        for (int x = 0; x < out; ++x) {
            const int sx = x0 + x / zoom, sy = y0 + y / zoom;   /* top-down */
            const unsigned char* p = rgb + 3 * ((size_t)(h - 1 - sy) * (size_t)w + (size_t)sx);
            memcpy(img + 3 * ((size_t)y * (size_t)out + (size_t)x), p, 3);
        }
    stbi_flip_vertically_on_write(0);
    const int ok = stbi_write_png(path, out, out, 3, img, 3 * out) != 0;
    free(img);
    return ok;
}

static void glfw_error(int code, const char* text) { fprintf(stderr, "aglod_viewer: GLFW error %d: %s\n", code, text); }

int main(int argc, char** argv) {
    options o;
    if (!parse_options(argc, argv, &o)) return 2;

    aglod_file* file = NULL;
    aglod_status status = aglod_open_file(o.scene, &file);
    if (status != AGLOD_OK) {
        fprintf(stderr, "aglod_viewer: %s (%s)\n", aglod_last_error(), aglod_status_string(status));
        return 1;
    }
    const uint32_t node_count = aglod_node_count(file);
    float lo[3], hi[3];
    aglod_scene_bounds(file, lo, hi);
    double center[3], radius = 0;
    for (int k = 0; k < 3; ++k) {
        center[k] = 0.5 * ((double)lo[k] + (double)hi[k]);
        radius += 0.25 * ((double)hi[k] - (double)lo[k]) * ((double)hi[k] - (double)lo[k]);
    }
    radius = sqrt(radius); /* the box's circumscribed sphere */
    int up_axis = o.up;
    if (up_axis < 0) { /* outdoor scenes spread wider than they are tall; y on ties */
        up_axis = 1;
        for (int k = 0; k < 3; ++k)
            if (hi[k] - lo[k] < hi[up_axis] - lo[up_axis]) up_axis = k;
    }
    /* Horizontal axes (a1, a2, up) right-handed, as bench_lod_budget orbits: z up -> x, y;
     * y up -> z, x; x up -> y, z. */
    const int a1 = (up_axis + 1) % 3, a2 = (up_axis + 2) % 3;
    if (!(radius > 0)) {
        fprintf(stderr, "aglod_viewer: %s: empty scene\n", o.scene);
        aglod_close(file);
        return 1;
    }

    glfwSetErrorCallback(glfw_error);
    if (!glfwInit()) {
        fprintf(stderr, "aglod_viewer: SKIPPED: no display for GLFW (run under xvfb-run for headless use)\n");
        aglod_close(file);
        return 77;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_VISIBLE, o.hidden ? GLFW_FALSE : GLFW_TRUE);
    int window_w = o.width, window_h = o.height;
    while (window_w > 1600 || window_h > 900) { window_w /= 2; window_h /= 2; }
    GLFWwindow* window = glfwCreateWindow(o.hidden ? 64 : window_w, o.hidden ? 64 : window_h, "aglod_viewer", NULL, NULL);
    if (!window) {
        fprintf(stderr, "aglod_viewer: SKIPPED: no OpenGL 3.3 core context (install Mesa: libgl1-mesa-dri)\n");
        glfwTerminate();
        aglod_close(file);
        return 77;
    }
    glfwMakeContextCurrent(window);
    glfwSwapInterval(0);
    if (!load_gl()) {
        glfwDestroyWindow(window);
        glfwTerminate();
        aglod_close(file);
        return 77;
    }
    printf("aglod_viewer: %s: %u nodes, %u objects, bounding sphere radius %.4g; OpenGL %s, %s\n", o.scene,
           node_count, aglod_object_count(file), radius, (const char*)glGetString(GL_VERSION),
           (const char*)glGetString(GL_RENDERER));

    /* Offscreen target: colour + depth at the viewport size. */
    GLuint fbo = 0, color_rb = 0, depth_rb = 0;
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glGenRenderbuffers(1, &color_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, color_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, o.width, o.height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_rb);
    glGenRenderbuffers(1, &depth_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, depth_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, o.width, o.height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_rb);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        fprintf(stderr, "aglod_viewer: offscreen framebuffer %dx%d incomplete\n", o.width, o.height);
        return 1;
    }
    const GLuint program = make_program();
    if (!program) return 1;
    renderer r;
    r.fbo = fbo;
    r.program = program;
    r.u_view_projection = glGetUniformLocation(program, "view_projection");
    r.u_sun = glGetUniformLocation(program, "sun");
    r.u_up = glGetUniformLocation(program, "up");
    r.u_eye = glGetUniformLocation(program, "eye");
    r.u_faceted = glGetUniformLocation(program, "faceted");
    r.width = o.width;
    r.height = o.height;
    GLuint query = 0;
    glGenQueries(1, &query);

    FILE* csv = NULL;
    FILE* shots = NULL;
    char path[4096];
    if (o.out) {
        if (make_dir(o.out) != 0 && errno != EEXIST) {
            fprintf(stderr, "aglod_viewer: cannot create %s: %s\n", o.out, strerror(errno));
            return 1;
        }
        snprintf(path, sizeof path, "%s/frames.csv", o.out);
        csv = fopen(path, "w");
        snprintf(path, sizeof path, "%s/screenshots.csv", o.out);
        shots = fopen(path, "w");
        if (!csv || !shots) {
            fprintf(stderr, "aglod_viewer: cannot write into %s\n", o.out);
            return 1;
        }
        fprintf(csv, "frame,distance_diameters,eye_x,eye_y,eye_z,forward_x,forward_y,forward_z,up_x,up_y,up_z,"
                     "fov_y,aspect,viewport_height,near,far,tau,coarsen_ratio,cut_nodes,proxies,originals,culled,"
                     "entered,left,uploads,frees,resident,missing,draw_calls,triangles,gpu_primitives,select_ms,"
                     "frame_ms\n");
        fprintf(shots, "file,frame,width,height,sphere_x_px,sphere_y_px,sphere_radius_px,background_r,background_g,"
                       "background_b,coverage,originals_coverage,missing_share,extra_share,shading_difference\n");
    }

    /* Streaming: creating the selector is the first change (the roots enter). */
    streaming s;
    memset(&s, 0, sizeof s);
    s.meshes = (gpu_mesh*)calloc(node_count ? node_count : 1, sizeof(gpu_mesh));
    aglod_selector* selector = aglod_selector_create(file);
    if (!s.meshes || !selector) {
        fprintf(stderr, "aglod_viewer: out of memory (%s)\n", aglod_last_error());
        return 1;
    }
    apply_changes(file, selector, &s);

    unsigned char* pixels = (unsigned char*)malloc((size_t)o.width * (size_t)o.height * 3);
    /* --compare-originals: every original object, uploaded once on first use, drawn at the
     * screenshot frames into a second picture. */
    unsigned char* reference_pixels =
        o.compare_originals ? (unsigned char*)malloc((size_t)o.width * (size_t)o.height * 3) : NULL;
    streaming reference;
    memset(&reference, 0, sizeof reference);
    reference.meshes = o.compare_originals ? (gpu_mesh*)calloc(node_count ? node_count : 1, sizeof(gpu_mesh)) : NULL;
    if (!pixels || (o.compare_originals && (!reference_pixels || !reference.meshes))) {
        fprintf(stderr, "aglod_viewer: out of memory\n");
        return 1;
    }
    double sun[3] = {0, 0, 0}, up[3] = {0, 0, 0};
    sun[a1] = 0.45;
    sun[a2] = 0.35;
    sun[up_axis] = 0.80;
    up[up_axis] = 1;
    normalize3(sun);
    printf("aglod_viewer: up axis %c; path %.3g -> %.3g diameters, %d frames, %dx%d px, fov %.3g deg, tau %.3g px\n",
           "xyz"[up_axis], o.near_diameters, o.far_diameters, o.frames, o.width, o.height, o.fov_degrees, o.tau);
    const double fov_y = o.fov_degrees * kPi / 180.0, aspect = (double)o.width / (double)o.height;
    const double elevation = o.elevation_degrees * kPi / 180.0;
    uint32_t frames_bad = 0;
    unsigned long long total_draws = 0, total_triangles = 0;
    int frame = 0, pass = 0;
    for (;; ++frame) {
        const int i = frame % o.frames;
        if (frame > 0 && i == 0) {
            if (!o.loop || glfwWindowShouldClose(window)) break;
            ++pass;
        }
        /* Camera on the path: near -> far (then back when looping). */
        const int step = (pass % 2 == 0) ? i : o.frames - 1 - i;
        const double t = o.frames > 1 ? (double)step / (double)(o.frames - 1) : 0.0;
        const double diameters = o.near_diameters * pow(o.far_diameters / o.near_diameters, t);
        const double d = diameters * 2 * radius;
        const double azimuth = (o.azimuth_degrees + o.sweep_degrees * t) * kPi / 180.0;
        double eye[3] = {center[0], center[1], center[2]};
        eye[a1] += d * cos(elevation) * cos(azimuth);
        eye[a2] += d * cos(elevation) * sin(azimuth);
        eye[up_axis] += d * sin(elevation);
        double forward[3] = {center[0] - eye[0], center[1] - eye[1], center[2] - eye[2]};
        normalize3(forward);
        /* Depth range: the scene's sphere, with a margin; never a near plane at 0. */
        const double z_near = fmax(1e-3 * radius, 0.5 * (d - radius)), z_far = d + 1.5 * radius;

        /* The camera exactly as the selection gets it (floats), also written to the CSV. */
        aglod_view_camera camera;
        for (int k = 0; k < 3; ++k) {
            camera.position[k] = (float)eye[k];
            camera.forward[k] = (float)forward[k];
            camera.up[k] = (float)up[k];
        }
        camera.fov_y = (float)fov_y;
        camera.viewport_height = (float)o.height;
        camera.aspect = (float)aspect;
        camera.near_distance = (float)z_near;
        camera.far_distance = (float)z_far;

        const double t0 = now_ms();
        aglod_cut cut;
        status = aglod_select_view(selector, &camera, (float)o.tau, (float)o.coarsen_ratio, &cut);
        const double t1 = now_ms();
        if (status != AGLOD_OK) {
            fprintf(stderr, "aglod_viewer: selection failed: %s\n", aglod_last_error());
            return 1;
        }
        uint32_t culled = 0;
        aglod_culled_nodes(selector, &culled);
        aglod_cut_changes changes;
        aglod_selector_changes(selector, &changes);
        const uint32_t uploads_before = s.uploads, frees_before = s.frees;
        apply_changes(file, selector, &s);

        /* Draw the cut. */
        pass_uniforms uniforms;
        view_projection(eye, forward, up, fov_y, aspect, z_near, z_far, uniforms.view_projection);
        for (int k = 0; k < 3; ++k) {
            uniforms.sun[k] = (float)sun[k];
            uniforms.up[k] = (float)up[k];
            uniforms.eye[k] = (float)eye[k];
        }
        uniforms.faceted = 0;
        begin_pass(&r, &uniforms);
        uint32_t draws = 0, missing = 0;
        unsigned long long triangles = 0;
        glBeginQuery(GL_PRIMITIVES_GENERATED, query);
        for (uint32_t n = 0; n < cut.node_count; ++n) {
            const gpu_mesh* m = &s.meshes[cut.nodes[n]];
            if (!m->resident) { /* the streaming missed it: an error, the frame is incomplete */
                ++missing;
                continue;
            }
            draw_mesh(m, &draws, &triangles);
        }
        glEndQuery(GL_PRIMITIVES_GENERATED);
        glBindVertexArray(0);
        GLuint primitives = 0;
        glGetQueryObjectuiv(query, GL_QUERY_RESULT, &primitives);
        glFinish();
        const double t2 = now_ms();
        const GLenum gl_error = glGetError();
        if (gl_error != GL_NO_ERROR) {
            fprintf(stderr, "aglod_viewer: frame %d: OpenGL error 0x%x\n", frame, gl_error);
            ++frames_bad;
        }
        /* The resident set must be the cut, exactly. */
        if (missing || s.resident != cut.node_count || primitives != triangles) ++frames_bad;
        total_draws += draws;
        total_triangles += triangles;

        if (pass == 0) {
            printf("frame %3d  %6.2f diameters  cut %5u nodes (%u proxies, %u originals), %u culled; "
                   "+%u -%u resident %u (%.2f MB); %u draw calls, %llu triangles (GPU %u); select %.3f ms, "
                   "frame %.1f ms\n",
                   frame, diameters, cut.node_count, cut.proxy_count, cut.original_count, culled,
                   changes.entered_count, changes.left_count, s.resident, s.resident_bytes / 1048576.0, draws,
                   triangles, primitives, t1 - t0, t2 - t0);
            if (csv)
                fprintf(csv,
                        "%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,"
                        "%u,%u,%u,%u,%u,%u,%u,%u,%u,%u,%u,%llu,%u,%.4f,%.3f\n",
                        frame, diameters, camera.position[0], camera.position[1], camera.position[2],
                        camera.forward[0], camera.forward[1], camera.forward[2], camera.up[0], camera.up[1],
                        camera.up[2], camera.fov_y, camera.aspect, camera.viewport_height, camera.near_distance,
                        camera.far_distance, (float)o.tau, (float)o.coarsen_ratio, cut.node_count, cut.proxy_count,
                        cut.original_count, culled, changes.entered_count, changes.left_count,
                        s.uploads - uploads_before, s.frees - frees_before, s.resident, missing, draws, triangles,
                        primitives, t1 - t0, t2 - t0);
            if (o.out && (i == 0 || i == o.frames - 1)) {
                const char* name = i == 0 ? "near.png" : "far.png";
                read_pixels(&r, pixels);
                snprintf(path, sizeof path, "%s/%s", o.out, name);
                double coverage = 0;
                if (!write_png(path, o.width, o.height, pixels, &coverage)) {
                    fprintf(stderr, "aglod_viewer: cannot write %s\n", path);
                    return 1;
                }
                /* Where the scene's bounding sphere lands on screen (the camera looks at its
                 * centre: a circle of radius f tan(asin(R / d)) around the image centre). */
                const double f = (double)o.height / (2 * tan(fov_y / 2));
                const double sphere_px = f * radius / sqrt(d * d - fmin(radius * radius, 0.99 * d * d));
                printf("wrote %s: %.2f %% of the pixels show the scene\n", path, 100 * coverage);
                double originals_coverage = -1, missing_share = -1, extra_share = -1, shading_difference = -1;
                if (o.compare_originals) {
                    /* The cut again, lit by its triangles' own (geometric) normals instead of the
                     * file's per-vertex normals: the two pictures differ only by smooth versus
                     * faceted shading when the normals reach the shader right. */
                    pass_uniforms faceted = uniforms;
                    faceted.faceted = 1;
                    begin_pass(&r, &faceted);
                    uint32_t unused_draws = 0;
                    unsigned long long unused_triangles = 0;
                    for (uint32_t n = 0; n < cut.node_count; ++n)
                        if (s.meshes[cut.nodes[n]].resident) draw_mesh(&s.meshes[cut.nodes[n]], &unused_draws, &unused_triangles);
                    read_pixels(&r, reference_pixels);
                    double sum = 0;
                    size_t both = 0;
                    for (size_t p = 0; p < (size_t)o.width * (size_t)o.height; ++p) {
                        const unsigned char *a = pixels + 3 * p, *b = reference_pixels + 3 * p;
                        if (is_background(a) || is_background(b)) continue;
                        sum += fabs((0.299 * a[0] + 0.587 * a[1] + 0.114 * a[2]) - (0.299 * b[0] + 0.587 * b[1] + 0.114 * b[2]));
                        ++both;
                    }
                    shading_difference = both ? sum / (double)both : 0.0;
                    printf("%s: smooth (file normals) and faceted (triangle normals) shading differ by %.2f of 255 "
                           "brightness levels on average\n", name, shading_difference);

                    /* The same camera, every original object at full detail, no culling. */
                    begin_pass(&r, &uniforms);
                    uint32_t reference_draws = 0;
                    unsigned long long reference_triangles = 0;
                    for (uint32_t n = 0; n < node_count; ++n) {
                        if (aglod_node_level(file, n) != AGLOD_LEAF_LEVEL) continue;
                        if (!reference.meshes[n].resident) upload(file, &reference, n);
                        draw_mesh(&reference.meshes[n], &reference_draws, &reference_triangles);
                    }
                    read_pixels(&r, reference_pixels);
                    size_t covered = 0, lacking = 0, surplus = 0, drawn = 0;
                    for (size_t p = 0; p < (size_t)o.width * (size_t)o.height; ++p) {
                        const int in_cut = !is_background(pixels + 3 * p), in_originals = !is_background(reference_pixels + 3 * p);
                        covered += in_originals;
                        drawn += in_cut;
                        lacking += in_originals && !in_cut;
                        surplus += in_cut && !in_originals;
                    }
                    originals_coverage = (double)covered / ((double)o.width * (double)o.height);
                    missing_share = covered ? (double)lacking / (double)covered : 0.0;
                    extra_share = drawn ? (double)surplus / (double)drawn : 0.0;
                    snprintf(path, sizeof path, "%s/%.*s_originals.png", o.out, (int)(strlen(name) - 4), name);
                    double unused = 0;
                    if (!write_png(path, o.width, o.height, reference_pixels, &unused)) {
                        fprintf(stderr, "aglod_viewer: cannot write %s\n", path);
                        return 1;
                    }
                    printf("wrote %s: the originals (%u draw calls, %llu triangles); of their %zu pixels the cut "
                           "leaves %zu uncovered (%.3f %%); %.3f %% of the cut's pixels lie outside them\n",
                           path, reference_draws, reference_triangles, covered, lacking, 100 * missing_share,
                           100 * extra_share);
                    snprintf(path, sizeof path, "%s/%.*s_originals_zoom.png", o.out, (int)(strlen(name) - 4), name);
                    if (2 * sphere_px < 0.5 * o.height &&
                        !write_zoom(path, o.width, o.height, reference_pixels, 0.5 * o.width, 0.5 * o.height,
                                    1.1 * sphere_px)) {
                        fprintf(stderr, "aglod_viewer: cannot write %s\n", path);
                        return 1;
                    }
                }
                fprintf(shots, "%s,%d,%d,%d,%.2f,%.2f,%.2f,%d,%d,%d,%.6f,%.6f,%.6f,%.6f,%.4f\n", name, frame, o.width,
                        o.height, 0.5 * o.width, 0.5 * o.height, sphere_px, kBackground[0], kBackground[1],
                        kBackground[2], coverage, originals_coverage, missing_share, extra_share, shading_difference);
                if (2 * sphere_px < 0.5 * o.height) {
                    snprintf(path, sizeof path, "%s/%.*s_zoom.png", o.out, (int)(strlen(name) - 4), name);
                    if (!write_zoom(path, o.width, o.height, pixels, 0.5 * o.width, 0.5 * o.height, 1.1 * sphere_px)) {
                        fprintf(stderr, "aglod_viewer: cannot write %s\n", path);
                        return 1;
                    }
                    printf("wrote %s: the scene's bounding circle, enlarged\n", path);
                }
            }
        }
        if (!o.hidden) {
            int fw = 0, fh = 0;
            glfwGetFramebufferSize(window, &fw, &fh);
            glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
            glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
            glBlitFramebuffer(0, 0, o.width, o.height, 0, 0, fw, fh, GL_COLOR_BUFFER_BIT, GL_LINEAR);
            glfwSwapBuffers(window);
        }
        glfwPollEvents();
        if (glfwGetKey(window, GLFW_KEY_ESCAPE) == GLFW_PRESS) glfwSetWindowShouldClose(window, GLFW_TRUE);
        if (glfwWindowShouldClose(window)) break;
    }

    /* Leaving: release everything still resident. */
    for (uint32_t n = 0; n < node_count; ++n) {
        if (s.meshes[n].resident) release(&s, n);
        if (reference.meshes && reference.meshes[n].resident) release(&reference, n);
    }
    printf("aglod_viewer: %d frames, %llu draw calls, %llu triangles; %u uploads, %u frees; %u streaming errors, "
           "%u bad frames\n",
           frame, total_draws, total_triangles, s.uploads, s.frees, s.errors, frames_bad);
    if (csv) fclose(csv);
    if (shots) fclose(shots);
    free(pixels);
    free(reference_pixels);
    free(reference.meshes);
    free(s.meshes);
    glDeleteQueries(1, &query);
    glDeleteProgram(program);
    glDeleteRenderbuffers(1, &color_rb);
    glDeleteRenderbuffers(1, &depth_rb);
    glDeleteFramebuffers(1, &fbo);
    aglod_selector_destroy(selector);
    glfwDestroyWindow(window);
    glfwTerminate();
    aglod_close(file);
    return (s.errors || frames_bad) ? 1 : 0;
}
