/* Draws sprites into an offscreen float framebuffer and reads the result
 * back as 8-bit straight-alpha RGBA. One core-profile 3.3 context per
 * renderer, from a backend in gl_context.h, one instanced draw per frame. It
 * does not make contexts, simulate, choose colours or write files; it only
 * turns sprites and a camera into pixels. */
#include "render/render.h"
#include "render/gl_context.h"

/* Types, enums and PFNGL...PROC typedefs only: without GL_GLEXT_PROTOTYPES
 * it declares no function, so every call goes through the table below. */
#include <GL/glcorearb.h>

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Clip planes. The depth test is off, so these only decide what is cut away:
 * nothing nearer than 1 cm or farther than 1 km is drawn, in either
 * projection. */
#define PFX_NEAR 0.01
#define PFX_FAR 1000.0
#define PFX_PI 3.14159265358979323846 /* M_PI is not in strict C11 + POSIX */

/* Every GL entry point render.c calls, 1.0 ones included, fetched through
 * the backend's GetProcAddress: with glvnd, libOpenGL's exported symbols
 * dispatch to whichever vendor is current, while libOSMesa brings its own;
 * asking the backend is right for both. */
#define PFX_GL_FUNCS(X)                                                                            \
    X(PFNGLGETERRORPROC, GetError)                                                                 \
    X(PFNGLGETINTEGERVPROC, GetIntegerv)                                                           \
    X(PFNGLENABLEPROC, Enable)                                                                     \
    X(PFNGLDISABLEPROC, Disable)                                                                   \
    X(PFNGLBLENDFUNCPROC, BlendFunc)                                                               \
    X(PFNGLVIEWPORTPROC, Viewport)                                                                 \
    X(PFNGLSCISSORPROC, Scissor)                                                                   \
    X(PFNGLCLEARCOLORPROC, ClearColor)                                                             \
    X(PFNGLCLEARPROC, Clear)                                                                       \
    X(PFNGLPIXELSTOREIPROC, PixelStorei)                                                           \
    X(PFNGLREADPIXELSPROC, ReadPixels)                                                             \
    X(PFNGLFINISHPROC, Finish)                                                                     \
    X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                                                   \
    X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                                             \
    X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                                                   \
    X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)                                   \
    X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                                     \
    X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers)                                                 \
    X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers)                                           \
    X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)                                                 \
    X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage)                                           \
    X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                                                   \
    X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                                             \
    X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                                                   \
    X(PFNGLGENBUFFERSPROC, GenBuffers)                                                             \
    X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                                                       \
    X(PFNGLBINDBUFFERPROC, BindBuffer)                                                             \
    X(PFNGLBUFFERDATAPROC, BufferData)                                                             \
    X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                                           \
    X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)                                   \
    X(PFNGLVERTEXATTRIBDIVISORPROC, VertexAttribDivisor)                                           \
    X(PFNGLDRAWARRAYSINSTANCEDPROC, DrawArraysInstanced)                                           \
    X(PFNGLCREATESHADERPROC, CreateShader)                                                         \
    X(PFNGLDELETESHADERPROC, DeleteShader)                                                         \
    X(PFNGLSHADERSOURCEPROC, ShaderSource)                                                         \
    X(PFNGLCOMPILESHADERPROC, CompileShader)                                                       \
    X(PFNGLGETSHADERIVPROC, GetShaderiv)                                                           \
    X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                                                 \
    X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                                       \
    X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                                                       \
    X(PFNGLATTACHSHADERPROC, AttachShader)                                                         \
    X(PFNGLLINKPROGRAMPROC, LinkProgram)                                                           \
    X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                                         \
    X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                                               \
    X(PFNGLUSEPROGRAMPROC, UseProgram)                                                             \
    X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                                             \
    X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)

typedef struct pfx_gl {
#define PFX_GL_FIELD(type, name) type name;
    PFX_GL_FUNCS(PFX_GL_FIELD)
#undef PFX_GL_FIELD
} pfx_gl;

struct pfx_renderer {
    int width, height;
    pfx_gl_context *ctx;
    pfx_gl gl;
    GLuint fbo, colour_rb, vao, quad_vbo, instance_vbo, program;
    GLint view_loc, proj_loc;
    float *pixels; /* width * height * 4 floats read back from the FBO */
    /* Sort scratch, grown to the largest count seen: two key and two index
     * arrays for the radix ping-pong, and a sprite copy for the permutation. */
    size_t scratch_cap;
    uint32_t *keys;
    uint32_t *index;
    pfx_sprite *sorted;
};

/* The sprite shader. Each instance is a unit quad with corners (+-1, +-1),
 * placed in view space at the sprite's centre and scaled by its radius
 * size/2, so it always faces the camera and shrinks with distance under
 * perspective. The quad lies in a plane of constant view depth, so the
 * interpolated corner coordinate is exact (no perspective distortion).
 *
 * Soft round falloff (documented in the man page): with d = distance from the
 * sprite centre divided by its radius, all four premultiplied components
 * (r, g, b, a) are multiplied by
 *     f(d) = (1 - d^2)^2   for d < 1,
 *     f(d) = 0             for d >= 1 (the fragment is discarded).
 * f is 1 at the centre, 0.5625 at half the radius, and reaches 0 with zero
 * slope at the rim, so sprites have no hard edge. It is a polynomial in d^2,
 * so no square root is needed. */
static const char *vertex_src = "#version 330 core\n"
                                "layout(location = 0) in vec2 corner;\n"
                                "layout(location = 1) in vec4 centre_size;\n"
                                "layout(location = 2) in vec4 colour;\n"
                                "layout(location = 3) in vec2 angle_shape;\n"
                                "uniform mat4 view;\n"
                                "uniform mat4 proj;\n"
                                "out vec2 v_corner;\n"
                                "out vec4 v_colour;\n"
                                "flat out float v_shape;\n"
                                "void main() {\n"
                                "    vec4 c = view * vec4(centre_size.xyz, 1.0);\n"
                                "    float s = sin(angle_shape.x), k = cos(angle_shape.x);\n"
                                "    vec2 turned = vec2(k * corner.x - s * corner.y,\n"
                                "                       s * corner.x + k * corner.y);\n"
                                "    c.xy += turned * (0.5 * centre_size.w);\n"
                                "    gl_Position = proj * c;\n"
                                "    v_corner = corner;\n"
                                "    v_colour = colour;\n"
                                "    v_shape = angle_shape.y;\n"
                                "}\n";

static const char *fragment_src = "#version 330 core\n"
                                  "in vec2 v_corner;\n"
                                  "in vec4 v_colour;\n"
                                  "flat in float v_shape;\n"
                                  "layout(location = 0) out vec4 frag;\n"
                                  "void main() {\n"
                                  "    if (v_shape > 0.5) {\n"
                                  "        vec2 q = 1.0 - v_corner * v_corner;\n"
                                  "        frag = v_colour * (q.x * q.x * q.y * q.y);\n"
                                  "        return;\n"
                                  "    }\n"
                                  "    float d2 = dot(v_corner, v_corner);\n"
                                  "    if (d2 >= 1.0) discard;\n"
                                  "    float k = 1.0 - d2;\n"
                                  "    frag = v_colour * (k * k);\n"
                                  "}\n";

/* pfx_gl_proc is void (*)(void), the generic function pointer type GCC
 * accepts in casts without -Wcast-function-type complaints. */
static bool load_gl(pfx_gl *gl, pfx_gl_context *ctx, pfx_diags *d) {
#define PFX_GL_LOAD(type, fn)                                                                      \
    gl->fn = (type)ctx->get_proc_address("gl" #fn);                                                \
    if (!gl->fn) {                                                                                 \
        pfx_diag_error(d, "renderer '%s' does not provide 'gl%s'", ctx->name, #fn);                \
        return false;                                                                              \
    }
    PFX_GL_FUNCS(PFX_GL_LOAD)
#undef PFX_GL_LOAD
    return true;
}

static GLuint compile_shader(pfx_renderer *r, GLenum type, const char *src, pfx_diags *d) {
    GLuint s = r->gl.CreateShader(type);
    r->gl.ShaderSource(s, 1, &src, NULL);
    r->gl.CompileShader(s);
    GLint ok = GL_FALSE;
    r->gl.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[512] = "";
        r->gl.GetShaderInfoLog(s, sizeof log, NULL, log);
        pfx_diag_error(d, "cannot compile %s shader: %s",
                       type == GL_VERTEX_SHADER ? "vertex" : "fragment", log);
        r->gl.DeleteShader(s);
        return 0;
    }
    return s;
}

static bool build_program(pfx_renderer *r, pfx_diags *d) {
    GLuint vs = compile_shader(r, GL_VERTEX_SHADER, vertex_src, d);
    if (!vs)
        return false;
    GLuint fs = compile_shader(r, GL_FRAGMENT_SHADER, fragment_src, d);
    if (!fs) {
        r->gl.DeleteShader(vs);
        return false;
    }
    r->program = r->gl.CreateProgram();
    r->gl.AttachShader(r->program, vs);
    r->gl.AttachShader(r->program, fs);
    r->gl.LinkProgram(r->program);
    r->gl.DeleteShader(vs); /* flagged; freed with the program */
    r->gl.DeleteShader(fs);
    GLint ok = GL_FALSE;
    r->gl.GetProgramiv(r->program, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[512] = "";
        r->gl.GetProgramInfoLog(r->program, sizeof log, NULL, log);
        pfx_diag_error(d, "cannot link sprite shader: %s", log);
        return false;
    }
    r->view_loc = r->gl.GetUniformLocation(r->program, "view");
    r->proj_loc = r->gl.GetUniformLocation(r->program, "proj");
    return true;
}

/* The float framebuffer: RGBA32F, so additive sums and many faint alpha
 * layers are not quantised to 8 bits between draws. No depth buffer: sprites
 * never occlude by depth, only by the order they are blended in. */
static bool build_framebuffer(pfx_renderer *r, pfx_diags *d) {
    r->gl.GenRenderbuffers(1, &r->colour_rb);
    r->gl.BindRenderbuffer(GL_RENDERBUFFER, r->colour_rb);
    r->gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA32F, r->width, r->height);
    r->gl.GenFramebuffers(1, &r->fbo);
    r->gl.BindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    r->gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                  r->colour_rb);
    GLenum status = r->gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        pfx_diag_error(d, "float framebuffer %dx%d is incomplete (status 0x%04x)", r->width,
                       r->height, (unsigned)status);
        return false;
    }
    return true;
}

/* Vertex layout: attribute 0 is the quad corner (per vertex); attributes 1
 * and 2 read a pfx_sprite as two vec4s, (x, y, z, size) and (r, g, b, a),
 * advancing once per instance. The sprite array is uploaded as it is. */
static void build_vertex_arrays(pfx_renderer *r) {
    static const float corners[8] = {-1, -1, 1, -1, -1, 1, 1, 1}; /* triangle strip */
    r->gl.GenVertexArrays(1, &r->vao);
    r->gl.BindVertexArray(r->vao);
    r->gl.GenBuffers(1, &r->quad_vbo);
    r->gl.BindBuffer(GL_ARRAY_BUFFER, r->quad_vbo);
    r->gl.BufferData(GL_ARRAY_BUFFER, sizeof corners, corners, GL_STATIC_DRAW);
    r->gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), (const void *)0);
    r->gl.EnableVertexAttribArray(0);
    r->gl.GenBuffers(1, &r->instance_vbo);
    r->gl.BindBuffer(GL_ARRAY_BUFFER, r->instance_vbo);
    r->gl.VertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, sizeof(pfx_sprite),
                              (const void *)offsetof(pfx_sprite, x));
    r->gl.VertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, sizeof(pfx_sprite),
                              (const void *)offsetof(pfx_sprite, r));
    r->gl.VertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, sizeof(pfx_sprite),
                              (const void *)offsetof(pfx_sprite, angle));
    r->gl.EnableVertexAttribArray(1);
    r->gl.EnableVertexAttribArray(2);
    r->gl.EnableVertexAttribArray(3);
    r->gl.VertexAttribDivisor(1, 1);
    r->gl.VertexAttribDivisor(2, 1);
    r->gl.VertexAttribDivisor(3, 1);
}

static const char *const kind_names[] = {
#define PFX_RENDERER_NAME(kind, name) name,
    PFX_RENDERER_KINDS(PFX_RENDERER_NAME)
#undef PFX_RENDERER_NAME
};

const char *pfx_renderer_kind_name(pfx_renderer_kind kind) {
    return (unsigned)kind < PFX_RENDERER_KIND_COUNT ? kind_names[kind] : "unknown";
}

bool pfx_renderer_kind_parse(const char *name, pfx_renderer_kind *kind) {
    for (int k = 0; k < PFX_RENDERER_KIND_COUNT; k++)
        if (!strcmp(name, kind_names[k])) {
            *kind = (pfx_renderer_kind)k;
            return true;
        }
    return false;
}

/* The backends this pfx was built with (PFX_HAVE_OSMESA, PFX_HAVE_EGL, set
 * by CMake from what it found), for the message when one is missing. */
static const char built_with[] = ""
#ifdef PFX_HAVE_OSMESA
                                 " osmesa"
#endif
#ifdef PFX_HAVE_EGL
                                 " egl-cpu egl-gpu"
#endif
    ;

/* A current context of the given kind. auto is OSMesa where it is built,
 * else egl-cpu, and never a GPU: a GPU's pixels may differ from llvmpipe's. */
static pfx_gl_context *create_context(pfx_renderer_kind kind, pfx_diags *d) {
    if (kind == PFX_RENDERER_AUTO) {
#ifdef PFX_HAVE_OSMESA
        kind = PFX_RENDERER_OSMESA;
#else
        kind = PFX_RENDERER_EGL_CPU;
#endif
    }
    switch (kind) {
#ifdef PFX_HAVE_OSMESA
    case PFX_RENDERER_OSMESA:
        return pfx_gl_osmesa_create(d);
#endif
#ifdef PFX_HAVE_EGL
    case PFX_RENDERER_EGL_CPU:
    case PFX_RENDERER_EGL_GPU:
        return pfx_gl_egl_create(kind == PFX_RENDERER_EGL_GPU, d);
#endif
    default:
        pfx_diag_error(d, "renderer '%s' is not built into this pfx (it has:%s)",
                       pfx_renderer_kind_name(kind), built_with);
        return NULL;
    }
}

const char *pfx_renderer_name(const pfx_renderer *r) { return r->ctx->name; }

pfx_renderer *pfx_renderer_create(pfx_renderer_kind kind, int width, int height, pfx_diags *d) {
    if (width <= 0 || height <= 0) {
        pfx_diag_error(d, "invalid image size %dx%d", width, height);
        return NULL;
    }
    pfx_renderer *r = calloc(1, sizeof *r);
    float *pixels = malloc((size_t)width * (size_t)height * 4 * sizeof(float));
    if (!r || !pixels) {
        free(r);
        free(pixels);
        pfx_diag_error(d, "out of memory for a %dx%d renderer", width, height);
        return NULL;
    }
    r->width = width;
    r->height = height;
    r->pixels = pixels;

    r->ctx = create_context(kind, d);
    if (!r->ctx)
        goto fail;
    if (!load_gl(&r->gl, r->ctx, d))
        goto fail;
    GLint max_rb = 0;
    r->gl.GetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_rb);
    if (width > max_rb || height > max_rb) {
        pfx_diag_error(d, "image size %dx%d exceeds the renderer limit of %d", width, height,
                       (int)max_rb);
        goto fail;
    }
    if (!build_framebuffer(r, d) || !build_program(r, d))
        goto fail;
    build_vertex_arrays(r);

    /* Fixed state for every draw: premultiplied "over", which is additive
     * when the sprite's alpha is 0. */
    r->gl.Disable(GL_DEPTH_TEST);
    r->gl.Enable(GL_BLEND);
    r->gl.BlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    r->gl.Viewport(0, 0, width, height);
    r->gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    GLenum e = r->gl.GetError();
    if (e != GL_NO_ERROR) {
        pfx_diag_error(d, "OpenGL error 0x%04x while setting up the renderer", (unsigned)e);
        goto fail;
    }
    return r;
fail:
    pfx_renderer_destroy(r);
    return NULL;
}

void pfx_renderer_destroy(pfx_renderer *r) {
    if (!r)
        return;
    if (r->ctx)
        r->ctx->destroy(r->ctx); /* frees every GL object it owns */
    free(r->pixels);
    free(r->keys);
    free(r->index);
    free(r->sorted);
    free(r);
}

/* Camera matrices, column-major (m[col * 4 + row]) as GL expects. The view
 * matrix is gluLookAt's: forward f = normalize(target - position), side
 * s = normalize(f x up), true up u = s x f; the camera looks down -z. */
typedef struct pfx_view {
    double m[16];
    double proj[16];
    double forward[3], eye[3];
} pfx_view;

/* The camera was checked when the effect was compiled (pfx_camera_frame);
 * a caller that built one by hand gets the same words. */
static bool camera_matrices(const pfx_camera *cam, int width, int height, pfx_view *v,
                            pfx_diags *d) {
    double s[3], u[3], f[3];
    switch (pfx_camera_frame(cam, s, u, f)) {
    case PFX_CAMERA_SAME_POINT:
        pfx_diag_error(d, "camera 'position' and 'target' are the same point");
        return false;
    case PFX_CAMERA_UP_PARALLEL:
        pfx_diag_error(d, "camera 'up' is parallel to the view direction");
        return false;
    case PFX_CAMERA_OK:
        break;
    }
    const double *e = cam->position;
    double *m = v->m;
    memset(m, 0, sizeof v->m);
    for (int i = 0; i < 3; i++) {
        m[i * 4 + 0] = s[i];
        m[i * 4 + 1] = u[i];
        m[i * 4 + 2] = -f[i];
    }
    m[12] = -(s[0] * e[0] + s[1] * e[1] + s[2] * e[2]);
    m[13] = -(u[0] * e[0] + u[1] * e[1] + u[2] * e[2]);
    m[14] = f[0] * e[0] + f[1] * e[1] + f[2] * e[2];
    m[15] = 1.0;
    memcpy(v->forward, f, sizeof f);
    memcpy(v->eye, e, sizeof v->eye);

    double aspect = (double)width / (double)height;
    double n = PFX_NEAR, fa = PFX_FAR;
    double *p = v->proj;
    memset(p, 0, sizeof v->proj);
    if (cam->ortho) {
        double half_h = 0.5 * cam->ortho_height, half_w = half_h * aspect;
        p[0] = 1.0 / half_w;
        p[5] = 1.0 / half_h;
        p[10] = -2.0 / (fa - n);
        p[14] = -(fa + n) / (fa - n);
        p[15] = 1.0;
    } else {
        double t = 1.0 / tan(0.5 * cam->fov);
        p[0] = t / aspect;
        p[5] = t;
        p[10] = -(fa + n) / (fa - n);
        p[11] = -1.0;
        p[14] = -2.0 * fa * n / (fa - n);
    }
    return true;
}

static bool grow_scratch(pfx_renderer *r, size_t count, pfx_diags *d) {
    if (count <= r->scratch_cap)
        return true;
    size_t cap = r->scratch_cap ? r->scratch_cap : 1024;
    while (cap < count)
        cap *= 2;
    uint32_t *keys = realloc(r->keys, 2 * cap * sizeof *keys);
    if (keys)
        r->keys = keys;
    uint32_t *index = realloc(r->index, 2 * cap * sizeof *index);
    if (index)
        r->index = index;
    pfx_sprite *sorted = realloc(r->sorted, cap * sizeof *sorted);
    if (sorted)
        r->sorted = sorted;
    if (!keys || !index || !sorted) {
        pfx_diag_error(d, "out of memory sorting %zu sprites", count);
        return false;
    }
    r->scratch_cap = cap;
    return true;
}

/* Maps a float to a uint32 whose unsigned order is the float's order
 * (negative floats have all bits flipped, positive ones only the sign). */
static uint32_t float_order_key(float x) {
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    return (b & 0x80000000u) ? ~b : (b | 0x80000000u);
}

/* Back-to-front sort by view depth (distance along the camera's forward
 * axis), farthest first. LSD radix sort on 32-bit keys, 8 bits per pass:
 * O(n), stable by construction (equal depths keep input order), and exactly
 * reproducible. Keys are inverted so that ascending key = descending depth.
 * Passes where every key has the same digit are skipped. */
static bool sort_back_to_front(pfx_renderer *r, const pfx_view *v, pfx_sprite *sprites,
                               size_t count, pfx_diags *d) {
    if (count < 2)
        return true;
    if (count > UINT32_MAX) {
        pfx_diag_error(d, "too many sprites to sort: %zu", count);
        return false;
    }
    if (!grow_scratch(r, count, d))
        return false;
    uint32_t *key = r->keys, *key_tmp = r->keys + r->scratch_cap;
    uint32_t *idx = r->index, *idx_tmp = r->index + r->scratch_cap;
    const double fx = v->forward[0], fy = v->forward[1], fz = v->forward[2];
    const double ex = v->eye[0], ey = v->eye[1], ez = v->eye[2];
    for (size_t i = 0; i < count; i++) {
        double depth =
            (sprites[i].x - ex) * fx + (sprites[i].y - ey) * fy + (sprites[i].z - ez) * fz;
        key[i] = ~float_order_key((float)depth);
        idx[i] = (uint32_t)i;
    }
    for (int shift = 0; shift < 32; shift += 8) {
        size_t hist[256] = {0};
        for (size_t i = 0; i < count; i++)
            hist[(key[i] >> shift) & 0xff]++;
        if (hist[(key[0] >> shift) & 0xff] == count)
            continue; /* all keys share this digit: the pass would not move anything */
        size_t sum = 0;
        for (int d = 0; d < 256; d++) {
            size_t c = hist[d];
            hist[d] = sum;
            sum += c;
        }
        for (size_t i = 0; i < count; i++) {
            size_t dst = hist[(key[i] >> shift) & 0xff]++;
            key_tmp[dst] = key[i];
            idx_tmp[dst] = idx[i];
        }
        uint32_t *t = key;
        key = key_tmp;
        key_tmp = t;
        t = idx;
        idx = idx_tmp;
        idx_tmp = t;
    }
    for (size_t i = 0; i < count; i++)
        r->sorted[i] = sprites[idx[i]];
    memcpy(sprites, r->sorted, count * sizeof *sprites);
    return true;
}

static void upload_uniforms(pfx_renderer *r, const pfx_view *v) {
    float view[16], proj[16];
    for (int i = 0; i < 16; i++) {
        view[i] = (float)v->m[i];
        proj[i] = (float)v->proj[i];
    }
    r->gl.UniformMatrix4fv(r->view_loc, 1, GL_FALSE, view);
    r->gl.UniformMatrix4fv(r->proj_loc, 1, GL_FALSE, proj);
}

/* Another renderer in this thread may have made its own context current. */
static bool make_current(pfx_renderer *r, pfx_diags *d) {
    if (!r->ctx->make_current(r->ctx)) {
        pfx_diag_error(d, "cannot make the '%s' context current", r->ctx->name);
        return false;
    }
    return true;
}

/* Clear, upload, one instanced draw. The sprite array goes up whole with
 * glBufferData every frame: respecifying the store orphans last frame's, so
 * the driver never waits on it. */
static void submit_frame(pfx_renderer *r, const pfx_view *v, const float clear[4],
                         const pfx_sprite *sprites, size_t count) {
    r->gl.BindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    r->gl.Viewport(0, 0, r->width, r->height);
    r->gl.ClearColor(clear[0], clear[1], clear[2], clear[3]);
    r->gl.Clear(GL_COLOR_BUFFER_BIT);
    if (count > 0) {
        r->gl.UseProgram(r->program);
        upload_uniforms(r, v);
        r->gl.BindVertexArray(r->vao);
        r->gl.BindBuffer(GL_ARRAY_BUFFER, r->instance_vbo);
        r->gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(count * sizeof *sprites), sprites,
                         GL_STREAM_DRAW);
        r->gl.DrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)count);
    }
}

static void read_frame(pfx_renderer *r) {
    r->gl.ReadPixels(0, 0, r->width, r->height, GL_RGBA, GL_FLOAT, r->pixels);
}

/* The pixels a frame's sprites can touch, in GL window coordinates (y up),
 * [x0, x1) x [y0, y1). Each quad lies at one view depth, so its image is
 * the projection of its view-space square, widened by sqrt 2 for turned
 * squares and by 2 pixels for rasterisation. A sprite at or behind the near
 * plane makes it the whole frame. Outside the box every pixel is the
 * background, so only the box is cleared, read back and converted. */
typedef struct pixel_box {
    int x0, y0, x1, y1;
} pixel_box;

static pixel_box sprites_box(const pfx_renderer *r, const pfx_view *v, const pfx_sprite *sp,
                             size_t count) {
    const pixel_box full = {0, 0, r->width, r->height};
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    const double *m = v->m, *p = v->proj;
    for (size_t i = 0; i < count; i++) {
        double c[3];
        for (int row = 0; row < 3; row++)
            c[row] = m[row] * sp[i].x + m[4 + row] * sp[i].y + m[8 + row] * sp[i].z + m[12 + row];
        double rad = 0.5 * sp[i].size * 1.4142136;
        double w = p[3] * c[0] + p[7] * c[1] + p[11] * c[2] + p[15];
        if (!(w > 1e-6) || !(rad < 1e30))
            return full;
        for (int cx = -1; cx <= 1; cx += 2)
            for (int cy = -1; cy <= 1; cy += 2) {
                double x = c[0] + cx * rad, y = c[1] + cy * rad;
                double nx = (p[0] * x + p[4] * y + p[8] * c[2] + p[12]) / w;
                double ny = (p[1] * x + p[5] * y + p[9] * c[2] + p[13]) / w;
                lo[0] = nx < lo[0] ? nx : lo[0];
                hi[0] = nx > hi[0] ? nx : hi[0];
                lo[1] = ny < lo[1] ? ny : lo[1];
                hi[1] = ny > hi[1] ? ny : hi[1];
            }
    }
    if (count == 0)
        return (pixel_box){0, 0, 0, 0};
    double size[2] = {r->width, r->height};
    int b[4];
    for (int a = 0; a < 2; a++) {
        double l = floor((lo[a] * 0.5 + 0.5) * size[a]) - 2,
               h = ceil((hi[a] * 0.5 + 0.5) * size[a]) + 2;
        l = l < 0 ? 0 : l > size[a] ? size[a] : l;
        h = h < 0 ? 0 : h > size[a] ? size[a] : h;
        b[a] = (int)l;
        b[a + 2] = (int)h;
    }
    if (b[2] <= b[0] || b[3] <= b[1])
        return (pixel_box){0, 0, 0, 0};
    return (pixel_box){b[0], b[1], b[2], b[3]};
}

/* fmax without the libm call (GCC must call it to keep its NaN rule): the
 * larger of x and y, and the other one when either is NaN. */
static inline double max_of(double x, double y) { return (y > x || x != x) ? y : x; }

/* lround(255 x) clamped to a byte. For 0 < x < 1, y = 255 x lies in (0, 255),
 * so truncation is floor and y - floor(y) is exact: rounding half away from
 * zero is then one comparison, with no libm call. */
static inline uint8_t to_byte(double x) {
    if (!(x > 0))
        return 0; /* also NaN */
    if (x >= 1)
        return 255;
    double y = 255.0 * x;
    int t = (int)y;
    return (uint8_t)(y - (double)t >= 0.5 ? t + 1 : t);
}

/* Premultiplied float framebuffer -> 8-bit straight alpha, top row first.
 *
 * A pixel holds premultiplied colour P = (r, g, b) and coverage A. Additive
 * particles add light with zero coverage, so P can exceed A (on a transparent
 * background A may even be 0 under a bright glow). Dividing by A would blow
 * up, and storing A alone would drop the glow. So the output alpha is
 *     A' = min(1, max(A, r, g, b)),
 * and the output colour is clamp(P / A', 0, 1) (or all zero when A' = 0).
 * Composited over black the result is colour * A' = P whenever P <= 1: an
 * additive particle on a transparent background then looks, placed over
 * black, exactly as it rendered over black, and where alpha blending
 * dominates (A >= every channel) this is the ordinary un-premultiply. Bytes
 * are lround(255 * x).
 *
 * Cost: most of a particle frame is untouched background, so an all-zero
 * pixel (all 16 bytes zero; -0.0 takes the general path) is written as zero
 * at once; the rest are computed in double with no libm calls. Measured on
 * effects/fire.yaml at 512x512 (80% transparent), 1.6 ms -> 0.5 ms a frame,
 * byte-identical output. */
static inline void convert_one(const float *src, uint8_t *dst) {
    uint32_t bits[4];
    memcpy(bits, src, sizeof bits);
    if ((bits[0] | bits[1] | bits[2] | bits[3]) == 0) {
        memset(dst, 0, 4);
        return;
    }
    double cr = src[0], cg = src[1], cb = src[2], a = src[3];
    double ap = max_of(max_of(a, cr), max_of(cg, cb));
    if (ap > 1)
        ap = 1;
    if (!(ap > 0)) {
        dst[0] = dst[1] = dst[2] = dst[3] = 0;
        return;
    }
    dst[0] = to_byte(cr / ap);
    dst[1] = to_byte(cg / ap);
    dst[2] = to_byte(cb / ap);
    dst[3] = to_byte(ap);
}

/* Converts the read-back box (packed rows of its width, bottom row first)
 * into its place in rgba (top row first) and fills the rest of the image
 * with the background, converted once. */
static void convert_pixels(const pfx_renderer *r, const pixel_box *box, const float clear[4],
                           uint8_t *rgba) {
    const size_t w = (size_t)r->width, bw = (size_t)(box->x1 - box->x0);
    uint8_t bg[4];
    convert_one(clear, bg);
    uint32_t bg_word;
    memcpy(&bg_word, bg, 4);
    for (int y = 0; y < r->height; y++) {
        uint8_t *dst = rgba + (size_t)y * w * 4;
        int gl_y = r->height - 1 - y;
        bool in = gl_y >= box->y0 && gl_y < box->y1;
        size_t from = in ? (size_t)box->x0 : w, to = in ? (size_t)box->x1 : w;
        for (size_t x = 0; x < from; x++)
            memcpy(dst + 4 * x, &bg_word, 4);
        if (in) {
            const float *src = r->pixels + (size_t)(gl_y - box->y0) * bw * 4;
            for (size_t x = from; x < to; x++, src += 4)
                convert_one(src, dst + 4 * x);
        }
        for (size_t x = to; x < w; x++)
            memcpy(dst + 4 * x, &bg_word, 4);
    }
}

bool pfx_renderer_draw(pfx_renderer *r, const pfx_camera *cam, const float bg[4],
                       pfx_sprite *sprites, size_t count, bool sort, uint8_t *rgba, pfx_diags *d) {
    if (count > (size_t)INT32_MAX) {
        pfx_diag_error(d, "too many sprites to draw: %zu", count);
        return false;
    }
    pfx_view v;
    if (!camera_matrices(cam, r->width, r->height, &v, d))
        return false;
    if (!make_current(r, d))
        return false;
    if (sort && !sort_back_to_front(r, &v, sprites, count, d))
        return false;
    const float clear[4] = {bg[0] * bg[3], bg[1] * bg[3], bg[2] * bg[3], bg[3]};
    pixel_box box = sprites_box(r, &v, sprites, count);
    if (box.x1 > box.x0) {
        r->gl.BindFramebuffer(GL_FRAMEBUFFER, r->fbo);
        r->gl.Enable(GL_SCISSOR_TEST);
        r->gl.Scissor(box.x0, box.y0, box.x1 - box.x0, box.y1 - box.y0);
        submit_frame(r, &v, clear, sprites, count);
        r->gl.Disable(GL_SCISSOR_TEST);
        r->gl.ReadPixels(box.x0, box.y0, box.x1 - box.x0, box.y1 - box.y0, GL_RGBA, GL_FLOAT,
                         r->pixels);
    }
    GLenum e = r->gl.GetError();
    if (e != GL_NO_ERROR) {
        pfx_diag_error(d, "OpenGL error 0x%04x while drawing %zu sprites", (unsigned)e, count);
        return false;
    }
    convert_pixels(r, &box, clear, rgba);
    return true;
}

double pfx_renderer_bench_raw(pfx_renderer *r, const pfx_camera *cam, const pfx_sprite *sprites,
                              size_t count, int frames) {
    pfx_view v;
    if (frames <= 0 || count > (size_t)INT32_MAX ||
        !camera_matrices(cam, r->width, r->height, &v, NULL) || !make_current(r, NULL))
        return -1.0;
    const float clear[4] = {0, 0, 0, 0};
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (int i = 0; i < frames; i++) {
        submit_frame(r, &v, clear, sprites, count);
        r->gl.Finish();
        read_frame(r);
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (r->gl.GetError() != GL_NO_ERROR)
        return -1.0;
    double s = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    return s > 0 ? frames / s : -1.0;
}
