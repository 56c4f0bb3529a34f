/* The motion-vector pass: the frame's sprites drawn once more, each writing
 * its own screen-space displacement to where the caller says it is at the
 * next frame, weighted by its falloff, summed in a float target of its own
 * and divided by the summed weight. It does not find the ends (the caller
 * does, jobs/motion_next.c), encode or write anything (output/
 * motion_vectors.c), and it is never run unless asked. */
#include "render/render_internal.h"

#include <stdlib.h>

/* The float target, made the first time: RGBA32F so that the weighted sums
 * of many faint sprites keep their precision. */
static bool build_target(pfx_renderer *r, pfx_diags *d) {
    if (r->mv_fbo)
        return true;
    r->mv_pixels = malloc((size_t)r->width * (size_t)r->height * 4 * sizeof(float));
    r->mv_ends = malloc(PFX_RENDER_CHUNK * 4 * sizeof(float));
    if (!r->mv_pixels || !r->mv_ends) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for motion vectors at %dx%d",
                       r->width, r->height);
        return false;
    }
    r->gl.GenBuffers(1, &r->mv_ends_vbo);
    r->gl.GenRenderbuffers(1, &r->mv_rb);
    r->gl.BindRenderbuffer(GL_RENDERBUFFER, r->mv_rb);
    r->gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA32F, r->width, r->height);
    r->gl.GenFramebuffers(1, &r->mv_fbo);
    r->gl.BindFramebuffer(GL_FRAMEBUFFER, r->mv_fbo);
    r->gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, r->mv_rb);
    GLenum status = r->gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                       "motion-vector framebuffer %dx%d is incomplete (status 0x%04x)", r->width,
                       r->height, (unsigned)status);
        return false;
    }
    return true;
}

/* The chunk's ends as instance attribute 5, from the chunk's instance
 * `first` on; only the motion pass's programs read it, and only while it
 * draws is the array enabled. */
static void point_ends(pfx_renderer *r, size_t first) {
    r->gl.BindBuffer(GL_ARRAY_BUFFER, r->mv_ends_vbo);
    r->gl.VertexAttribPointer(5, 4, GL_FLOAT, GL_FALSE, 4 * sizeof(float),
                              (const void *)(first * 4 * sizeof(float)));
    r->gl.BindBuffer(GL_ARRAY_BUFFER, r->instance_vbo);
}

/* The motion pass's program for a run (the motion variant of the
 * material's), and the ends pointed at the run's first instance. */
typedef struct motion_run {
    const pfx_view *v;
    const pfx_render_settings *s;
    pfx_diags *d;
} motion_run;

static bool use_motion(pfx_renderer *r, const pfx_gpu_material *g, size_t first, void *ctx) {
    const motion_run *m = ctx;
    if (!pfx_shader_motion(r, m->v, m->s, g, m->d))
        return false;
    point_ends(r, first);
    return true;
}

/* One instanced draw per run of one material, as the colour pass draws,
 * a chunk of the source at a time (at most two in flight, as there). The
 * blend sums (dx w, dy w, w) in RGB and keeps A = 1 - prod(1 - w), the
 * coverage of the sprites laid over each other; both are independent of
 * the drawing order but for rounding, and the order is the source's. */
static bool draw_motion(pfx_renderer *r, const pfx_view *v, const pfx_render_settings *s,
                        const pfx_sprite_source *src, const pfx_sprite_ends *ends, pfx_diags *d) {
    motion_run run = {v, s, d};
    r->gl.BindFramebuffer(GL_FRAMEBUFFER, r->mv_fbo);
    r->gl.Viewport(0, 0, r->width, r->height);
    r->gl.ClearColor(0, 0, 0, 0);
    r->gl.Clear(GL_COLOR_BUFFER_BIT);
    if (src->count == 0)
        return true;
    r->gl.BlendFuncSeparate(GL_ONE, GL_ONE, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    r->gl.BindVertexArray(r->vao);
    r->gl.EnableVertexAttribArray(5);
    r->gl.VertexAttribDivisor(5, 1);
    r->gl.BindBuffer(GL_ARRAY_BUFFER, r->instance_vbo);
    bool ok = true;
    GLsync fences[2] = {NULL, NULL};
    for (size_t at = 0, k = 0; ok && at < src->count; at += PFX_RENDER_CHUNK, k++) {
        const size_t n = src->count - at < PFX_RENDER_CHUNK ? src->count - at : PFX_RENDER_CHUNK;
        const pfx_sprite *sprites = r->chunk;
        if (k > 0)
            pfx_render_chunk_done(r, fences, k - 1);
        pfx_sort_make(r, src, NULL, at, at + n, r->chunk);
        r->gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(n * sizeof *sprites), sprites,
                         GL_STREAM_DRAW);
        ends->make(ends->ctx, at, n, r->mv_ends);
        r->gl.BindBuffer(GL_ARRAY_BUFFER, r->mv_ends_vbo);
        r->gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(n * 4 * sizeof(float)), r->mv_ends,
                         GL_STREAM_DRAW);
        r->gl.BindBuffer(GL_ARRAY_BUFFER, r->instance_vbo);
        ok = pfx_render_runs(r, sprites, n, use_motion, &run);
    }
    pfx_render_chunks_end(r, fences);
    pfx_render_point_instances(r, 0);
    r->gl.DisableVertexAttribArray(5);
    r->gl.BlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA); /* the colour pass's, as it was */
    return ok;
}

bool pfx_renderer_motion_vectors(pfx_renderer *r, const pfx_camera *cam,
                                 const pfx_render_settings *s, const pfx_sprite_source *src,
                                 const pfx_sprite_ends *ends, float *mv, pfx_diags *d) {
    const size_t count = src->count;
    if (count > (size_t)INT32_MAX) {
        pfx_diag_error(d, PFX_RULE_TOO_MANY, "too many sprites to draw: %zu", count);
        return false;
    }
    pfx_view v;
    if (!pfx_render_view(cam, r->width, r->height, &v, d) || !pfx_render_make_current(r, d) ||
        !build_target(r, d))
        return false;
    bool drawn = draw_motion(r, &v, s, src, ends, d);
    r->gl.ReadPixels(0, 0, r->width, r->height, GL_RGBA, GL_FLOAT, r->mv_pixels);
    r->gl.BindFramebuffer(GL_FRAMEBUFFER, r->fbo);
    GLenum e = r->gl.GetError();
    if (!drawn)
        return false;
    if (e != GL_NO_ERROR) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                       "OpenGL error 0x%04x while drawing motion vectors of %zu sprites",
                       (unsigned)e, count);
        return false;
    }
    /* GL's rows run bottom up; the caller's top down. A pixel no sprite
     * touches has weight 0: no motion, no coverage. */
    const size_t w = (size_t)r->width;
    for (int y = 0; y < r->height; y++) {
        const float *src = r->mv_pixels + (size_t)(r->height - 1 - y) * w * 4;
        float *dst = mv + (size_t)y * w * 3;
        for (size_t x = 0; x < w; x++, src += 4, dst += 3) {
            float sum = src[2];
            dst[0] = sum > 0 ? src[0] / sum : 0.0f;
            dst[1] = sum > 0 ? src[1] / sum : 0.0f;
            dst[2] = src[3] < 0 ? 0.0f : src[3] > 1 ? 1.0f : src[3];
        }
    }
    return true;
}
