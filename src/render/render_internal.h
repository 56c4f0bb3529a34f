/* What the files of src/render share: the GL entry points, the renderer's
 * state, the camera's matrices, the screen box a frame touches. Private to
 * src/render. */
#ifndef PFX_RENDER_INTERNAL_H
#define PFX_RENDER_INTERNAL_H

#include "render/gl_context.h"
#include "render/render.h"

#include "base/workers.h"

/* Types, enums and PFNGL...PROC typedefs only: without GL_GLEXT_PROTOTYPES
 * it declares no function, so every call goes through the table below. */
#include <GL/glcorearb.h>

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
    X(PFNGLFLUSHPROC, Flush)                                                                       \
    X(PFNGLFENCESYNCPROC, FenceSync)                                                               \
    X(PFNGLCLIENTWAITSYNCPROC, ClientWaitSync)                                                     \
    X(PFNGLDELETESYNCPROC, DeleteSync)                                                             \
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
    X(PFNGLDISABLEVERTEXATTRIBARRAYPROC, DisableVertexAttribArray)                                 \
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
    X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                                                 \
    X(PFNGLUNIFORM1IPROC, Uniform1i)                                                               \
    X(PFNGLUNIFORM1FPROC, Uniform1f)                                                               \
    X(PFNGLUNIFORM2FPROC, Uniform2f)                                                               \
    X(PFNGLUNIFORM3FPROC, Uniform3f)                                                               \
    X(PFNGLGENTEXTURESPROC, GenTextures)                                                           \
    X(PFNGLDELETETEXTURESPROC, DeleteTextures)                                                     \
    X(PFNGLBINDTEXTUREPROC, BindTexture)                                                           \
    X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                                                       \
    X(PFNGLTEXIMAGE2DPROC, TexImage2D)                                                             \
    X(PFNGLTEXIMAGE3DPROC, TexImage3D)                                                             \
    X(PFNGLTEXPARAMETERIPROC, TexParameteri)                                                       \
    X(PFNGLBLENDFUNCSEPARATEPROC, BlendFuncSeparate)

typedef struct pfx_gl {
#define PFX_GL_FIELD(type, name) type name;
    PFX_GL_FUNCS(PFX_GL_FIELD)
#undef PFX_GL_FIELD
} pfx_gl;

/* Uniform locations of a sprite program (render/shader.c). */
typedef struct pfx_sprite_uniforms {
    GLint view, proj, px_per_unit, min_px, axis, plane_x, plane_y;
    GLint tex, grid, frames, frame_loop, normal_tex, light_dir, light_color, ambient;
    GLint mv_size;                              /* the motion-vector variant only (-1 elsewhere) */
    GLint shadow_tex, shadow_from_view;         /* shadowed programs only */
    GLint viewport, cell_texels, normal_texels; /* textured programs: the level of detail */
} pfx_sprite_uniforms;

/* A sprite program specialised for one combination of material switches
 * (render/shader.c says which and why). */
typedef struct pfx_program {
    unsigned key;
    GLuint id;
    pfx_sprite_uniforms u;
} pfx_program;

/* Sprite kinds x alignments x texture, cross-fade, light and normal-map
 * switches give far more combinations than an effect's emitters use; an
 * effect has at most this many materials' worth of distinct ones. */
#define PFX_MAX_PROGRAMS 64

/* A material as the GPU holds it: the caller's description, its textures
 * (0: none) and its program (an index into the renderer's). */
typedef struct pfx_gpu_material {
    pfx_material m;
    GLuint texture, normal_map;
    size_t program;
} pfx_gpu_material;

struct pfx_renderer {
    int width, height;
    pfx_gl_context *ctx;
    pfx_gl gl;
    GLuint fbo, colour_rb, vao, quad_vbo, instance_vbo;
    pfx_program programs[PFX_MAX_PROGRAMS];
    size_t program_count;
    GLuint ribbon_vao, ribbon_vbo, ribbon_program; /* ribbons: world-space triangles */
    GLint ribbon_view, ribbon_proj, ribbon_textured;
    pfx_gpu_material *materials;
    size_t material_count;
    size_t texture_count; /* distinct GL textures the materials share */
    float *pixels;        /* width * height * 4 floats read back from the FBO */
    float *blur;          /* motion blur: the weighted sum of full float images */
    /* Sort scratch, grown to the largest count seen, up to sort_batch: two
     * key and two index arrays for the radix ping-pong and the radix
     * blocks' histograms (render/sort.c). `sorted` is pfx_renderer_sort's copy alone (pfx
     * bench): drawing makes the sorted sprites a chunk at a time. */
    size_t scratch_cap;
    uint32_t *keys;
    uint32_t *index;
    size_t sort_batch;     /* sprites sorted at once (PFX_SORT_BATCH): the scratch's limit */
    uint32_t *select_hist; /* the batches' selection histograms, when a source has more */
    pfx_sprite *sorted;
    size_t sorted_cap;
    /* The sprites of one draw chunk, made from the source, then uploaded
     * (PFX_RENDER_CHUNK of them). */
    pfx_sprite *chunk;
    /* The pixels of fbo that may differ from `cleared`, the colour last
     * cleared to: last frame's box (render.c clears only these). */
    int dirty[4];
    float cleared[4];
    /* Motion vectors (render/motion_vectors.c): their own float target and
     * read-back, made on first use so that a render without them pays
     * nothing; the ends of one chunk's sprites (x, y, z, weight a sprite),
     * uploaded to mv_ends_vbo beside the chunk. */
    GLuint mv_fbo, mv_rb, mv_ends_vbo;
    float *mv_pixels;
    float *mv_ends;
    uint32_t *hist;
    pfx_workers *workers; /* the sort's threads; NULL: the caller's alone */
    /* Self-shadowing (render/shadow.h): the 3D texture of optical depth
     * (0 until the first pfx_renderer_set_shadow) and the map from world
     * points to its coordinates; shadow_on false: an empty volume. */
    GLuint shadow_tex;
    double shadow_from_world[16];
    bool shadow_on;
};

/* Camera matrices, column-major (m[col * 4 + row]) as GL expects. The view
 * matrix is gluLookAt's: forward f = normalize(target - position), side
 * s = normalize(f x up), true up u = s x f; the camera looks down -z. */
typedef struct pfx_view {
    double m[16];
    double proj[16];
    double forward[3], eye[3];
} pfx_view;

/* The pixels a frame's sprites can touch, in GL window coordinates (y up),
 * [x0, x1) x [y0, y1). */
typedef struct pixel_box {
    int x0, y0, x1, y1;
} pixel_box;

/* The pixels a frame's sprites can touch, in GL window coordinates (y up),
 * [x0, x1) x [y0, y1), gathered chunk by chunk as normalised device
 * coordinates (lo, hi; min and max, so in any order). A camera-facing or
 * velocity-stretched quad lies at one view depth, so its image is the
 * projection of its view-space square of half-side max(size, length) / 2,
 * widened by sqrt 2 for turned quads, by the minimum footprint and by 2
 * pixels for rasterisation. A quad in a world plane or about an axis tilts
 * in depth, and a sprite at or behind the near plane: then the box is the
 * whole frame (`full`). Outside the box every pixel is the background, so
 * only the box is read back and converted, and cleared next frame. */
typedef struct pfx_bounds {
    double lo[2], hi[2];
    bool full;
} pfx_bounds;
/* Nothing yet: lo above hi. */
pfx_bounds pfx_bounds_empty(void);
/* Widens b to hold part too. */
void pfx_bounds_merge(pfx_bounds *b, const pfx_bounds *part);
/* Clips drawing to b's pixels (GL_SCISSOR_TEST on; the caller turns it
 * off): what is drawn next cannot leave a pixel outside the box that is
 * read back and cleared, even if a bound fell short. */
void pfx_bounds_scissor(pfx_renderer *r, const pfx_bounds *b);
/* Widens b by the ribbons' corners, final world points each. */
void pfx_bounds_ribbons(const pfx_view *v, pfx_ribbons ribbons, pfx_bounds *b);
/* Widens b by the quads of count sprites. */
void pfx_bounds_sprites(const pfx_renderer *r, const pfx_view *v, const pfx_sprite *sp,
                        size_t count, pfx_bounds *b);
/* The pixels of b, with a margin for rasterisation and the minimum
 * footprint, clipped to the frame. */
pixel_box pfx_bounds_box(const pfx_renderer *r, const pfx_bounds *b);

/* render/shader.c: bind gives g the program its switches need, compiling
 * and linking it the first time; material makes g's program current and
 * sets its uniforms (camera, light, alignment, flipbook, textures).
 * Programs live until the context does. */
bool pfx_shader_bind(pfx_renderer *r, pfx_gpu_material *g, pfx_diags *d);
void pfx_shader_material(pfx_renderer *r, const pfx_view *v, const pfx_render_settings *s,
                         const pfx_gpu_material *g);
/* render/shader.c: makes current the motion-vector variant of g's program
 * (linked on first use; false with an error when it cannot be) and sets
 * its uniforms. */
bool pfx_shader_motion(pfx_renderer *r, const pfx_view *v, const pfx_render_settings *s,
                       const pfx_gpu_material *g, pfx_diags *d);
/* render/render.c, for the passes in other files: the camera's matrices
 * (false with an error for a degenerate camera), a current context, the
 * material a sprite names, and the instance attributes pointed at sprite
 * `first` of the uploaded array. */
bool pfx_render_view(const pfx_camera *cam, int width, int height, pfx_view *v, pfx_diags *d);
bool pfx_render_make_current(pfx_renderer *r, pfx_diags *d);
const pfx_gpu_material *pfx_render_material_of(const pfx_renderer *r, const pfx_sprite *sp);
void pfx_render_point_instances(pfx_renderer *r, size_t first);
/* render/render.c: one instanced draw per run of sprites of one material
 * over sprites [0, n) of the uploaded instance buffer, the one loop of
 * every sprite pass: `use` makes the run's program current (and points
 * any attributes of its own at instance `first`); false from it stops the
 * loop and is returned. */
typedef bool (*pfx_render_run_fn)(pfx_renderer *r, const pfx_gpu_material *g, size_t first,
                                  void *ctx);
bool pfx_render_runs(pfx_renderer *r, const pfx_sprite *sprites, size_t n, pfx_render_run_fn use,
                     void *ctx);

/* render/shader.c: the ribbon program (world-space triangles, no
 * switches), into r->ribbon_program and its two uniforms. */
bool pfx_shader_build_ribbon(pfx_renderer *r, pfx_diags *d);

/* render/sort.c: the back-to-front order of the source's sprites by view
 * depth, stable (LSD radix on float keys, over r->workers), given out in
 * batches of at most r->sort_batch: pfx_sort_begin, then pfx_sort_next
 * until it gives n = 0. Each batch is the next stretch of the one stable
 * order: order[0, n) are sprite positions in the source, in r's scratch,
 * valid until the next call. false with an error when the scratch cannot
 * grow or the count does not fit 32 bits. */
typedef struct pfx_sort_cursor {
    const pfx_sprite_source *src;
    double f[3], e[3]; /* the camera's forward axis and eye */
    size_t done;       /* sprites given out */
    bool started;      /* a batch was given; (k_last, i_last) is its last */
    uint32_t k_last, i_last;
} pfx_sort_cursor;
void pfx_sort_begin(pfx_sort_cursor *c, const pfx_view *v, const pfx_sprite_source *src);
bool pfx_sort_next(pfx_renderer *r, pfx_sort_cursor *c, const uint32_t **order, size_t *n,
                   pfx_diags *d);
/* render/render.c: keeps at most two chunks of sprites in the driver's
 * hands: after chunk k is drawn, fences it and flushes, and first waits
 * for chunk k - 2 (fences[k % 2]). pfx_render_chunks_end drops what is
 * left (the read-back that follows waits for everything anyway). */
void pfx_render_chunk_done(pfx_renderer *r, GLsync fences[2], size_t k);
void pfx_render_chunks_end(pfx_renderer *r, GLsync fences[2]);

/* render/sort.c: pfx_renderer_sort's in-place sort of an array. */
bool pfx_sort_back_to_front(pfx_renderer *r, const pfx_view *v, pfx_sprite *sprites, size_t count,
                            pfx_diags *d);
/* render/sort.c: sprites [lo, hi) of the source (in the order `index`
 * gives, when not NULL) into out, over r->workers when there are many. */
void pfx_sort_make(pfx_renderer *r, const pfx_sprite_source *src, const uint32_t *index, size_t lo,
                   size_t hi, pfx_sprite *out);

#endif
