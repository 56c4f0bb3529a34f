/* Draws sprites into an offscreen float framebuffer and reads the result
 * back as 8-bit straight-alpha RGBA. One core-profile 3.3 context per
 * renderer, from a backend in gl_context.h, one instanced draw per frame. It
 * does not make contexts, simulate, choose colours or write files; it only
 * turns sprites and a camera into pixels. */
#include "render/render_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "model/kinds.h"
#include "render/mipmap.h"
#include "render/shadow.h"

/* Clip planes. The depth test is off, so these only decide what is cut away:
 * nothing nearer than 1 cm or farther than 1 km is drawn, in either
 * projection. */
#define PFX_NEAR 0.01
#define PFX_FAR 1000.0

/* pfx_gl_proc is void (*)(void), the generic function pointer type GCC
 * accepts in casts without -Wcast-function-type complaints. */
static bool load_gl(pfx_gl *gl, pfx_gl_context *ctx, pfx_diags *d) {
#define PFX_GL_LOAD(type, fn)                                                                      \
    gl->fn = (type)ctx->get_proc_address("gl" #fn);                                                \
    if (!gl->fn) {                                                                                 \
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED, "renderer '%s' does not provide 'gl%s'",       \
                       ctx->name, #fn);                                                            \
        return false;                                                                              \
    }
    PFX_GL_FUNCS(PFX_GL_LOAD)
#undef PFX_GL_LOAD
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
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                       "float framebuffer %dx%d is incomplete (status 0x%04x)", r->width, r->height,
                       (unsigned)status);
        return false;
    }
    return true;
}

/* Vertex layout: attribute 0 is the quad corner (per vertex); attributes
 * 1 to 4 read a pfx_sprite as four vec4s, advancing once per instance. The
 * sprite array is uploaded as it is; a run of one material points the
 * attributes at its first sprite (GL 3.3 has no base instance). */
static void point_instances(pfx_renderer *r, size_t first) {
    const size_t base = first * sizeof(pfx_sprite);
    static const size_t offsets[4] = {offsetof(pfx_sprite, x), offsetof(pfx_sprite, r),
                                      offsetof(pfx_sprite, angle), offsetof(pfx_sprite, vx)};
    for (GLuint i = 0; i < 4; i++)
        r->gl.VertexAttribPointer(1 + i, 4, GL_FLOAT, GL_FALSE, sizeof(pfx_sprite),
                                  (const void *)(base + offsets[i]));
}

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
    point_instances(r, 0);
    for (GLuint i = 1; i <= 4; i++) {
        r->gl.EnableVertexAttribArray(i);
        r->gl.VertexAttribDivisor(i, 1);
    }
    /* Ribbons: a pfx_ribbon_vertex per vertex, three attributes. */
    r->gl.GenVertexArrays(1, &r->ribbon_vao);
    r->gl.BindVertexArray(r->ribbon_vao);
    r->gl.GenBuffers(1, &r->ribbon_vbo);
    r->gl.BindBuffer(GL_ARRAY_BUFFER, r->ribbon_vbo);
    static const size_t at[3] = {offsetof(pfx_ribbon_vertex, x), offsetof(pfx_ribbon_vertex, r),
                                 offsetof(pfx_ribbon_vertex, profile)};
    static const GLint size[3] = {4, 4, 2}; /* profile, along */
    for (GLuint i = 0; i < 3; i++) {
        r->gl.VertexAttribPointer(i, size[i], GL_FLOAT, GL_FALSE, sizeof(pfx_ribbon_vertex),
                                  (const void *)at[i]);
        r->gl.EnableVertexAttribArray(i);
    }
    r->gl.BindVertexArray(r->vao);
}

static const char *const kind_names[] = {
#define PFX_RENDERER_NAME(kind, name) name,
    PFX_RENDERER_KINDS(PFX_RENDERER_NAME)
#undef PFX_RENDERER_NAME
        NULL};

const char *pfx_renderer_kind_name(pfx_renderer_kind kind) {
    return (unsigned)kind < PFX_RENDERER_KIND_COUNT ? kind_names[kind] : "unknown";
}

bool pfx_renderer_kind_parse(const char *name, pfx_renderer_kind *kind) {
    int k = pfx_kind_find(kind_names, name);
    if (k >= 0)
        *kind = (pfx_renderer_kind)k;
    return k >= 0;
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
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                       "renderer '%s' is not built into this pfx (it has:%s)",
                       pfx_renderer_kind_name(kind), built_with);
        return NULL;
    }
}

const char *pfx_renderer_name(const pfx_renderer *r) { return r->ctx->name; }

/* Material k is built-in sprite k, facing the camera: what sprites mean
 * before pfx_renderer_set_materials. */
static bool default_materials(pfx_renderer *r, pfx_diags *d) {
    size_t n = pfx_kind_count(pfx_sprite_names);
    r->materials = calloc(n, sizeof *r->materials);
    if (!r->materials) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for the sprite materials");
        return false;
    }
    r->material_count = n;
    for (size_t k = 0; k < n; k++) {
        r->materials[k].m = (pfx_material){
            .sprite = (pfx_sprite_kind)k, .cols = 1, .rows = 1, .frames = 1, .axis = {0, 1, 0}};
        if (!pfx_shader_bind(r, &r->materials[k], d))
            return false;
    }
    return true;
}

pfx_render_settings pfx_render_settings_plain(const float bg[4]) {
    pfx_render_settings s = {
        .light_dir = {0, -1, 0}, .light_color = {1, 1, 1}, .ambient = {0.25f, 0.25f, 0.25f}};
    memcpy(s.background, bg, sizeof s.background);
    return s;
}

/* One texture with mipmaps, held as floats (render/mipmap.h says why): 8- or 16-bit RGBA rows top
 * first (so texture t = 0 is the image's top row), linear between texels and mip levels (sprites
 * pass the level explicitly: render/shader.c), the levels made by render/mipmap.c; 0 when out of
 * memory for them. */
static GLuint upload_texture(pfx_renderer *r, const pfx_image *img) {
    GLuint t = 0;
    r->gl.GenTextures(1, &t);
    r->gl.BindTexture(GL_TEXTURE_2D, t);
    r->gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    const bool wide = img->bits == 16;
    r->gl.TexImage2D(GL_TEXTURE_2D, 0, pfx_texture_format(img), img->width, img->height, 0, GL_RGBA,
                     wide ? GL_UNSIGNED_SHORT : GL_UNSIGNED_BYTE, img->pixels);
    if (!pfx_mipmap_upload(r, img)) {
        r->gl.DeleteTextures(1, &t);
        return 0;
    }
    r->gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    r->gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    r->gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    r->gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
}

/* The GL texture already made for these pixels by an earlier material
 * (or by this one's colour map), or 0. The compiler reads a file once and
 * gives every emitter naming it the same pixels (compile/file_cache.c), so
 * pixels are the identity: one upload per distinct image, not per emitter. */
static GLuint uploaded(const pfx_gpu_material *g, size_t count, const pfx_image *img) {
    for (size_t i = 0; i < count; i++) {
        if (g[i].texture && g[i].m.texture->pixels == img->pixels)
            return g[i].texture;
        if (g[i].normal_map && g[i].m.normal_map->pixels == img->pixels)
            return g[i].normal_map;
    }
    return 0;
}

static GLuint texture_for(pfx_renderer *r, const pfx_gpu_material *g, size_t count,
                          const pfx_image *img) {
    GLuint t = uploaded(g, count, img);
    if (!t && (t = upload_texture(r, img)) != 0)
        r->texture_count++;
    return t;
}

/* Deletes each texture once, however many materials share it. */
static void drop_textures(pfx_renderer *r) {
    pfx_gpu_material *g = r->materials;
    for (size_t i = 0; i < r->material_count; i++) {
        if (g[i].texture && uploaded(g, i, g[i].m.texture) != g[i].texture)
            r->gl.DeleteTextures(1, &g[i].texture);
        if (g[i].normal_map && uploaded(g, i, g[i].m.normal_map) != g[i].normal_map &&
            g[i].normal_map != g[i].texture)
            r->gl.DeleteTextures(1, &g[i].normal_map);
    }
    r->texture_count = 0;
}

size_t pfx_renderer_texture_count(const pfx_renderer *r) { return r->texture_count; }

bool pfx_renderer_set_materials(pfx_renderer *r, const pfx_material *m, size_t count,
                                pfx_diags *d) {
    if (!r->ctx->make_current(r->ctx)) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED, "cannot make the '%s' context current",
                       r->ctx->name);
        return false;
    }
    pfx_gpu_material *g = calloc(count ? count : 1, sizeof *g);
    if (!g) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for %zu materials", count);
        return false;
    }
    drop_textures(r);
    free(r->materials);
    r->materials = g;
    r->material_count = count;
    for (size_t i = 0; i < count; i++) {
        g[i].m = m[i];
        if (m[i].texture)
            g[i].texture = texture_for(r, g, i, m[i].texture);
        if (m[i].normal_map)
            g[i].normal_map = texture_for(r, g, i + 1, m[i].normal_map);
        if ((m[i].texture && !g[i].texture) || (m[i].normal_map && !g[i].normal_map)) {
            pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY,
                           "out of memory for the mipmaps of material %zu", i);
            return false;
        }
        if (!pfx_shader_bind(r, &g[i], d))
            return false;
    }
    GLenum e = r->gl.GetError();
    if (e != GL_NO_ERROR) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED, "OpenGL error 0x%04x while uploading textures",
                       (unsigned)e);
        return false;
    }
    return true;
}

pfx_renderer *pfx_renderer_create(pfx_renderer_kind kind, int width, int height, pfx_diags *d) {
    if (width <= 0 || height <= 0) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_RANGE, "invalid image size %dx%d", width, height);
        return NULL;
    }
    pfx_renderer *r = calloc(1, sizeof *r);
    if (r)
        r->sort_batch = PFX_SORT_BATCH;
    float *pixels = malloc((size_t)width * (size_t)height * 4 * sizeof(float));
    pfx_sprite *chunk = malloc(PFX_RENDER_CHUNK * sizeof *chunk);
    if (!r || !pixels || !chunk) {
        free(r);
        free(pixels);
        free(chunk);
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for a %dx%d renderer", width,
                       height);
        return NULL;
    }
    r->width = width;
    r->height = height;
    r->pixels = pixels;
    r->chunk = chunk;
    /* The framebuffer starts undefined: all of it is to be cleared. */
    r->dirty[2] = width;
    r->dirty[3] = height;

    r->ctx = create_context(kind, d);
    if (!r->ctx)
        goto fail;
    if (!load_gl(&r->gl, r->ctx, d))
        goto fail;
    GLint max_rb = 0;
    r->gl.GetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_rb);
    if (width > max_rb || height > max_rb) {
        pfx_diag_error(d, PFX_RULE_TOO_LARGE, "image size %dx%d exceeds the renderer limit of %d",
                       width, height, (int)max_rb);
        goto fail;
    }
    if (!build_framebuffer(r, d) || !pfx_shader_build_ribbon(r, d) || !default_materials(r, d))
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
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                       "OpenGL error 0x%04x while setting up the renderer", (unsigned)e);
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
    free(r->blur);
    free(r->materials);
    free(r->keys);
    free(r->index);
    free(r->sorted);
    free(r->chunk);
    free(r->mv_pixels);
    free(r->mv_ends);
    free(r->hist);
    free(r->select_hist);
    pfx_workers_destroy(r->workers);
    free(r);
}

/* The camera was checked when the effect was compiled (pfx_camera_frame);
 * a caller that built one by hand gets the same words. */
static bool camera_matrices(const pfx_camera *cam, int width, int height, pfx_view *v,
                            pfx_diags *d) {
    double s[3], u[3], f[3];
    switch (pfx_camera_frame(cam, s, u, f)) {
    case PFX_CAMERA_SAME_POINT:
        pfx_diag_error(d, PFX_RULE_INCONSISTENT_VALUES,
                       "camera 'position' and 'target' are the same point");
        return false;
    case PFX_CAMERA_UP_PARALLEL:
        pfx_diag_error(d, PFX_RULE_INCONSISTENT_VALUES,
                       "camera 'up' is parallel to the view direction");
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

/* Another renderer in this thread may have made its own context current. */
static bool make_current(pfx_renderer *r, pfx_diags *d) {
    if (!r->ctx->make_current(r->ctx)) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED, "cannot make the '%s' context current",
                       r->ctx->name);
        return false;
    }
    return true;
}

/* The material of index m, as sprites and ribbon vertices name it
 * (material 0 for an index out of range). */
static const pfx_gpu_material *material_at(const pfx_renderer *r, float m) {
    size_t k = m >= 0 && m < (float)r->material_count ? (size_t)m : 0;
    return &r->materials[k];
}

static const pfx_gpu_material *material_of(const pfx_renderer *r, const pfx_sprite *sp) {
    return material_at(r, sp->material);
}

bool pfx_render_runs(pfx_renderer *r, const pfx_sprite *sprites, size_t n, pfx_render_run_fn use,
                     void *ctx) {
    for (size_t first = 0; first < n;) {
        const pfx_gpu_material *g = material_of(r, &sprites[first]);
        size_t end = first + 1;
        while (end < n && material_of(r, &sprites[end]) == g)
            end++;
        if (!use(r, g, first, ctx))
            return false;
        point_instances(r, first);
        r->gl.DrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)(end - first));
        first = end;
    }
    return true;
}

/* The colour pass's program for a run: the material's own. */
typedef struct colour_run {
    const pfx_view *v;
    const pfx_render_settings *s;
} colour_run;

static bool use_colour(pfx_renderer *r, const pfx_gpu_material *g, size_t first, void *ctx) {
    const colour_run *c = ctx;
    (void)first;
    pfx_shader_material(r, c->v, c->s, g);
    return true;
}

/* One instanced draw per run of sprites of one material, over sprites
 * [0, n) of the uploaded instance buffer. */
static void draw_runs(pfx_renderer *r, const pfx_view *v, const pfx_render_settings *s,
                      const pfx_sprite *sprites, size_t n) {
    colour_run c = {v, s};
    pfx_render_runs(r, sprites, n, use_colour, &c);
}

/* The ribbons: one draw of their triangles, under every sprite. */
static void submit_ribbons(pfx_renderer *r, const pfx_view *v, pfx_ribbons ribbons) {
    if (!ribbons.count)
        return;
    float view[16], proj[16];
    for (int i = 0; i < 16; i++) {
        view[i] = (float)v->m[i];
        proj[i] = (float)v->proj[i];
    }
    r->gl.UseProgram(r->ribbon_program);
    r->gl.UniformMatrix4fv(r->ribbon_view, 1, GL_FALSE, view);
    r->gl.UniformMatrix4fv(r->ribbon_proj, 1, GL_FALSE, proj);
    r->gl.BindVertexArray(r->ribbon_vao);
    r->gl.BindBuffer(GL_ARRAY_BUFFER, r->ribbon_vbo);
    r->gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(ribbons.count * sizeof *ribbons.v), ribbons.v,
                     GL_STREAM_DRAW);
    /* One draw per run of triangles of one material, its texture bound
     * (none: the program skips the read). */
    for (size_t first = 0; first < ribbons.count;) {
        const pfx_gpu_material *g = material_at(r, ribbons.v[first].material);
        size_t end = first + 3;
        while (end < ribbons.count && ribbons.v[end].material == ribbons.v[first].material)
            end += 3;
        r->gl.BindTexture(GL_TEXTURE_2D, g->texture);
        r->gl.Uniform1i(r->ribbon_textured, g->texture != 0);
        r->gl.DrawArraysInstanced(GL_TRIANGLES, (GLint)first, (GLsizei)(end - first), 1);
        first = end;
    }
}

/* pfx_renderer_bench_raw's frame: clear everything, upload the sprite
 * array whole, draw. glBufferData respecifies the store, orphaning last
 * frame's, so the driver never waits on it. */
static void submit_raw(pfx_renderer *r, const pfx_view *v, const pfx_render_settings *s,
                       const float clear[4], const pfx_sprite *sprites, size_t count) {
    r->gl.BindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    r->gl.Viewport(0, 0, r->width, r->height);
    r->gl.ClearColor(clear[0], clear[1], clear[2], clear[3]);
    r->gl.Clear(GL_COLOR_BUFFER_BIT);
    if (count == 0)
        return;
    r->gl.BindVertexArray(r->vao);
    r->gl.BindBuffer(GL_ARRAY_BUFFER, r->instance_vbo);
    r->gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(count * sizeof *sprites), sprites,
                     GL_STREAM_DRAW);
    draw_runs(r, v, s, sprites, count);
    point_instances(r, 0);
}

static void read_frame(pfx_renderer *r) {
    r->gl.ReadPixels(0, 0, r->width, r->height, GL_RGBA, GL_FLOAT, r->pixels);
}

static void array_make(const void *ctx, size_t first, size_t n, const uint32_t *index,
                       pfx_sprite *out) {
    const pfx_sprite *s = ctx;
    if (!index) {
        memcpy(out, s + first, n * sizeof *out);
        return;
    }
    for (size_t k = 0; k < n; k++)
        out[k] = s[index[k]];
}

static void array_centres(const void *ctx, size_t first, size_t n, float *xyz) {
    const pfx_sprite *s = (const pfx_sprite *)ctx + first;
    for (size_t k = 0; k < n; k++) {
        xyz[3 * k] = s[k].x;
        xyz[3 * k + 1] = s[k].y;
        xyz[3 * k + 2] = s[k].z;
    }
}

pfx_sprite_source pfx_sprite_source_array(const pfx_sprite *sprites, size_t count) {
    return (pfx_sprite_source){count, array_make, array_centres, sprites};
}

/* The background as the float image holds it: premultiplied. */
static void clear_colour(const pfx_render_settings *s, float clear[4]) {
    const float *bg = s->background;
    clear[0] = bg[0] * bg[3], clear[1] = bg[1] * bg[3], clear[2] = bg[2] * bg[3];
    clear[3] = bg[3];
}

/* Clears what the last frame drew (its box) to `clear`; the rest of the
 * framebuffer already holds it. A new clear colour clears everything. */
static void clear_dirty(pfx_renderer *r, const float clear[4]) {
    r->gl.BindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    r->gl.Viewport(0, 0, r->width, r->height);
    if (memcmp(clear, r->cleared, sizeof r->cleared)) {
        memcpy(r->cleared, clear, sizeof r->cleared);
        r->dirty[0] = r->dirty[1] = 0;
        r->dirty[2] = r->width;
        r->dirty[3] = r->height;
    }
    if (r->dirty[2] > r->dirty[0] && r->dirty[3] > r->dirty[1]) {
        r->gl.Enable(GL_SCISSOR_TEST);
        r->gl.Scissor(r->dirty[0], r->dirty[1], r->dirty[2] - r->dirty[0],
                      r->dirty[3] - r->dirty[1]);
        r->gl.ClearColor(clear[0], clear[1], clear[2], clear[3]);
        r->gl.Clear(GL_COLOR_BUFFER_BIT);
        r->gl.Disable(GL_SCISSOR_TEST);
    }
}

/* Why a fence: glFlush alone hands each chunk's binned triangles to
 * llvmpipe's rasteriser as a scene of its own, but llvmpipe keeps making
 * new scenes while earlier ones are drawn, so a fast producer piles them up
 * and the driver's memory grows with the frame's sprites again (measured:
 * 2e5 additive sprites peaked 30-60 MB higher than alpha-blended ones,
 * whose chunks are slower to make). Waiting for the chunk before last
 * bounds what is in flight to two chunks and still lets the next chunk be
 * made while the last is rasterised. */
void pfx_render_chunk_done(pfx_renderer *r, GLsync fences[2], size_t k) {
    GLsync *f = &fences[k % 2];
    if (*f) {
        r->gl.ClientWaitSync(*f, GL_SYNC_FLUSH_COMMANDS_BIT, GL_TIMEOUT_IGNORED);
        r->gl.DeleteSync(*f);
    }
    *f = r->gl.FenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    r->gl.Flush();
}

void pfx_render_chunks_end(pfx_renderer *r, GLsync fences[2]) {
    for (int i = 0; i < 2; i++)
        if (fences[i])
            r->gl.DeleteSync(fences[i]);
}

/* Sprites [0, n) of `order` (NULL: the source's own), a chunk at a time:
 * made into r->chunk, bounded, uploaded (glBufferData orphans the previous
 * chunk's store, so the driver never waits on it) and drawn. Each chunk
 * but the frame's last is flushed to the rasteriser, and at most two are in
 * flight (pfx_render_chunk_done), so the driver's binned triangles are
 * bounded by the chunk, not the frame. *k counts the frame's chunks. */
static void draw_chunks(pfx_renderer *r, const pfx_view *v, const pfx_render_settings *s,
                        const pfx_sprite_source *src, const uint32_t *order, size_t n, bool last,
                        size_t *k, GLsync fences[2], pfx_bounds *b) {
    for (size_t first = 0; first < n; first += PFX_RENDER_CHUNK, ++*k) {
        const size_t m = n - first < PFX_RENDER_CHUNK ? n - first : PFX_RENDER_CHUNK;
        pfx_sort_make(r, src, order, first, first + m, r->chunk);
        pfx_bounds chunk = pfx_bounds_empty();
        pfx_bounds_sprites(r, v, r->chunk, m, &chunk);
        pfx_bounds_merge(b, &chunk);
        pfx_bounds_scissor(r, &chunk);
        r->gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(m * sizeof *r->chunk), r->chunk,
                         GL_STREAM_DRAW);
        draw_runs(r, v, s, r->chunk, m);
        if (!last || first + m < n)
            pfx_render_chunk_done(r, fences, *k);
    }
}

/* The sprites, in the depth sort's batches when `sort` (render/sort.c). */
static bool submit_sprites(pfx_renderer *r, const pfx_view *v, const pfx_render_settings *s,
                           const pfx_sprite_source *src, bool sort, pfx_bounds *b, pfx_diags *d) {
    const size_t count = src->count;
    if (count == 0)
        return true;
    r->gl.BindVertexArray(r->vao);
    r->gl.BindBuffer(GL_ARRAY_BUFFER, r->instance_vbo);
    GLsync fences[2] = {NULL, NULL};
    size_t k = 0;
    bool ok = true;
    if (!sort || count < 2) {
        draw_chunks(r, v, s, src, NULL, count, true, &k, fences, b);
    } else {
        pfx_sort_cursor c;
        pfx_sort_begin(&c, v, src);
        const uint32_t *order;
        size_t n;
        while ((ok = pfx_sort_next(r, &c, &order, &n, d)) && n > 0)
            draw_chunks(r, v, s, src, order, n, c.done == count, &k, fences, b);
    }
    pfx_render_chunks_end(r, fences);
    r->gl.Disable(GL_SCISSOR_TEST);
    point_instances(r, 0);
    return ok;
}

/* Sorts, draws and reads back the box the sprites touch into dst
 * (r->pixels, or a caller's frame buffer of the same size). The box is
 * known only once every chunk is made, so the frame is cleared where the
 * last one drew and drawn whole; the box bounds every pixel a sprite
 * touches, so the pixels outside it are still the background. */
static bool render_float(pfx_renderer *r, const pfx_camera *cam, const pfx_render_settings *s,
                         const pfx_sprite_source *src, bool sort, pfx_ribbons ribbons,
                         pixel_box *box, float *dst, pfx_diags *d) {
    const size_t count = src->count;
    if (count > (size_t)INT32_MAX || ribbons.count > (size_t)INT32_MAX) {
        pfx_diag_error(d, PFX_RULE_TOO_MANY, "too many sprites to draw: %zu", count);
        return false;
    }
    pfx_view v;
    if (!camera_matrices(cam, r->width, r->height, &v, d) || !make_current(r, d))
        return false;
    float clear[4];
    clear_colour(s, clear);
    clear_dirty(r, clear);
    pfx_bounds b = pfx_bounds_empty();
    pfx_bounds_ribbons(&v, ribbons, &b);
    pfx_bounds_scissor(r, &b);
    submit_ribbons(r, &v, ribbons);
    r->gl.Disable(GL_SCISSOR_TEST);
    if (!submit_sprites(r, &v, s, src, sort, &b, d))
        return false;
    *box = pfx_bounds_box(r, &b);
    if (box->x1 > box->x0)
        r->gl.ReadPixels(box->x0, box->y0, box->x1 - box->x0, box->y1 - box->y0, GL_RGBA, GL_FLOAT,
                         dst);
    r->dirty[0] = box->x0, r->dirty[1] = box->y0, r->dirty[2] = box->x1, r->dirty[3] = box->y1;
    GLenum e = r->gl.GetError();
    if (e != GL_NO_ERROR) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED, "OpenGL error 0x%04x while drawing %zu sprites",
                       (unsigned)e, count);
        return false;
    }
    return true;
}

/* The float image of a frame whose box was read back into pixels. */
static pfx_float_image float_image(const pfx_renderer *r, const pfx_render_settings *s,
                                   const pixel_box *box, float *pixels) {
    pfx_float_image img = {.width = r->width,
                           .height = r->height,
                           .x0 = box->x0,
                           .y0 = box->y0,
                           .x1 = box->x1,
                           .y1 = box->y1,
                           .pixels = pixels};
    clear_colour(s, img.clear);
    return img;
}

bool pfx_renderer_draw_frame(pfx_renderer *r, const pfx_camera *cam, const pfx_render_settings *s,
                             const pfx_sprite *sprites, size_t count, bool sort,
                             pfx_ribbons ribbons, uint8_t *rgba, pfx_diags *d) {
    pixel_box box;
    const pfx_sprite_source src = pfx_sprite_source_array(sprites, count);
    if (!render_float(r, cam, s, &src, sort, ribbons, &box, r->pixels, d))
        return false;
    const pfx_float_image img = float_image(r, s, &box, r->pixels);
    const pfx_tone tone = pfx_render_tone(s);
    pfx_float_image_to_rgba8(&img, &tone, rgba);
    return true;
}

bool pfx_renderer_draw_float(pfx_renderer *r, const pfx_camera *cam, const pfx_render_settings *s,
                             const pfx_sprite_source *src, bool sort, pfx_ribbons ribbons,
                             pfx_float_image *img, pfx_diags *d) {
    pixel_box box;
    float *pixels = img->pixels;
    if (!render_float(r, cam, s, src, sort, ribbons, &box, pixels, d))
        return false;
    *img = float_image(r, s, &box, pixels);
    return true;
}

bool pfx_renderer_draw(pfx_renderer *r, const pfx_camera *cam, const float bg[4],
                       const pfx_sprite *sprites, size_t count, bool sort, uint8_t *rgba,
                       pfx_diags *d) {
    const pfx_render_settings s = pfx_render_settings_plain(bg);
    return pfx_renderer_draw_frame(r, cam, &s, sprites, count, sort, (pfx_ribbons){NULL, 0}, rgba,
                                   d);
}

bool pfx_renderer_blur_begin(pfx_renderer *r, pfx_diags *d) {
    const size_t n = (size_t)r->width * (size_t)r->height * 4;
    if (!r->blur && !(r->blur = malloc(n * sizeof *r->blur))) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for motion blur at %dx%d",
                       r->width, r->height);
        return false;
    }
    memset(r->blur, 0, n * sizeof *r->blur);
    return true;
}

/* Adds weight x the sub-frame's image: the box from r->pixels, the clear
 * colour elsewhere, pixel by pixel in a fixed order. */
bool pfx_renderer_blur_add(pfx_renderer *r, const pfx_camera *cam, const pfx_render_settings *s,
                           const pfx_sprite_source *src, bool sort, pfx_ribbons ribbons,
                           float weight, pfx_diags *d) {
    pixel_box box;
    if (!render_float(r, cam, s, src, sort, ribbons, &box, r->pixels, d))
        return false;
    float clear[4];
    clear_colour(s, clear);
    const size_t bw = (size_t)(box.x1 - box.x0);
    for (int y = 0; y < r->height; y++) {
        float *dst = r->blur + (size_t)y * (size_t)r->width * 4;
        for (int x = 0; x < r->width; x++, dst += 4) {
            bool in = x >= box.x0 && x < box.x1 && y >= box.y0 && y < box.y1;
            const float *src =
                in ? r->pixels + ((size_t)(y - box.y0) * bw + (size_t)(x - box.x0)) * 4 : clear;
            for (int c = 0; c < 4; c++)
                dst[c] += weight * src[c];
        }
    }
    return true;
}

void pfx_renderer_blur_resolve(pfx_renderer *r, const pfx_render_settings *s, uint8_t *rgba) {
    const pixel_box full = {0, 0, r->width, r->height};
    const pfx_float_image img = float_image(r, s, &full, r->blur);
    const pfx_tone tone = pfx_render_tone(s);
    pfx_float_image_to_rgba8(&img, &tone, rgba);
}

void pfx_renderer_blur_resolve_float(pfx_renderer *r, const pfx_render_settings *s,
                                     pfx_float_image *img) {
    const pixel_box full = {0, 0, r->width, r->height};
    float *pixels = img->pixels;
    memcpy(pixels, r->blur, (size_t)r->width * (size_t)r->height * 4 * sizeof *pixels);
    *img = float_image(r, s, &full, pixels);
}

double pfx_renderer_bench_raw(pfx_renderer *r, const pfx_camera *cam, const pfx_sprite *sprites,
                              size_t count, int frames) {
    pfx_view v;
    if (frames <= 0 || count > (size_t)INT32_MAX ||
        !camera_matrices(cam, r->width, r->height, &v, NULL) || !make_current(r, NULL))
        return -1.0;
    const float clear[4] = {0, 0, 0, 0};
    const pfx_render_settings s = pfx_render_settings_plain(clear);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (int i = 0; i < frames; i++) {
        submit_raw(r, &v, &s, clear, sprites, count);
        r->gl.Finish();
        read_frame(r);
    }
    r->dirty[0] = r->dirty[1] = 0; /* it drew over the whole frame */
    r->dirty[2] = r->width;
    r->dirty[3] = r->height;
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (r->gl.GetError() != GL_NO_ERROR)
        return -1.0;
    double t = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    return t > 0 ? frames / t : -1.0;
}

/* The volume as a 3D texture of one float a cell, linear between cell
 * centres (the optical depth changes smoothly through a slice), clamped
 * at the edges (a margin cell of 0 across the light). */
bool pfx_renderer_set_shadow(pfx_renderer *r, const pfx_shadow_volume *v, pfx_diags *d) {
    r->shadow_on = v && !v->empty;
    if (!r->shadow_on)
        return true;
    if (!make_current(r, d))
        return false;
    if (!r->shadow_tex) {
        r->gl.GenTextures(1, &r->shadow_tex);
        r->gl.BindTexture(GL_TEXTURE_3D, r->shadow_tex);
        r->gl.TexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        r->gl.TexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        r->gl.TexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        r->gl.TexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        r->gl.TexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    }
    r->gl.ActiveTexture(GL_TEXTURE2);
    r->gl.BindTexture(GL_TEXTURE_3D, r->shadow_tex);
    r->gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    r->gl.TexImage3D(GL_TEXTURE_3D, 0, GL_R32F, PFX_SHADOW_SIDE, PFX_SHADOW_SIDE, PFX_SHADOW_SLICES,
                     0, GL_RED, GL_FLOAT, v->depth);
    r->gl.ActiveTexture(GL_TEXTURE0);
    pfx_shadow_texture_matrix(v, r->shadow_from_world);
    GLenum e = r->gl.GetError();
    if (e != GL_NO_ERROR) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                       "OpenGL error 0x%04x while uploading the shadow map", (unsigned)e);
        return false;
    }
    return true;
}

/* render_internal.h's doors into this file for the passes kept in their
 * own files (render/motion_vectors.c). */
bool pfx_render_view(const pfx_camera *cam, int width, int height, pfx_view *v, pfx_diags *d) {
    return camera_matrices(cam, width, height, v, d);
}

bool pfx_render_make_current(pfx_renderer *r, pfx_diags *d) { return make_current(r, d); }

const pfx_gpu_material *pfx_render_material_of(const pfx_renderer *r, const pfx_sprite *sp) {
    return material_of(r, sp);
}

void pfx_render_point_instances(pfx_renderer *r, size_t first) { point_instances(r, first); }
bool pfx_renderer_set_threads(pfx_renderer *r, int threads, pfx_diags *d) {
    if (threads <= 0)
        threads = pfx_workers_cores();
    if (pfx_workers_count(r->workers) == threads)
        return true;
    pfx_workers_destroy(r->workers);
    r->workers = NULL;
    if (threads > 1 && !(r->workers = pfx_workers_create(threads))) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED, "cannot start %d threads for the depth sort",
                       threads);
        return false;
    }
    return true;
}

void pfx_renderer_set_sort_batch(pfx_renderer *r, size_t batch) {
    r->sort_batch = batch < 1 ? 1 : batch > PFX_SORT_BATCH ? PFX_SORT_BATCH : batch;
}

bool pfx_renderer_sort(pfx_renderer *r, const pfx_camera *cam, pfx_sprite *sprites, size_t count,
                       pfx_diags *d) {
    pfx_view v;
    return camera_matrices(cam, r->width, r->height, &v, d) &&
           pfx_sort_back_to_front(r, &v, sprites, count, d);
}
